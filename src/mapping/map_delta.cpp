#include "gesture_formation/mapping/map_delta.hpp"

#include <cmath>

namespace gesture_formation::mapping {

namespace {

std::string keyText(const VoxelKey& k) {
  return "(" + std::to_string(k[0]) + ", " + std::to_string(k[1]) + ", " + std::to_string(k[2]) + ")";
}

std::string listProblem(const std::vector<VoxelKey>& keys, const KeyGrid& grid, const std::string& field) {
  for (std::size_t i = 0; i < keys.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      if (keys[i][a] < grid.min_key[a] || keys[i][a] > grid.max_key[a]) {
        return field + "[" + std::to_string(i) + "] key " + keyText(keys[i]) + " is outside the map's keys " +
               keyText(grid.min_key) + " .. " + keyText(grid.max_key);
      }
    }
  }
  return "";
}

}  // namespace

std::string deltaProblem(const MapDelta& delta, const KeyGrid& grid, const std::string& prefix) {
  if (!std::isfinite(delta.resolution_m) || std::abs(delta.resolution_m - grid.resolution_m) > 1e-9) {
    return prefix + "resolution_m " + std::to_string(delta.resolution_m) + " differs from the map's " +
           std::to_string(grid.resolution_m);
  }
  if (!std::isfinite(delta.stamp_s)) return prefix + "stamp_s must be finite, got " + std::to_string(delta.stamp_s);
  std::string p = listProblem(delta.occupied, grid, prefix + "occupied");
  if (p.empty()) p = listProblem(delta.free, grid, prefix + "free");
  return p;
}

}  // namespace gesture_formation::mapping

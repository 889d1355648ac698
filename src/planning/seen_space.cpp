#include "gesture_formation/planning/seen_space.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace gesture_formation::planning {

SeenSpace::SeenSpace(const OccupancyMap& map, const SeenRule& rule)
    : rule_(rule),
      resolution_m_(map.resolution()),
      origin_(map.gridOrigin()),
      size_(map.gridSize()),
      seen_(static_cast<std::size_t>(map.gridSize().prod()), 0) {}

void SeenSpace::markOccupied(const OccupancyMap& map) {
  const std::vector<std::uint8_t>& grid = map.denseGrid();
  for (std::size_t i = 0; i < grid.size() && i < seen_.size(); ++i) {
    if (grid[i] != 0) seen_[i] = 1;
  }
}

bool SeenSpace::seenLocal(const VoxelIndex& l) const {
  if ((l.array() < 0).any() || (l.array() >= size_.array()).any()) return false;
  const std::size_t i = static_cast<std::size_t>(l.x()) +
                        static_cast<std::size_t>(size_.x()) *
                            (static_cast<std::size_t>(l.y()) + static_cast<std::size_t>(size_.y()) * static_cast<std::size_t>(l.z()));
  return seen_[i] != 0;
}

bool SeenSpace::seen(const Eigen::Vector3d& p) const {
  if (!p.allFinite()) return false;
  const VoxelIndex v = (p / resolution_m_).array().floor().cast<int>();
  return seenLocal(v - origin_);
}

std::size_t SeenSpace::seenCount() const {
  return static_cast<std::size_t>(std::count(seen_.begin(), seen_.end(), std::uint8_t{1}));
}

std::optional<Eigen::Vector3d> SeenSpace::unseenNear(const Eigen::Vector3d& p, const Eigen::Vector3d& exempt) const {
  if (!p.allFinite()) return p;
  const double r = rule_.margin_m, r2 = r * r, res = resolution_m_;
  const VoxelIndex lo = ((p.array() - r) / res - 0.5).ceil().cast<int>();  // centres (i + 0.5)·res ≥ p − r
  const VoxelIndex hi = ((p.array() + r) / res - 0.5).floor().cast<int>();
  for (int k = lo.z(); k <= hi.z(); ++k) {
    for (int j = lo.y(); j <= hi.y(); ++j) {
      for (int i = lo.x(); i <= hi.x(); ++i) {
        const VoxelIndex v(i, j, k);
        const Eigen::Vector3d c = (v.cast<double>().array() + 0.5).matrix() * res;
        if ((c - p).squaredNorm() > r2 || seenLocal(v - origin_)) continue;
        if (exempt.allFinite() && (c - exempt).squaredNorm() <= r2) continue;  // where the UAV is
        return c;
      }
    }
  }
  return std::nullopt;
}

}  // namespace gesture_formation::planning

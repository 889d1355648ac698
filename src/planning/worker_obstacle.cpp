#include "gesture_formation/planning/worker_obstacle.hpp"

#include <cmath>

namespace gesture_formation::planning {

std::vector<std::string> WorkerObstacleConfig::validate() const {
  std::vector<std::string> e;
  if (!(std::isfinite(radius_m) && radius_m > 0.0)) e.push_back("radius_m must be > 0, got " + std::to_string(radius_m));
  if (!(std::isfinite(height_m) && height_m > 0.0)) e.push_back("height_m must be > 0, got " + std::to_string(height_m));
  return e;
}

}  // namespace gesture_formation::planning

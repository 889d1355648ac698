#pragma once
/// \file
/// \brief The interface the corridor builder queries obstacles through: points (world
/// frame, m) inside an axis-aligned box. Implemented by OccupancyMap (occupied voxel
/// centres) and PointCloudObstacles (a plain list, for tests and tools).

#include <vector>

#include <Eigen/Core>

#include "gesture_formation/planning/shapes.hpp"

namespace gesture_formation::planning {

class ObstaclePoints {
 public:
  virtual ~ObstaclePoints() = default;
  /// \brief Appends every obstacle point inside the closed box to `out`.
  /// Thread safety: implementations are safe to call concurrently.
  virtual void pointsInBox(const Aabb& box, std::vector<Eigen::Vector3d>& out) const = 0;
};

/// \brief Obstacles given as a list of points; queries scan the whole list.
class PointCloudObstacles : public ObstaclePoints {
 public:
  explicit PointCloudObstacles(std::vector<Eigen::Vector3d> points_world) : points_(std::move(points_world)) {}
  void pointsInBox(const Aabb& box, std::vector<Eigen::Vector3d>& out) const override {
    for (const auto& p : points_) {
      if (box.contains(p)) out.push_back(p);
    }
  }
  const std::vector<Eigen::Vector3d>& points() const { return points_; }

 private:
  std::vector<Eigen::Vector3d> points_;
};

}  // namespace gesture_formation::planning

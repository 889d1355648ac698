#pragma once
/// \file
/// \brief The worker as a moving obstacle: a vertical cylinder around the estimator's
/// predicted position (docs/design.md §3 constant-velocity model), queried separately from the
/// static map because it moves. World frame, metres, seconds.
/// Thread safety: value type.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/planning/shapes.hpp"

namespace gesture_formation::planning {

/// \brief Size of the cylinder kept around the worker. Defaults: an adult with arms
/// spread partly (radius 0.5 m) and a 2.0 m tall body.
struct WorkerObstacleConfig {
  double radius_m = 0.5;  ///< > 0
  double height_m = 2.0;  ///< > 0; the cylinder spans the position's z ± height/2
  /// Every problem, each naming the field; empty when valid.
  std::vector<std::string> validate() const;
};

/// \brief The worker's state at `stamp_s` (position = the estimator's p, mid-body).
class WorkerObstacle {
 public:
  WorkerObstacle(const WorkerObstacleConfig& config, const Eigen::Vector3d& p_world, const Eigen::Vector3d& v_world_mps,
                 double stamp_s)
      : config_(config), p_world_(p_world), v_world_mps_(v_world_mps), stamp_s_(stamp_s) {}

  /// \brief Predicted position (m) at time t_s (constant velocity).
  Eigen::Vector3d positionAt(double t_s) const { return p_world_ + (t_s - stamp_s_) * v_world_mps_; }
  /// \brief The occupied cylinder at time t_s.
  Cylinder cylinderAt(double t_s) const {
    const Eigen::Vector3d c = positionAt(t_s);
    const Eigen::Vector3d half(0.0, 0.0, 0.5 * config_.height_m);
    return Cylinder{c - half, c + half, config_.radius_m};
  }
  /// \brief Distance (m) from p to the worker's cylinder at time t_s; 0 inside.
  double clearance(const Eigen::Vector3d& p_world, double t_s) const { return cylinderAt(t_s).distance(p_world); }

 private:
  WorkerObstacleConfig config_;
  Eigen::Vector3d p_world_;
  Eigen::Vector3d v_world_mps_;
  double stamp_s_;
};

}  // namespace gesture_formation::planning

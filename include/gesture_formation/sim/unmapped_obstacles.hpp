#pragma once
/// \file
/// \brief Obstacles that exist in the simulated world only (issue 35 item 2; docs/simulation.md
/// §"Unmapped obstacles"): a crane arm, scaffolding, a truck — present in the world the UAVs fly
/// in (collisions, obstacle distances, the synthetic depth camera) but absent from the prior map
/// the planners get. A scenario file lists them in its top-level section `unmapped_obstacles:`,
/// each with exactly one shape written as in `boxes:` / `cylinders:` (docs/planning.md §1) and an
/// optional motion:
///
///   unmapped_obstacles:
///     - name: crane_arm                       # optional, unique (default "unmapped_<i>")
///       box: {center: [x, y, z], size: [sx, sy, sz], rpy_deg: [r, p, y]}   # rpy optional
///     - cylinder: {base: [x, y, z], radius_m: r, height_m: h}              # vertical
///     - name: truck
///       box: {...}
///       moves: {from_s: 30, to_s: 40, velocity_mps: [3, 0, 0]}  # translates between from_s and to_s
///       gone_after_s: 60                                          # absent from then on
///
/// World frame (x east, y north, z up), metres, seconds of mission time.
/// Thread safety: value types; loading has no shared state.

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/planning/shapes.hpp"

namespace gesture_formation::sim {

/// \brief How an unmapped obstacle moves: a constant velocity from `from_s` to `to_s` (the
/// offset then stays), and it disappears at `gone_after_s` (a truck that drove out of the site).
struct ObstacleMotion {
  double from_s = 0.0;                                          ///< ≥ 0
  double to_s = 0.0;                                            ///< ≥ from_s
  Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();       ///< world frame, finite
  double gone_after_s = std::numeric_limits<double>::infinity();  ///< > 0; +inf: never gone

  /// \brief Translation of the obstacle at t_s relative to its listed pose.
  Eigen::Vector3d offsetAt(double t_s) const;
  bool moves() const { return to_s > from_s && velocity_mps.squaredNorm() > 0.0; }
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief One unmapped obstacle: a box or a vertical cylinder (as listed, at t = 0) and its motion.
struct UnmappedObstacle {
  enum class Shape { kBox, kCylinder };
  std::string name;
  Shape shape = Shape::kBox;
  planning::OrientedBox box;       ///< kBox
  planning::Cylinder cylinder;     ///< kCylinder
  ObstacleMotion motion;

  /// \brief Present in the world at t_s (before motion.gone_after_s).
  bool presentAt(double t_s) const { return t_s < motion.gone_after_s; }
  /// \brief Distance (m) from p to the obstacle at t_s (0 inside, +inf when gone).
  double distanceAt(const Eigen::Vector3d& p_world, double t_s) const;
  /// \brief The obstacle at t_s as primitives (empty when gone).
  planning::PrimitiveSet primitivesAt(double t_s) const;
  /// \brief Its bounding box at t_s (the listed pose moved; meaningless when gone).
  planning::Aabb boundsAt(double t_s) const;
};

/// \brief The section `unmapped_obstacles` of a scenario's YAML text (absent: an empty list).
/// On failure the reason lists every problem, one per line, "<source>: <key>: <message>" naming
/// the value (e.g. `unmapped_obstacles[1].moves.to_s: must be >= from_s (2), got 1`).
common::Result<std::vector<UnmappedObstacle>> parseUnmappedObstacles(const std::string& yaml,
                                                                     const std::string& source_name);
/// \brief As parseUnmappedObstacles, from the scenario file.
common::Result<std::vector<UnmappedObstacle>> loadUnmappedObstacles(const std::string& scenario_path);

/// \brief Distance (m) from p to the nearest obstacle of `obstacles` present at t_s (+inf: none).
double unmappedDistance(const std::vector<UnmappedObstacle>& obstacles, const Eigen::Vector3d& p_world, double t_s);

}  // namespace gesture_formation::sim

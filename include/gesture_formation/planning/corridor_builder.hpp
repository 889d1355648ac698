#pragma once
/// \file
/// \brief Convex safe corridors along a path by ellipsoid-based decomposition (Liu et al.,
/// "Planning Dynamically Feasible Trajectories for Quadrotors Using Safe Flight Corridors
/// in 3-D Complex Environments", RA-L 2017 — the method behind DecompUtil; our own code).
/// For each segment: (1) an ellipsoid around the segment is shrunk against the obstacle
/// points near it; (2) repeatedly, the remaining obstacle point closest in the ellipsoid's
/// metric contributes the plane tangent to the ellipsoid's level set through it, moved
/// towards the segment by the clearance, and every point beyond that plane is dropped;
/// (3) the six planes of the segment's local box close the polytope.
///
/// Guarantees of a returned corridor (docs/planning.md §3; tested in test_corridor_builder):
/// - both segment ends satisfy A x ≤ b − seed_margin_m (so consecutive corridors overlap at
///   their shared waypoint, and the whole segment lies inside by convexity);
/// - every obstacle point reported by the ObstaclePoints source in the query box violates
///   some row by ≥ min_exclusion_m, and every point outside the query box lies outside the
///   local box by more than clearance_m: no obstacle point lies in the polytope;
/// - every obstacle point lies at least `SegmentCorridor::clearance_m` (≤ config.clearance_m)
///   from the polytope.
/// An obstacle point closer than min_exclusion_m + seed_margin_m to the segment makes such a
/// polytope impossible: buildSegment fails and names it. No obstacles: the local box.
/// Thread safety: const methods may run concurrently (no shared scratch state).

#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/planning/obstacle_points.hpp"
#include "gesture_formation/planning/polytope.hpp"
#include "gesture_formation/planning/shapes.hpp"

namespace gesture_formation::common {
template <class Config>
struct FieldTable;
}  // namespace gesture_formation::common

namespace gesture_formation::planning {

/// \brief Parameters of the decomposition.
struct CorridorConfig {
  /// Distance (m) each tangent plane is moved from its obstacle point towards the segment:
  /// robot radius + safety margin. Occupied voxel centres stand for whole voxels, so keep it
  /// ≥ √3/2·resolution (0.17 m at 0.2 m) for the corridor to clear whole voxels. [0, inf).
  double clearance_m = 0.5;
  /// Local box: the segment's bounding box grown by this much along x, y, z (m); each
  /// must exceed seed_margin_m. Larger boxes give larger corridors and cost more.
  Eigen::Vector3d local_box_margin_m = Eigen::Vector3d(2.0, 2.0, 2.0);
  /// Segment ends lie at least this far (m) inside every plane, > 0.
  double seed_margin_m = 1e-3;
  /// Every obstacle point lies at least this far (m) outside some plane, > 0.
  double min_exclusion_m = 1e-3;
  /// Shorter segments are rejected (m), > 0.
  double min_segment_length_m = 1e-6;

  /// Every problem, each naming the field; empty when valid.
  std::vector<std::string> validate() const;
};

/// \brief CorridorConfig's numbers (keys as the member names) with their ranges: the only place
/// they are written, used by validate() and by `gfctl corridor`'s options.
const common::FieldTable<CorridorConfig>& corridorConfigFields();

/// \brief The corridor of one path segment.
struct SegmentCorridor {
  Polytope polytope;
  Ellipsoid ellipsoid;
  Eigen::Vector3d seed_begin_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d seed_end_world = Eigen::Vector3d::Zero();
  Aabb local_box;
  /// Achieved clearance (m): every obstacle point is at least this far from the polytope;
  /// equals config.clearance_m unless an obstacle is closer than that to the segment.
  double clearance_m = 0.0;
  /// Distance (m) from the segment to the nearest obstacle point in the query box (+inf
  /// without any): below the voxel half diagonal, the segment crosses an occupied voxel.
  double segment_clearance_m = 0.0;
  std::size_t obstacle_points = 0;  ///< points considered (in the query box)
};

class CorridorBuilder {
 public:
  /// \brief `config` must be valid (validate() empty); an invalid one is replaced by the
  /// defaults and `configError()` names the problems.
  explicit CorridorBuilder(const CorridorConfig& config);

  const CorridorConfig& config() const { return config_; }
  const std::string& configError() const { return config_error_; }

  /// \brief The corridor of the segment p0 → p1 (world, m). Fails (with the reason) for
  /// non-finite or too short segments and for obstacles touching the segment.
  common::Result<SegmentCorridor> buildSegment(const Eigen::Vector3d& p0_world, const Eigen::Vector3d& p1_world,
                                               const ObstaclePoints& obstacles) const;

  /// \brief One corridor per segment of a path of ≥ 2 waypoints. The reason of a failure
  /// names the segment ("segment 3 (waypoints 3 → 4): ...").
  common::Result<std::vector<SegmentCorridor>> buildPath(const std::vector<Eigen::Vector3d>& path_world,
                                                         const ObstaclePoints& obstacles) const;

 private:
  CorridorConfig config_;
  std::string config_error_;
};

}  // namespace gesture_formation::planning

#pragma once
/// \file
/// \brief The space a UAV's depth camera has observed, and the rule that keeps a UAV able to
/// stop inside it (docs/mapping.md §3.1, the seen-space rule).
///
/// With online mapping the planner's map holds what the camera has seen occupied; a voxel the
/// camera never looked at is free in that map although it may hold an obstacle (a scaffold face
/// just outside the view, the inside of a solid seen from one side). SeenSpace records, per voxel
/// of the planner's grid, whether it has been observed (a ray crossed it or ended in it, or the
/// prior map holds it occupied). The verifier (TrajectoryVerifier) then requires, when it is
/// given a SeenSpace, that from every point of a plan within `horizon_s` of its start the
/// straight braking path (brakeStop()) runs through seen space: every voxel whose centre lies
/// within `margin_m` of the path has been observed — or lies within `margin_m` of the plan's
/// start, where the UAV itself is. So a plan is executed only if the UAV, braking at any time
/// before the next replanning can replace it, stops inside space it has seen; towards space
/// it has not seen it may move no faster than that allows (voxel quantisation lets it creep a
/// fraction of a voxel per horizon).
///
/// Voxels outside the grid are never seen. Thread safety: none of its own; LiveMap marks it
/// under its writer lock, planners read it under LiveMap::readLock().

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/planning/occupancy_map.hpp"

namespace gesture_formation::planning {

/// \brief The seen-space rule's settings (mapping config keys `seen.margin_m`, `seen.horizon_s`).
struct SeenRule {
  /// Every voxel centre within this distance (m) of a braking path must have been observed
  /// (> 0; default 0.3: the followers' body radius).
  double margin_m = 0.3;
  /// Plan points within this time (s) of the plan's start are checked (> 0; default 1.0: more
  /// than the replanning period, so that a failed replanning still finds the UAV able to stop
  /// inside seen space).
  double horizon_s = 1.0;
};

class SeenSpace {
 public:
  /// \brief Nothing seen, over the grid of `map` (resolution, origin, size).
  SeenSpace(const OccupancyMap& map, const SeenRule& rule);

  const SeenRule& rule() const { return rule_; }
  double resolution() const { return resolution_m_; }

  /// \brief Marks the grid voxel with linear index `local_linear` (x fastest) as observed.
  void markLinear(std::size_t local_linear) { seen_[local_linear] = 1; }
  /// \brief Marks every occupied voxel of `map` (same grid) as observed (a prior map: surveyed).
  void markOccupied(const OccupancyMap& map);
  /// \brief The voxel containing p (world) has been observed (false outside the grid).
  bool seen(const Eigen::Vector3d& p_world) const;
  /// \brief Number of observed voxels.
  std::size_t seenCount() const;

  /// \brief The first voxel centre (world) within `margin_m` of p that has not been observed
  /// and is not within `margin_m` of `exempt_world`; none when every such voxel is seen.
  std::optional<Eigen::Vector3d> unseenNear(const Eigen::Vector3d& p_world, const Eigen::Vector3d& exempt_world) const;

 private:
  bool seenLocal(const VoxelIndex& local) const;

  SeenRule rule_;
  double resolution_m_ = 0.2;
  VoxelIndex origin_ = VoxelIndex::Zero();
  VoxelIndex size_ = VoxelIndex::Zero();
  std::vector<std::uint8_t> seen_;
};

}  // namespace gesture_formation::planning

#pragma once
/// \file
/// \brief Clearance queries against the occupancy map. Two implementations, compared in
/// bench/bench_planning.cpp (decision and figures: docs/planning.md §2):
/// - DistanceField: an exact Euclidean distance transform (Felzenszwalb & Huttenlocher 2012,
///   separable, O(voxels)) over the map's dense grid, storing at every voxel centre the
///   distance to the nearest occupied voxel centre. O(1) queries.
/// - FclClearance: FCL's distance between a small sphere and fcl::OcTree over the OctoMap.
/// Thread safety: const queries of DistanceField may run concurrently; FclClearance may not.

#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/planning/occupancy_map.hpp"

namespace gesture_formation::planning {

class DistanceField {
 public:
  /// \brief Builds the transform over `map.gridBounds()` (4 bytes per voxel).
  explicit DistanceField(const OccupancyMap& map);

  /// \brief Lower bound (m) on the distance from p (world) to the nearest occupied voxel
  /// centre: d(c) − |p − c| with c the centre of the voxel nearest to p inside the grid
  /// (exact at voxel centres, low by at most √3·resolution elsewhere; the distance function
  /// is 1-Lipschitz, so the bound also holds outside the grid). Never negative; +inf for an
  /// empty map.
  double clearance(const Eigen::Vector3d& p_world) const;
  /// \brief Distance (m) stored at a voxel centre (grid-local index, must be inside).
  float atLocal(int i, int j, int k) const {
    return dist_m_[static_cast<std::size_t>(i) +
                   static_cast<std::size_t>(size_.x()) *
                       (static_cast<std::size_t>(j) + static_cast<std::size_t>(size_.y()) * static_cast<std::size_t>(k))];
  }
  std::size_t memoryBytes() const { return dist_m_.size() * sizeof(float); }

 private:
  double resolution_m_;
  VoxelIndex origin_;
  VoxelIndex size_;
  std::vector<float> dist_m_;
};

/// \brief Clearance through FCL: distance (m) from p to the nearest occupied OctoMap voxel's
/// cube (not its centre: it is smaller than the centre distance by up to √3/2·resolution);
/// 0 when p lies inside an occupied voxel; +inf for an empty map.
class FclClearance {
 public:
  explicit FclClearance(const OccupancyMap& map);
  ~FclClearance();
  FclClearance(const FclClearance&) = delete;
  FclClearance& operator=(const FclClearance&) = delete;

  double clearance(const Eigen::Vector3d& p_world) const;
  /// \brief True when the ball of radius `radius_m` around p touches an occupied voxel's
  /// cube (FCL collision, no distance): the cheap check for verifying a trajectory.
  bool collides(const Eigen::Vector3d& p_world, double radius_m) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gesture_formation::planning

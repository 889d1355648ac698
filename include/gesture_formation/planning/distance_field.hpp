#pragma once
/// \file
/// \brief Clearance queries against the occupancy map. Two implementations, compared in
/// bench/bench_planning.cpp (decision and figures: docs/planning.md §2):
/// - DistanceField: an exact Euclidean distance transform (Felzenszwalb & Huttenlocher 2012,
///   separable, O(voxels)) over the map's dense grid, storing at every voxel centre the
///   distance to the nearest occupied voxel centre. O(1) queries. Stored as the squared
///   distance in voxels² (2 bytes a voxel; every such distance is √n·resolution for an integer
///   n) and read through a table of the 65 536 values: exact below 256 voxels (51.2 m at 0.2 m),
///   the cap's distance beyond it (still a lower bound).
///   A truncated field (DistanceField::truncated, the live map's) stores min(distance, range) and
///   can be updated in place after occupancy changes (DistanceField::update). It keeps the
///   transform's two intermediate passes (squared distances along x, then in x–y planes, capped
///   at the range²: 2 × 2 bytes per voxel), so an update re-runs only the 1-D transforms whose
///   input changed: the x rows of the changed voxels, the y columns within the range of them,
///   the z columns within the range of those. The result equals a full rebuild bit for bit
///   (docs/mapping.md §2).
/// - FclClearance: FCL's distance between a small sphere and fcl::OcTree over the OctoMap.
/// Thread safety: const queries of DistanceField may run concurrently; update() must not run
/// concurrently with anything else on the same field. FclClearance is not thread-safe; it
/// reads the map's OctoMap at every query (a live map's in-place updates are seen).

#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"

namespace gesture_formation::planning {

/// \brief What DistanceField::update recomputed.
struct FieldUpdateStats {
  int changed_voxels = 0;          ///< voxels whose occupancy changed (the input)
  int lines = 0;                   ///< 1-D transforms run (x rows + y columns + z columns)
  std::size_t voxels_written = 0;  ///< final values recomputed (within the range of the changes)
};

class DistanceField {
 public:
  /// \brief Builds the transform over `map.gridBounds()` (2 bytes per voxel), untruncated: beyond
  /// 256 voxels from every obstacle the value is 256 voxels' distance (+inf on an empty map).
  explicit DistanceField(const OccupancyMap& map);
  /// \brief A field truncated at `max_distance_m` (> 0, finite, at most 255 voxels): every value is
  /// min(distance, max_distance_m) — still a lower bound of the distance, so every clearance
  /// check stays safe, but a clearance above the range is never seen (a caller asking for
  /// more, e.g. an abort goal's clearance, finds nothing). Fails naming a bad range.
  static common::Result<DistanceField> truncated(const OccupancyMap& map, double max_distance_m);

  /// \brief The truncation range (m); +inf for an untruncated field.
  double maxDistance() const { return max_distance_m_; }

  /// \brief After the voxels `changed_voxels` (world voxel indices, as returned by
  /// OccupancyMap::setOccupancy) changed occupancy in `map` (the map this field was built from,
  /// already updated), recomputes the values that can change — those within the range of a
  /// changed voxel — by re-running the 1-D transforms whose input changed (see the file
  /// comment). The result equals a full rebuild over the updated map. An untruncated field
  /// recomputes the whole grid. Fails (field unchanged) when `map`'s grid differs from the
  /// field's.
  common::Result<FieldUpdateStats> update(const OccupancyMap& map, const std::vector<VoxelIndex>& changed_voxels);

  /// \brief Lower bound (m) on the distance from p (world) to the nearest occupied voxel
  /// centre: d(c) − |p − c| with c the centre of the voxel nearest to p inside the grid
  /// (exact at voxel centres, low by at most √3·resolution elsewhere; the distance function
  /// is 1-Lipschitz, so the bound also holds outside the grid). Never negative; +inf for an
  /// empty map.
  double clearance(const Eigen::Vector3d& p_world) const;
  /// \brief Distance (m) stored at a voxel centre (grid-local index, must be inside).
  float atLocal(int i, int j, int k) const { return metres_[squared_[linear(i, j, k)]]; }
  std::size_t memoryBytes() const {
    return squared_.size() * sizeof(std::uint16_t) + metres_.size() * sizeof(float) +
           (pass1_.size() + pass2_.size()) * sizeof(std::uint16_t);
  }

 private:
  DistanceField(const OccupancyMap& map, double max_distance_m);
  /// The untruncated transform of the whole grid, in place (see the .cpp).
  void recomputeAll(const std::vector<std::uint8_t>& occupancy);
  /// The truncated field's passes, one 1-D transform each: the x row (j, k) of pass1_ from the
  /// occupancy, the y column (i, k) of pass2_ from pass1_, the z column (i, j) of the field from
  /// pass2_ (written for k in [k_lo, k_hi]). A line without any finite input is far throughout.
  void rowX(const std::vector<std::uint8_t>& occupancy, int j, int k);
  void columnY(int i, int k);
  void columnZ(int i, int j, int k_lo, int k_hi);
  /// The truncated update (see update()); returns what it ran.
  FieldUpdateStats updateTruncated(const std::vector<std::uint8_t>& occupancy, const std::vector<VoxelIndex>& changed);
  /// Metres from a squared distance in voxels² (the one conversion, shared by build and update).
  float toMetres(double squared_voxels) const;
  std::size_t linear(int i, int j, int k) const {
    return static_cast<std::size_t>(i) +
           static_cast<std::size_t>(size_.x()) *
               (static_cast<std::size_t>(j) + static_cast<std::size_t>(size_.y()) * static_cast<std::size_t>(k));
  }

  double resolution_m_;
  double max_distance_m_ = std::numeric_limits<double>::infinity();
  int range_voxels_ = 0;  ///< ceil(max_distance_m / resolution), 0 when untruncated
  VoxelIndex origin_;
  VoxelIndex size_;
  /// Per voxel: the squared distance in voxels² (untruncated: capped at kFarSquared; truncated:
  /// ≤ range_voxels_², else kFarSquared); metres_ holds the value of each (kFarSquared: beyond the
  /// cap or the range).
  std::vector<std::uint16_t> squared_;
  std::vector<float> metres_;
  /// Truncated fields: squared distances (voxels²) after the x pass and after the y pass, capped:
  /// values above range_voxels_² are kFarSquared.
  std::vector<std::uint16_t> pass1_, pass2_;
  std::vector<double> line_f_, line_d_, line_z_;  ///< one line's input, output, parabola bounds
  std::vector<int> line_v_;                         ///< one line's parabola vertices
  static constexpr std::uint16_t kFarSquared = 0xFFFF;
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

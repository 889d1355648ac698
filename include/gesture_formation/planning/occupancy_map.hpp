#pragma once
/// \file
/// \brief The environment map: an OctoMap (octomap::OcTree) of occupied voxels plus, over
/// the map's bounded region, a dense voxel grid and a block index of the occupied voxel
/// centres for fast box queries (corridor decomposition, distance field).
///
/// Rasterisation rule (docs/planning.md §1): a voxel is occupied when its centre lies within
/// ρ = (√3/2)·resolution of a solid — the half diagonal of a voxel. Every voxel that touches a
/// solid is then occupied (the voxels cover every obstacle, so conductors of 3 cm still
/// occupy a voxel chain), and every occupied voxel lies within √3·resolution of a solid.
/// Voxels follow OctoMap's grid: voxel i spans [i·res, (i+1)·res), its centre is (i+½)·res.
/// Thread safety: const methods may be called concurrently once built.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/planning/obstacle_points.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/planning/shapes.hpp"

namespace octomap {
class OcTree;
}

namespace gesture_formation::planning {

/// \brief Integer voxel index (OctoMap grid, not offset by OctoMap's key origin).
using VoxelIndex = Eigen::Vector3i;

class OccupancyMap : public ObstaclePoints {
 public:
  /// \brief Rasterises the scenario's solids (and merges its `map.octomap_file`, if any).
  /// Fails when the `.bt` file cannot be read or its resolution differs.
  static common::Result<OccupancyMap> fromScenario(const Scenario& scenario);
  /// \brief Rasterises solids and an optional ground into an empty map.
  static OccupancyMap fromPrimitives(const MapConfig& map, const PrimitiveSet& solids, const GroundSpec& ground);
  /// \brief Loads a `.bt` file; voxels outside `map.bounds` are dropped (counted in
  /// `droppedVoxels()`). Its resolution must equal `map.resolution_m`.
  static common::Result<OccupancyMap> fromOctomapFile(const MapConfig& map, const std::string& path);

  /// \brief The half-diagonal inflation ρ (m) used by the rasteriser at this resolution.
  static double rasterInflation(double resolution_m);

  double resolution() const { return resolution_m_; }
  /// \brief The region the dense grid covers (whole voxels; contains the configured bounds).
  const Aabb& gridBounds() const { return grid_bounds_; }
  const VoxelIndex& gridOrigin() const { return origin_; }
  const VoxelIndex& gridSize() const { return size_; }
  /// \brief Centres of all occupied voxels, world frame (m), ordered by block.
  const std::vector<Eigen::Vector3d>& occupiedCenters() const { return centers_; }
  std::size_t occupiedCount() const { return centers_.size(); }
  std::size_t droppedVoxels() const { return dropped_; }

  /// \brief Index of the voxel containing p (world, m).
  VoxelIndex voxelOf(const Eigen::Vector3d& p_world) const;
  Eigen::Vector3d centerOf(const VoxelIndex& v) const { return (v.cast<double>().array() + 0.5).matrix() * resolution_m_; }
  /// \brief True when the voxel lies in the grid and is occupied (outside the grid: free).
  bool isOccupied(const VoxelIndex& v) const;
  bool isOccupied(const Eigen::Vector3d& p_world) const { return isOccupied(voxelOf(p_world)); }
  /// \brief Dense occupancy, x fastest: index (i + nx (j + ny k)) relative to gridOrigin().
  const std::vector<std::uint8_t>& denseGrid() const { return grid_; }

  /// \brief Appends the occupied voxel centres inside the closed box (ObstaclePoints).
  void pointsInBox(const Aabb& box, std::vector<Eigen::Vector3d>& out) const override;

  /// \brief The OctoMap (max-depth voxels, pruned; occupancy = clamping max). Shared with FCL.
  std::shared_ptr<const octomap::OcTree> octree() const { return octree_; }
  /// \brief Writes the OctoMap as `.bt`. Returns an empty string or the reason of failure.
  std::string writeBinary(const std::string& path) const;

 private:
  explicit OccupancyMap(const MapConfig& map);
  void rasterise(const PrimitiveSet& solids, const GroundSpec& ground);
  void markFromOctree(const octomap::OcTree& tree);
  /// Builds centres_, the block index and the OctoMap from grid_.
  void finalise();
  std::size_t linear(const VoxelIndex& local) const {
    return static_cast<std::size_t>(local.x()) +
           static_cast<std::size_t>(size_.x()) *
               (static_cast<std::size_t>(local.y()) + static_cast<std::size_t>(size_.y()) * static_cast<std::size_t>(local.z()));
  }

  static constexpr int kBlock = 8;  ///< block edge in voxels for the point index

  double resolution_m_ = 0.2;
  Aabb grid_bounds_;
  VoxelIndex origin_ = VoxelIndex::Zero();
  VoxelIndex size_ = VoxelIndex::Zero();
  VoxelIndex blocks_ = VoxelIndex::Zero();
  std::vector<std::uint8_t> grid_;
  std::vector<Eigen::Vector3d> centers_;
  std::vector<std::uint32_t> block_start_;  ///< CSR offsets into centres_, one per block + 1
  std::size_t dropped_ = 0;
  std::shared_ptr<const octomap::OcTree> octree_;
};

}  // namespace gesture_formation::planning

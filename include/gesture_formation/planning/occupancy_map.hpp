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
/// Thread safety: const methods may be called concurrently once built. setOccupancy() (the live
/// map's update, mapping::LiveMap) changes the map in place: it must not run concurrently with
/// any other method (the caller serialises; LiveMap does it with a reader/writer lock).

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

/// \brief A voxel's new state for OccupancyMap::setOccupancy (world voxel index).
struct VoxelChange {
  VoxelIndex voxel = VoxelIndex::Zero();
  bool occupied = false;
};

class OccupancyMap : public ObstaclePoints {
 public:
  /// Copies are deep (the copy owns its own OctoMap); moves keep it.
  OccupancyMap(const OccupancyMap& other);
  OccupancyMap& operator=(const OccupancyMap& other);
  OccupancyMap(OccupancyMap&&) noexcept = default;
  OccupancyMap& operator=(OccupancyMap&&) noexcept = default;
  ~OccupancyMap() override = default;

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
  /// \brief Centres of all occupied voxels, world frame (m), ordered by block (a copy).
  std::vector<Eigen::Vector3d> occupiedCenters() const;
  std::size_t occupiedCount() const { return occupied_count_; }
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
  /// \brief Sets voxels occupied or free in place — the dense grid, the block index and the
  /// OctoMap (a freed voxel's node is set free), so that everything holding this map (the
  /// distance field's update, FclClearance, the corridor builder) sees the new state. Voxels
  /// outside the grid are ignored. Returns the voxels whose state changed (the input for
  /// DistanceField::update). Cost: O(changes · (block occupancy + tree depth)).
  std::vector<VoxelIndex> setOccupancy(const std::vector<VoxelChange>& changes);

  /// \brief Writes the OctoMap as `.bt`. Returns an empty string or the reason of failure.
  std::string writeBinary(const std::string& path) const;

 private:
  explicit OccupancyMap(const MapConfig& map);
  void rasterise(const PrimitiveSet& solids, const GroundSpec& ground);
  void markFromOctree(const octomap::OcTree& tree);
  /// Builds the block index and the OctoMap from grid_.
  void finalise();
  std::size_t blockOfLocal(const VoxelIndex& local) const {
    return static_cast<std::size_t>(local.x() / kBlock) +
           static_cast<std::size_t>(blocks_.x()) * (static_cast<std::size_t>(local.y() / kBlock) +
                                                    static_cast<std::size_t>(blocks_.y()) *
                                                        static_cast<std::size_t>(local.z() / kBlock));
  }
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
  /// Occupied voxel centres per kBlock³ block (x fastest), each in grid scan order when built.
  std::vector<std::vector<Eigen::Vector3d>> block_centers_;
  std::size_t occupied_count_ = 0;
  std::size_t dropped_ = 0;
  std::shared_ptr<octomap::OcTree> octree_;
};

}  // namespace gesture_formation::planning

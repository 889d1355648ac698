#pragma once
/// \file
/// \brief Online mapping (docs/mapping.md): depth frames integrated into an OctoMap with
/// ray-cast free space, fused with an optional prior map, and the planner's map and distance
/// field updated in place — only the voxels that changed, and the field only within its range
/// of them.
///
///   per depth frame:  live_map.integrate(frame)      // the one call (any thread, one at a time)
///   planners:         UavPlanner(cfg, live_map.map(), live_map.field())   // shared, never copied
///                     RetreatSpace{live_map.field().get(), live_map.map()->gridBounds(), ...}
///
/// Fusion: a voxel of the planner's map is occupied when the prior map has it or the observed
/// OctoMap holds it occupied (log-odds above 0). Prior voxels stay occupied whatever the camera
/// sees: the prior is surveyed geometry (towers, 3 cm conductors the depth camera does not
/// resolve at range), and a few rays through a thin wire's voxel must not erase it. Space never
/// observed is free for the planner, as it is today outside the prior's solids.
///
/// Thread safety: integrate() must not run concurrently with itself. It ray-casts into its own
/// OctoMap without any lock and takes the writer lock of readLock()'s mutex only while it
/// applies the changes to map() and field() (usually well under a millisecond). A planner on
/// another thread holds readLock() for a whole replanning (ReplanStep::step / UavPlanner::plan),
/// so that it never sees a half-applied update; on the same thread no lock is needed. map() and
/// field() point to the same objects for the live map's lifetime.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <shared_mutex>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <octomap/OcTree.h>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/mapping/depth_points.hpp"
#include "gesture_formation/mapping/mapping_config.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/planning/seen_space.hpp"


namespace gesture_formation::mapping {

/// \brief What one integrate() did and how long each stage took (wall clock, ms).
struct FrameUpdate {
  int pixels = 0;           ///< pixels looked at after decimation
  int hits = 0;             ///< returns within range
  int free_rays = 0;        ///< returns beyond max_range_m / +Inf (free space only)
  int skipped = 0;          ///< invalid or nearer than min_range_m
  int rays_cast = 0;        ///< rays after merging returns that end in the same voxel
  int observed_changes = 0; ///< OctoMap voxels created or flipped by this frame
  int map_changes = 0;      ///< voxels of the planner's map that changed (fused with the prior)
  planning::FieldUpdateStats field;
  double points_ms = 0.0;   ///< decimation, back-projection, merging
  double raycast_ms = 0.0;  ///< OctoMap insertPointCloud
  double map_ms = 0.0;      ///< fusion and OccupancyMap::setOccupancy
  double field_ms = 0.0;    ///< DistanceField::update
  double total_ms = 0.0;
};

/// \brief The observed state of a voxel in the live OctoMap (not fused with the prior).
enum class Observed { kUnknown, kFree, kOccupied };

class LiveMap {
 public:
  /// \brief A live map over `grid` (resolution and bounds of the planner's map), starting from
  /// `prior` (null: empty). Fails naming every bad setting, a bad grid, or a prior whose grid
  /// differs from `grid`'s.
  static common::Result<std::unique_ptr<LiveMap>> create(const MappingConfig& config, const planning::MapConfig& grid,
                                                         std::shared_ptr<const planning::OccupancyMap> prior = nullptr);
  ~LiveMap();
  LiveMap(const LiveMap&) = delete;
  LiveMap& operator=(const LiveMap&) = delete;

  /// \brief Integrates one depth frame (the one call per frame, see the file comment). Fails,
  /// changing nothing, when the frame is bad (depthToPoints' reasons).
  common::Result<FrameUpdate> integrate(const DepthFrame& frame);

  /// \brief The planner's map: the prior fused with the observed occupancy (updated in place).
  std::shared_ptr<const planning::OccupancyMap> map() const { return map_; }
  /// \brief The planner's distance field over map(), truncated at config().field_range_m.
  std::shared_ptr<const planning::DistanceField> field() const { return field_; }
  /// \brief The space observed so far (every voxel a ray crossed or ended in, and the prior's
  /// occupied voxels), for the planners' seen-space rule (planning/seen_space.hpp).
  std::shared_ptr<const planning::SeenSpace> seen() const { return seen_; }
  /// \brief A shared lock on the map and field: hold it while planning on another thread.
  std::shared_lock<std::shared_mutex> readLock() const { return std::shared_lock<std::shared_mutex>(mutex_); }

  /// \brief The observed state of the voxel containing p (world, m): the OctoMap alone.
  Observed observed(const Eigen::Vector3d& p_world) const;
  /// \brief The observed OctoMap (log-odds, pruned); not to be read while integrate() runs.
  const octomap::OcTree& observedTree() const { return *tree_; }
  const MappingConfig& config() const { return config_; }

 private:
  LiveMap(const MappingConfig& config, std::shared_ptr<planning::OccupancyMap> map,
          std::shared_ptr<planning::DistanceField> field, std::shared_ptr<const planning::OccupancyMap> prior);
  /// The rays' ends: the first return per end voxel, hits (the first `hits`) before free rays.
  std::vector<octomap::point3d> rayEnds(const DepthPoints& points, std::size_t& hits);
  /// Ray-casts the points into tree_ as OctoMap's insertPointCloud does; returns rays cast.
  int castRays(const DepthPoints& points);
  /// Linear index of the key's voxel in the planner's grid, −1 outside it.
  std::ptrdiff_t gridIndex(const octomap::OcTreeKey& key) const {
    const int i = key[0] - key_origin_.x(), j = key[1] - key_origin_.y(), k = key[2] - key_origin_.z();
    if (i < 0 || j < 0 || k < 0 || i >= grid_size_.x() || j >= grid_size_.y() || k >= grid_size_.z()) return -1;
    return i + static_cast<std::ptrdiff_t>(grid_size_.x()) * (j + static_cast<std::ptrdiff_t>(grid_size_.y()) * k);
  }
  /// One hit or miss of a voxel (index −1: outside the grid), skipped when OctoMap would abort it.
  void updateVoxel(const octomap::OcTreeKey& key, std::ptrdiff_t index, bool hit);
  /// The changed OctoMap voxels as planner-map changes (fused with the prior); clears the record.
  std::vector<planning::VoxelChange> fusedChanges(int& observed_changes);

  MappingConfig config_;
  std::shared_ptr<planning::OccupancyMap> map_;
  std::shared_ptr<planning::DistanceField> field_;
  std::shared_ptr<const planning::OccupancyMap> prior_;
  std::shared_ptr<planning::SeenSpace> seen_;
  std::unique_ptr<octomap::OcTree> tree_;
  octomap::KeyRay keyray_;  ///< castRays' scratch
  std::vector<std::pair<octomap::OcTreeKey, std::ptrdiff_t>> free_cells_, occupied_cells_;  ///< castRays' scratch
  std::vector<std::size_t> touched_;                                                          ///< castRays' scratch
  planning::VoxelIndex key_origin_ = planning::VoxelIndex::Zero();  ///< OctoMap key of the grid's first voxel
  planning::VoxelIndex grid_size_ = planning::VoxelIndex::Zero();
  std::vector<std::uint8_t> mark_;       ///< per grid voxel, this frame: 1 free cell, 2 occupied cell
  std::vector<std::uint8_t> saturated_;  ///< per grid voxel: kSaturatedFree / kSaturatedOccupied / 0
  mutable std::shared_mutex mutex_;
  static constexpr int kKeyOrigin = 32768;  ///< OctoMap's key of voxel index 0 (tree depth 16)
  static constexpr std::uint8_t kSaturatedFree = 1;
  static constexpr std::uint8_t kSaturatedOccupied = 2;
};

}  // namespace gesture_formation::mapping

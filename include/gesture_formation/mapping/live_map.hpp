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
#include "gesture_formation/mapping/map_delta.hpp"
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
  std::size_t tree_nodes = 0;  ///< the observed OctoMap's nodes after the frame (pruned in batches)
  planning::FieldUpdateStats field;
  double points_ms = 0.0;   ///< decimation, back-projection, merging
  double raycast_ms = 0.0;  ///< OctoMap insertPointCloud
  double map_ms = 0.0;      ///< fusion and OccupancyMap::setOccupancy
  double field_ms = 0.0;    ///< DistanceField::update
  double total_ms = 0.0;
};

/// \brief What one merge() of another UAV's changes did.
struct MergeResult {
  int voxels = 0;       ///< voxels in the delta
  int superseded = 0;   ///< ignored: seen by this UAV (or received) at or after the delta's stamp
  int map_changes = 0;  ///< voxels of the planner's map that changed
  planning::FieldUpdateStats field;
  double total_ms = 0.0;
};

/// \brief What one takeChanges() did.
struct OutgoingStats {
  int sent = 0;      ///< voxels in the returned delta (new changes and resent ones)
  int refreshed = 0; ///< of them, occupied voxels sent before, resent (share.refresh_share)
  int deferred = 0;  ///< changes left for a later update (over the voxel budget)
  int dropped = 0;   ///< changes older than max_age_s when their turn came: never sent
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

  /// \brief Merges another UAV's map changes (docs/mapping.md §8). Per voxel, the newer word wins:
  /// a received class is ignored where this UAV's own rays crossed or ended in the voxel at or after
  /// `delta.stamp_s` (or a newer received class is held), and a later own frame through the voxel
  /// replaces it; a received "free" never clears a voxel this UAV's own camera holds occupied, and
  /// an own return replaces a received "free" whatever the stamps. Received occupied voxels enter the map and the field like observed ones; prior
  /// voxels stay occupied. Received voxels do NOT count as seen for the seen-space rule (§8 why).
  /// Fails, changing nothing, on a delta that does not fit keyGrid() (naming the field).
  /// Same thread rules as integrate() (never concurrently with it or itself).
  common::Result<MergeResult> merge(const MapDelta& delta);
  /// \brief This UAV's own observed changes not yet sent (docs/mapping.md §8): voxels whose observed
  /// class became occupied, or free after being sent occupied (prior voxels are never sent). At most
  /// `max_voxels` of them, the nearest to `p_sender_world` first (ties: the newest); changes older
  /// than `max_age_s` at `now_s` are dropped, the rest wait for the next call. Stamped with the
  /// newest integrated frame's time. Not concurrently with integrate().
  MapDelta takeChanges(const Eigen::Vector3d& p_sender_world, double now_s, std::size_t max_voxels, double max_age_s,
                       OutgoingStats* stats = nullptr);
  /// \brief The clock went back (ROS time: a simulation restarted, a bag looped) to `now_s`: the
  /// map, the field and the seen space are kept (what was seen stays — the safe side), the times
  /// of the old timeline are forgotten — every voxel's own and received stamps (a new word of
  /// either wins) — and the newest frame's stamp and the changes waiting to be sent are dated now_s.
  /// Not concurrently with integrate(), merge() or takeChanges().
  void restartClock(double now_s);
  /// \brief Own changes waiting to be sent.
  std::size_t pendingChanges() const { return pending_.size(); }
  /// \brief The keys this map holds (resolution and grid), what merge() accepts.
  KeyGrid keyGrid() const;

  /// \brief The observed state of the voxel containing p (world, m): the OctoMap alone.
  Observed observed(const Eigen::Vector3d& p_world) const;
  /// \brief The observed OctoMap (log-odds per voxel; pruned in batches, inner nodes' occupancy
  /// not maintained: call updateInnerOccupancy() on a copy before reading coarser depths); not to
  /// be read while integrate() runs.
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
  /// Prunes tree_ when it has doubled since the last pruning (updates are lazy: see updateVoxel).
  void pruneWhenGrown();
  /// One hit or miss of a voxel (index −1: outside the grid), skipped when OctoMap would abort it.
  void updateVoxel(const octomap::OcTreeKey& key, std::ptrdiff_t index, bool hit);
  /// The changed OctoMap voxels, and the voxels of this frame that held a received class, as
  /// planner-map changes (fused with the prior and the received classes); clears the record.
  std::vector<planning::VoxelChange> fusedChanges(int& observed_changes, const std::vector<std::size_t>& recheck);
  /// This frame's own observations: stamps, received classes they replace (returned: to re-fuse).
  std::vector<std::size_t> stampOwnCells(double stamp_s);
  /// The planner's voxel (fused): prior, else a received class, else the own observation.
  bool fusedOccupied(std::size_t index, const planning::VoxelIndex& voxel, bool own_occupied) const;
  bool ownOccupied(std::size_t index) const;
  planning::VoxelIndex voxelOfIndex(std::size_t index) const;
  octomap::OcTreeKey keyOfIndex(std::size_t index) const;
  /// Queues an own change of the voxel for sharing when its class differs from what was sent.
  void notePending(std::size_t index, const planning::VoxelIndex& voxel, bool own_occupied, double stamp_s);

  MappingConfig config_;
  std::shared_ptr<planning::OccupancyMap> map_;
  std::shared_ptr<planning::DistanceField> field_;
  std::shared_ptr<const planning::OccupancyMap> prior_;
  std::shared_ptr<planning::SeenSpace> seen_;
  std::unique_ptr<octomap::OcTree> tree_;
  std::size_t nodes_after_prune_ = 0;  ///< tree_'s size after its last pruning
  octomap::KeyRay keyray_;  ///< castRays' scratch
  std::vector<std::pair<octomap::OcTreeKey, std::ptrdiff_t>> free_cells_, occupied_cells_;  ///< castRays' scratch
  std::vector<std::size_t> touched_;                                                          ///< castRays' scratch
  planning::VoxelIndex key_origin_ = planning::VoxelIndex::Zero();  ///< OctoMap key of the grid's first voxel
  planning::VoxelIndex grid_size_ = planning::VoxelIndex::Zero();
  std::vector<std::uint8_t> mark_;       ///< per grid voxel, scratch: 1 free / 2 occupied cell of this frame; 3 changed; 4 sent in this update
  std::vector<std::uint8_t> saturated_;  ///< per grid voxel: kSaturatedFree / kSaturatedOccupied / 0
  // Sharing (docs/mapping.md §8), per grid voxel:
  std::vector<double> own_s_;             ///< the last own frame whose ray crossed or ended in it (−inf: none)
  std::vector<std::uint8_t> received_;    ///< kReceivedNone / kReceivedOccupied / kReceivedFree
  std::vector<double> received_s_;        ///< the received class's stamp
  std::vector<std::uint8_t> announced_;   ///< bit 0: sent as occupied (receivers hold it occupied); bit 1: in refresh_
  std::vector<std::size_t> refresh_;      ///< voxels sent as occupied, resent round robin (share.refresh_share)
  std::size_t refresh_cursor_ = 0;
  std::vector<std::uint8_t> pending_mark_;
  std::vector<double> pending_s_;         ///< when the pending change was observed
  std::vector<std::size_t> pending_;      ///< grid voxels with an unsent own change
  double map_stamp_s_ = 0.0;              ///< the newest integrated frame's stamp
  mutable std::shared_mutex mutex_;
  static constexpr std::uint8_t kReceivedNone = 0;
  static constexpr std::uint8_t kReceivedOccupied = 1;
  static constexpr std::uint8_t kReceivedFree = 2;
  static constexpr int kKeyOrigin = 32768;  ///< OctoMap's key of voxel index 0 (tree depth 16)
  static constexpr std::uint8_t kSaturatedFree = 1;
  static constexpr std::uint8_t kSaturatedOccupied = 2;
};

}  // namespace gesture_formation::mapping

#pragma once
/// \file
/// \brief What `gfctl simulate` reports about the unmapped obstacles and the UAVs' online mapping
/// (sim::SiteMapping; metrics.json `site_mapping`, keys in docs/simulation.md §4).
/// Thread safety: value types and pure functions.

#include <limits>
#include <string>
#include <vector>

namespace gesture_formation::sim {

/// \brief One unmapped obstacle's record.
struct UnmappedObstacleRecord {
  std::string name;
  /// Surface voxels of the obstacle (at its listed pose) and how many of them any UAV's live map
  /// held occupied while the obstacle was there; coverage = seen / surface (0 without mapping).
  int surface_voxels = 0;
  int surface_voxels_seen = 0;
  double coverage = 0.0;
  /// The first depth frame after which a UAV's live map held a voxel of the obstacle occupied
  /// (NaN: never seen) and that UAV.
  double first_seen_s = std::numeric_limits<double>::quiet_NaN();
  int first_seen_uav = -1;
  /// That UAV's first verified plan at or after first_seen_s whose every sample keeps
  /// planner.obstacle_clearance_m from the obstacle (NaN: none); avoided_s − first_seen_s.
  double avoided_s = std::numeric_limits<double>::quiet_NaN();
  double sight_to_avoidance_s = std::numeric_limits<double>::quiet_NaN();
  /// Least distance (m) from any UAV's centre to the obstacle over the mission (true states).
  double min_distance_m = std::numeric_limits<double>::infinity();
  int min_distance_uav = -1;
  double min_distance_t_s = std::numeric_limits<double>::quiet_NaN();
};

/// \brief The mission's site-mapping summary.
/// \brief What the UAVs' map sharing did over a mission.
struct MapShareSummary {
  bool enabled = false;
  long updates_sent = 0;        ///< map updates sent (each to every other UAV)
  long updates_merged = 0;      ///< received, decoded, checked and merged
  long updates_lost = 0;        ///< lost on the links (the link model) or sent to / from an offline UAV
  long updates_refused = 0;     ///< refused by the decoder or the receiver's check (none expected)
  long voxels_sent = 0;
  long changes_deferred = 0;    ///< summed over updates: changes left for a later update (budget)
  long changes_dropped = 0;     ///< changes older than share.max_age_s before their turn: never sent
  long voxels_superseded = 0;   ///< received voxels the receiver had seen itself since (or held newer)
  /// Bytes each UAV sent per mission second (envelope included), over every UAV and second.
  double bytes_per_s_p50 = std::numeric_limits<double>::quiet_NaN();
  double bytes_per_s_max = std::numeric_limits<double>::quiet_NaN();
  /// The age (receiver's time − the sender's map stamp) of each merged update: median and largest.
  double age_s_p50 = std::numeric_limits<double>::quiet_NaN();
  double age_s_max = std::numeric_limits<double>::quiet_NaN();
  /// LiveMap::merge wall time per update (ms).
  double merge_ms_median = std::numeric_limits<double>::quiet_NaN();
  double merge_ms_p99 = std::numeric_limits<double>::quiet_NaN();
};

struct SiteMappingSummary {
  bool mapping = false;        ///< the UAVs kept live maps (mission.mapping.enabled)
  bool prior_map = true;       ///< the live maps started from the prior map
  std::string camera;          ///< "synthetic" (the analytic depth camera) or "rendered" (SiteMapping::useOfferedDepth)
  double clearance_m = 0.0;    ///< planner.obstacle_clearance_m: the avoidance criterion
  int depth_frames = 0;        ///< integrated, all UAVs
  /// Surface voxels of all unmapped obstacles seen / all: the map coverage.
  double coverage = 0.0;
  /// Least distance (m) from any UAV to any unmapped obstacle (+inf: none listed).
  double min_unmapped_distance_m = std::numeric_limits<double>::infinity();
  /// Per depth frame (wall clock, ms): the depth image (ray casting) and LiveMap::integrate.
  double depth_ms_median = std::numeric_limits<double>::quiet_NaN();
  double integrate_ms_median = std::numeric_limits<double>::quiet_NaN();
  double integrate_ms_p99 = std::numeric_limits<double>::quiet_NaN();
  std::vector<UnmappedObstacleRecord> obstacles;
  /// Map sharing (mission.mapping.share; docs/mapping.md §8); all zero / NaN when off.
  MapShareSummary share;
};

/// \brief The summary as a JSON object (non-finite numbers as null), `indent` spaces deep.
std::string siteMappingJson(const SiteMappingSummary& summary, int indent);

}  // namespace gesture_formation::sim

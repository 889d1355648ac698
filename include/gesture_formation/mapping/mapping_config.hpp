#pragma once
/// \file
/// \brief Settings of online mapping (mapping::LiveMap, docs/mapping.md): how a depth frame is
/// decimated and range-limited, the OctoMap sensor model, and the distance field's range. Every
/// number's range is written once, in mappingConfigFields(), which validate() and the YAML
/// reader share. Thread safety: value types and pure functions.

#include <cstddef>
#include <string>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/planning/seen_space.hpp"

namespace gesture_formation::common {
template <class Config>
struct FieldTable;
}  // namespace gesture_formation::common

namespace gesture_formation::mapping {

/// \brief Sharing map changes with the other UAVs (docs/mapping.md §8): keys `share.*`.
struct ShareConfig {
  /// `share.enabled` [false]: every UAV sends its own map changes and merges the others'.
  bool enabled = false;
  /// `share.rate_hz` [2, in (0, 10]]: updates per second and UAV (an update only when something changed).
  double rate_hz = 2.0;
  /// `share.max_bytes_per_s` [50 000, in [1 000, 10 000 000]]: each UAV's sending budget, envelope
  /// included; an update carries at most (max_bytes_per_s / rate_hz − 118) / 6 voxels (and at most
  /// mapping::kMaxMapUpdateVoxels), the nearest to the sender first; must allow one voxel per update.
  double max_bytes_per_s = 50000.0;
  /// `share.max_age_s` [5, in (0, 60]]: a change still unsent this long after it was observed is
  /// dropped (counted), not sent stale.
  double max_age_s = 5.0;
  /// `share.refresh_share` [0.25, in [0, 1]]: share of each update's voxel budget that resends voxels
  /// already sent as occupied (round robin, once the new changes are in), so that an update lost on
  /// the link costs a receiver an obstacle for at most one pass over the sender's obstacles, not for
  /// good; a lost "free" stays lost (the receiver keeps the obstacle: the safe side). 0: never resend.
  double refresh_share = 0.25;
};

/// \brief Voxels one update may carry under `share`'s budget (0: not even one).
std::size_t shareVoxelBudget(const ShareConfig& share);

/// \brief Online mapping settings (keys as in mappingConfigFields()).
struct MappingConfig {
  /// Decimation: every pixel_stride-th pixel of every pixel_stride-th row is used (1: all),
  /// key `depth.pixel_stride`, in [1, 64].
  int pixel_stride = 4;
  /// Returns nearer than this (range along the ray, m) are dropped — no ray at all (the camera's
  /// blind zone, propellers): `depth.min_range_m`, > 0.
  double min_range_m = 0.3;
  /// Returns farther than this (and +Inf, REP 118 "too far") clear the ray up to this range and
  /// mark nothing occupied (depth noise grows with range²): `depth.max_range_m`, > min_range_m.
  double max_range_m = 10.0;
  /// OctoMap sensor model: probability of a voxel holding a return being occupied
  /// (`octomap.prob_hit`, in (0.5, 1)) and of a voxel a ray passes being occupied
  /// (`octomap.prob_miss`, in (0, 0.5)); log-odds clamped to [clamping_min, clamping_max]
  /// (`octomap.clamping_min` in (0, 0.5), `octomap.clamping_max` in (0.5, 1)). With the defaults
  /// one return makes a never-seen voxel occupied (one clamped free needs three), and a voxel seen occupied for long is free again after
  /// ten rays through it (|log-odds(0.97)| / |log-odds(0.4)| ≈ 8.6).
  double prob_hit = 0.7;
  double prob_miss = 0.4;
  double clamping_min = 0.12;
  double clamping_max = 0.97;
  /// The distance field's range (m, `field.range_m`, > 0): values are min(distance, range) and an
  /// update recomputes only the voxels within the range of a change. Must cover the largest
  /// clearance any caller asks of the field (the planner's path clearance plus its allowances,
  /// 2.5 m with config/planner.yaml; an abort goal's goal_clearance_m, 3 m): a larger clearance
  /// is never found. The update's cost grows with range³.
  double field_range_m = 3.5;
  /// The seen-space rule the planners on this live map verify (planning/seen_space.hpp):
  /// `seen.margin_m` (> 0, default 0.3) and `seen.horizon_s` (> 0, default 1.0).
  planning::SeenRule seen;
  /// Sharing with the other UAVs (`share.*`).
  ShareConfig share;

  /// \brief Every problem, each "<prefix><key> must be ..., got v"; empty when valid.
  std::vector<std::string> validate(const std::string& prefix = "") const;
};

/// \brief MappingConfig's numbers with their ranges (keys `depth.pixel_stride`,
/// `depth.min_range_m`, `depth.max_range_m`, `octomap.prob_hit`, `octomap.prob_miss`,
/// `octomap.clamping_min`, `octomap.clamping_max`, `field.range_m`, `seen.margin_m`, `seen.horizon_s`,
/// `share.rate_hz`, `share.max_bytes_per_s`, `share.max_age_s`; `share.enabled` is a bool read by readMappingConfig).
const common::FieldTable<MappingConfig>& mappingConfigFields();

/// \brief Reads a MappingConfig under `prefix` (missing keys per the reader's mode); every
/// problem — ranges and the rules between fields — is recorded in `reader`.
MappingConfig readMappingConfig(common::ConfigReader& reader, const std::string& prefix = "");

}  // namespace gesture_formation::mapping

#pragma once
/// \file
/// \brief Settings of the UAVs' online mapping in `gfctl simulate` (scenario key
/// `mission.mapping`, docs/simulation.md §"Mapping the site", docs/mapping.md §7). Every number's
/// range is written once, in siteMappingConfigFields(), which validate() and the reader share.
/// Thread safety: value types and pure functions.

#include <string>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/mapping/mapping_config.hpp"

namespace gesture_formation::common {
template <class Config>
struct FieldTable;
}  // namespace gesture_formation::common

namespace gesture_formation::sim {

/// \brief `mission.mapping.*` (defaults in brackets).
struct SiteMappingConfig {
  /// `enabled` [false]: every UAV keeps a mapping::LiveMap from its depth frames and plans on it;
  /// false: every UAV plans on the prior map (the scenario's mapped obstacles) — blind to the
  /// unmapped ones. `gfctl simulate --mapping on|off` overrides it.
  bool enabled = false;
  /// `prior_map` [true]: the live map starts from the scenario's mapped obstacles; false: from an
  /// empty map ("no prior map"; `gfctl simulate --no-prior-map`).
  bool prior_map = true;
  /// `rate_hz` [5]: depth frames per second and UAV, in (0, 30].
  double rate_hz = 5.0;
  /// `camera_range_m` [20]: the synthetic depth camera's range (m, in [1, 100]): farther, or
  /// nothing hit, is +Inf (free space up to `depth.max_range_m`).
  double camera_range_m = 20.0;
  /// `travel_camera_hfov_deg` [0: none]: a second depth camera per UAV (640×480, square pixels,
  /// this horizontal field of view, in [0, 120]; 87: a RealSense D435's depth FOV) that looks along
  /// the UAV's intended direction of travel — from the UAV to its stage-1 reference
  /// `travel_lookahead_s` [1.5, in (0, 10]] ahead (its velocity when that is nearer than 0.3 m, else
  /// the last direction) — so that the braking paths the seen-space rule checks lie in view
  /// (docs/mapping.md §7). Its frames are integrated at `rate_hz` like the worker camera's.
  double travel_camera_hfov_deg = 0.0;
  double travel_lookahead_s = 1.5;
  /// `depth.*`, `octomap.*`, `field.*`, `seen.*`: the live map's settings (mapping::MappingConfig, defaults
  /// there: docs/mapping.md §4).
  mapping::MappingConfig live;

  /// \brief Every problem, each "<prefix><key> must be ..., got v"; empty when valid.
  std::vector<std::string> validate(const std::string& prefix = "") const;
};

/// \brief SiteMappingConfig's own numbers (`rate_hz`, `camera_range_m`) with their ranges.
const common::FieldTable<SiteMappingConfig>& siteMappingConfigFields();

/// \brief Reads `prefix` + `enabled`, `prior_map`, `rate_hz`, `camera_range_m` and the live map's
/// keys (missing keys keep their defaults); every problem is recorded in `reader`.
SiteMappingConfig readSiteMappingConfig(common::ConfigReader& reader, const std::string& prefix);

}  // namespace gesture_formation::sim

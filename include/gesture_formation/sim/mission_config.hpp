#pragma once
/// \file
/// \brief The `mission:` section of a scenario file (config/scenarios/*.yaml;
/// docs/simulation.md §2): worker route and gestures, UAVs with their plant parameters,
/// controller, odometry, wind, sensors, links, formation, gesture filter and mapping, planner,
/// estimator, operator requests and fault injection. The world sections (map, towers, …) are
/// the planning loader's (planning/scenario.hpp); this loader reads only `mission`.
///
/// Loading collects every problem at once, each as "file: key: message" naming the field and
/// value (common::ConfigReader), and refuses the mission if there is any. Plant limits have no
/// silent defaults: every key of `uavs[i].plant` is required. Other sections take the
/// documented defaults when absent. Thread safety: value types.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/estimation/estimator_config.hpp"
#include "gesture_formation/formation/formation_commands.hpp"
#include "gesture_formation/formation/formation_config.hpp"
#include "gesture_formation/gesture/gesture_filter.hpp"
#include "gesture_formation/gesture/gesture_mapping.hpp"
#include "gesture_formation/gesture/view_fusion.hpp"
#include "gesture_formation/planning/abort_mode.hpp"
#include "gesture_formation/planning/plan_request_builder.hpp"
#include "gesture_formation/sim/abort_drill.hpp"
#include "gesture_formation/planning/planner_config.hpp"
#include "gesture_formation/planning/replan_step.hpp"
#include "gesture_formation/sim/leader_handover.hpp"
#include "gesture_formation/sim/link.hpp"
#include "gesture_formation/sim/multirotor.hpp"
#include "gesture_formation/sim/odometry.hpp"
#include "gesture_formation/sim/site_mapping_config.hpp"
#include "gesture_formation/sim/synthetic_sensors.hpp"
#include "gesture_formation/sim/tracking_controller.hpp"
#include "gesture_formation/sim/wind.hpp"
#include "gesture_formation/sim/worker_approach.hpp"
#include "gesture_formation/sim/worker_model.hpp"
#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::sim {

/// \brief One simulated UAV (index 0 = leader, i = follower i).
struct UavConfig {
  std::string name;
  MultirotorParams plant;
  /// Start position; absent → the formation reference around the worker's start.
  std::optional<Eigen::Vector3d> initial_position;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief A scheduled operator request (docs/design.md §4 command).
struct OperatorRequest {
  double t_s = 0.0;
  std::string target_text;  ///< as written (for the timeline)
  formation::CommandTarget target;
  formation::Parameter parameter = formation::Parameter::kBeta;
  formation::CommandKind kind = formation::CommandKind::kIncrement;
  double amount = 0.0;
};

/// \brief A time window during which UAV `uav`'s planner is not run (fault injection).
struct PlannerOutage {
  int uav = 0;
  double from_s = 0.0, to_s = 0.0;
};

/// \brief A follower's onboard computer is down from `from_s` to `to_s` (reboot): it neither
/// plans nor sends nor receives; its flight controller completes the last loaded (verified)
/// plan and holds its end. After `to_s` it rejoins (docs/safety.md §2.4).
struct UavDropout {
  int uav = 1;
  double from_s = 0.0, to_s = 0.0;
};

/// \brief Gross errors of the range sensors (UWB, stereo): with `probability` per available
/// range, the range is off by ± U[min_error_m, max_error_m] (sign random).
struct RangeOutlierConfig {
  double probability = 0.0;  ///< [0, 1]
  double min_error_m = 3.0;  ///< ≥ 0
  double max_error_m = 15.0;  ///< ≥ min_error_m
};

/// \brief `mission.faults` (issue 9; docs/safety.md states what the UAVs do for each fault).
/// Windows are [from, to) in mission seconds. `faults.link`, `faults.operator_link` and
/// `faults.wind` override `mission.links.uav`, `mission.links.operator` and `mission.wind`
/// key by key (the loader applies them; they are not kept here).
struct FaultConfig {
  std::vector<std::pair<double, double>> camera_blackouts;  ///< [from, to] s: the leader sees no worker
  std::vector<PlannerOutage> planner_outages;
  std::vector<UavDropout> follower_dropouts;               ///< uav ≥ 1
  /// The ground station's link to UAV `uav` is down in [from_s, to_s) (`operator_outages:
  /// [{uav, from_s, to_s}]`): the operator's commands and abort copies sent to it then are lost.
  std::vector<PlannerOutage> operator_outages;
  std::vector<std::pair<double, double>> uwb_dropouts;     ///< [from, to] s: no UWB range
  std::vector<std::pair<double, double>> stereo_dropouts;  ///< [from, to] s: no stereo range
  RangeOutlierConfig range_outliers;
  double max_command_age_s = 5.0;  ///< an operator command older than this on arrival is rejected, > 0
  // max_share_age_s, max_worker_age_s, max_plan_age_s, avoid_all_plans and search_* are
  // MissionConfig::replan's (the onboard replanning settings, read by onboard::readOnboardSettings).
  /// An abort issued during the mission (`abort: {t_s, source: operator | gesture}`; fault profile
  /// abort_mid_mission; docs/safety.md §2.8). Absent: none.
  std::optional<AbortEvent> abort;
  /// The worker walks towards a UAV (`worker_approach: {t_s, uav, speed_mps, stop_m}`; fault
  /// profile worker_approaches_holding_uav; docs/safety.md §3). Absent: he keeps to his route.
  std::optional<WorkerApproach> worker_approach;
  /// The leader's radio dies (`leader_silence: {t_s, duration_s}`; fault profiles leader_dropout_*;
  /// docs/safety.md §1.2). Absent: none.
  std::optional<LeaderSilence> leader_silence;
  std::vector<std::string> validate(const std::string& prefix = "") const;
  /// \brief Whether follower `uav`'s computer is down at `t_s` (a follower_dropouts window).
  bool followerOffline(int uav, double t_s) const;
  /// \brief Whether the ground station's link to UAV `uav` is down at `t_s` (an operator_outages window).
  bool operatorLinkDown(int uav, double t_s) const;
};

/// \brief The one range of each number of the fault section's entries: range_outliers.*,
/// planner_outages[i].* (and operator_outages[i].*), follower_dropouts[i].*.
const common::FieldTable<RangeOutlierConfig>& rangeOutlierFields();
const common::FieldTable<PlannerOutage>& plannerOutageFields();
const common::FieldTable<UavDropout>& uavDropoutFields();

/// \brief True when t_s lies in one of the [from, to) windows.
bool inWindow(const std::vector<std::pair<double, double>>& windows, double t_s);

struct MissionConfig {
  std::string source;             ///< scenario file
  double duration_s = 0.0;        ///< > 0; default: the worker's route duration
  double step_s = 0.01;           ///< plant/controller step, (0, 0.05]
  double replanning_period_s = 0.4;  ///< per UAV, staggered by period·i/n, > 0
  /// The onboard replanning settings (horizon, freshness limits of docs/safety.md §1, the
  /// avoidance rule, the search, the braking deceleration, the abort), as the nodelets read them.
  planning::ReplanConfig replan;
  double timeline_rate_hz = 10.0;  ///< > 0
  double gesture_match_window_s = 20.0;  ///< a fired gesture matches a performed one started at most this long before
  std::string gesture_model;      ///< ONNX path (resolved against the scenario's folder); empty: no gesture pipeline

  WorkerConfig worker;
  std::vector<UavConfig> uavs;    ///< uavs[0] leader; count = 1 + followers
  ControllerConfig controller;
  OdometryConfig odometry;
  WindConfig wind;
  CameraSensorConfig camera;
  RangeSensorConfig stereo{0.3, 15.0, 0.05};
  RangeSensorConfig uwb{0.1, 40.0, 0.05};
  LinkConfig link;                ///< between UAVs
  LinkConfig operator_link = operatorLinkDefaults();
  FaultConfig faults;
  formation::FormationConfig formation;
  gesture::GestureFilterConfig gesture_filter;
  gesture::ViewFusionConfig view_fusion;  ///< `gestures.view_fusion.*`: the formation's cameras vote
  gesture::GestureMapping gesture_mapping = gesture::GestureMapping::paperDefault();
  planning::PlannerConfig planner;
  estimation::EstimatorConfig estimator;
  /// The UAVs' online mapping of the site (`mission.mapping.*`, site_mapping_config.hpp).
  SiteMappingConfig mapping;
  std::vector<OperatorRequest> requests;  ///< ascending t_s
  /// `assistance_acks_s`: when the operator's acknowledgement of a pending assistance request reaches
  /// the acting leader (s, ascending; assistance_drill.hpp). Empty: never acknowledged.
  std::vector<double> assistance_acks_s;
  /// `leadership.*`: every UAV's formation::Leadership (uav_count: the formation's).
  formation::LeadershipConfig leadership;
};

/// \brief Reads `mission` of a scenario file. Fails listing every problem (file: key: message).
common::Result<MissionConfig> loadMissionConfig(const std::string& scenario_path);
/// \brief As loadMissionConfig with the `faults:` section of `faults_path` (a YAML file whose
/// only top-level key is `faults`) replacing the scenario's `mission.faults` (gfctl simulate
/// --faults / --fault-profile; docs/simulation.md §3). Problems name the field as
/// `mission.faults.<key>` and both files.
common::Result<MissionConfig> loadMissionConfig(const std::string& scenario_path, const std::string& faults_path);
/// \brief As loadMissionConfig, from YAML text (`source_name` in messages; relative paths
/// resolve against `base_dir`).
common::Result<MissionConfig> parseMissionConfig(const std::string& yaml, const std::string& source_name,
                                                 const std::string& base_dir);

/// \brief What keeps the mission's formation, as configured at its start, from reading gestures:
/// with view_fusion.gate_envelope, the UAVs whose reference lies outside the validated envelope
/// (distance and elevation from the worker) when fewer than min_agreeing_views stay inside — one
/// message naming each such UAV, its distance and elevation and the envelope. Empty when enough
/// cameras are inside, or without a gesture model. For gfctl simulate and SimWorld to warn with.
std::vector<std::string> gestureReadabilityWarnings(const MissionConfig& m);

}  // namespace gesture_formation::sim

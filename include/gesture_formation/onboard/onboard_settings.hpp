#pragma once
/// \file
/// \brief The product's settings as a scenario's `mission` section carries them — one parse
/// for `gfctl simulate` (sim::loadMissionConfig reads them through this) and for the onboard
/// nodelets of a ROS simulation (parameter `mission_file`), so that both run with the same
/// values from the same keys and ranges:
///   mission.replanning_period_s, mission.horizon_dt_s, mission.horizon_steps;
///   mission.controller.brake_accel_mps2 (where a holding UAV stops);
///   mission.faults.{max_share_age_s, max_worker_age_s, max_command_age_s, max_plan_age_s,
///     avoid_all_plans, search_timeout_s, search_height_m, search_vertical_speed_mps,
///     search_period_s, search_horizontal_speed_mps} (the safety rules' limits, docs/safety.md §1),
///     {reach_walking_speed_mps, reach_base_m, reach_max_m, reach_margin_m} (the worker's reach, §3);
///   mission.formation.*, mission.gestures.* (filter, mapping, view_fusion), mission.planner.*,
///   mission.estimator.*, mission.abort.* (each read by its module's own loader; abort's rules
///   against the planner's Γ_dis and speed limit checked here).
/// A key that is absent keeps the documented default of its struct; every problem is reported
/// at once, each naming its key.

#include <string>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/result.hpp"
#include "gesture_formation/estimation/estimator_config.hpp"
#include "gesture_formation/formation/formation_config.hpp"
#include "gesture_formation/gesture/gesture_filter.hpp"
#include "gesture_formation/gesture/gesture_mapping.hpp"
#include "gesture_formation/gesture/view_fusion.hpp"
#include "gesture_formation/planning/abort_mode.hpp"
#include "gesture_formation/planning/plan_request_builder.hpp"
#include "gesture_formation/planning/planner_config.hpp"
#include "gesture_formation/planning/replan_step.hpp"

namespace gesture_formation::onboard {

/// \brief The one range of each setting here that is not a ReplanConfig number (those:
/// planning::replanConfigFields()), for the mission keys and the nodelets' parameters alike.
namespace ranges {
inline const common::Range kReplanningPeriodS = common::Range::openClosed(0.0, 5.0);
inline const common::Range kMaxCommandAgeS = common::Range::positive();
}  // namespace ranges

/// \brief The onboard settings of a mission (see the file comment for the keys).
struct OnboardSettings {
  double replanning_period_s = 0.4;  ///< per UAV, staggered by period·i/n, (0, 5]
  /// horizon_dt_s, horizon_steps, controller.brake_accel_mps2, faults.max_share_age_s,
  /// faults.max_worker_age_s, faults.avoid_all_plans, faults.max_plan_age_s, faults.search_*,
  /// faults.reach_* (docs/safety.md §3), abort.* (docs/safety.md §2.8). uav_index, uav_count and
  /// home_world are the UAV's own; worker_heading is formation.worker_heading; reach's
  /// worker_min_distance_m is formation.limits.safety_distance_m (Γ_dis).
  planning::ReplanConfig replan;
  double max_command_age_s = 5.0;       ///< faults.max_command_age_s: never act on an older command, > 0
  formation::FormationConfig formation;
  gesture::GestureFilterConfig gesture_filter;
  gesture::GestureMapping gesture_mapping = gesture::GestureMapping::paperDefault();
  gesture::ViewFusionConfig view_fusion;
  planning::PlannerConfig planner;
  estimation::EstimatorConfig estimator;
};

/// \brief Reads the settings under `prefix` (e.g. "mission.") of `r` into `out`; problems go to
/// `r`'s error list (each naming its key). Keys it reads are marked used in `r`.
void readOnboardSettings(common::ConfigReader& r, const std::string& prefix, OnboardSettings& out);

/// \brief A scenario file's `mission` YAML, with the `faults:` section of the optional
/// `faults_path` (a YAML file whose only top-level key is `faults`) replacing `mission.faults`
/// (gfctl simulate --faults / --fault-profile; the nodelets' ~faults_file). Returns the merged
/// document's text; fails naming the file and the problem.
common::Result<std::string> loadMissionYaml(const std::string& scenario_path, const std::string& faults_path = "");

/// \brief The onboard settings of a scenario file (with the optional fault profile merged as
/// loadMissionYaml does). Fails listing every problem in these settings (file: key: message);
/// the rest of the mission (worker, UAVs, requests, ...) is not read.
common::Result<OnboardSettings> loadOnboardSettings(const std::string& scenario_path, const std::string& faults_path = "");

}  // namespace gesture_formation::onboard

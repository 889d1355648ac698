#pragma once
// Where a nodelet's algorithm configs come from (docs/ros.md): onboard, the product files
// (config/formation.yaml, config/planner.yaml, config/gestures.yaml, every key required);
// in simulation, the `mission` section of a scenario file, so that the ROS simulation runs
// with exactly the parameters of `gfctl simulate` (parameter `mission_file`; the mission file's
// values win over every other parameter source, and the nodelet's "loaded" report says so).
#include <iomanip>
#include <memory>
#include <sstream>
#include <string>

#include "gesture_formation/formation/formation_config.hpp"
#include "gesture_formation/gesture/gesture_filter.hpp"
#include "gesture_formation/gesture/gesture_mapping.hpp"
#include "gesture_formation/gesture/view_fusion.hpp"
#include "gesture_formation/planning/brake_horizon.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/planner_config.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/onboard/onboard_settings.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

/// The scenario's map and distance field (built once per process that loads it), and its
/// exact solids and ground height (the obstacle-distance metric of the simulation).
struct WorldMap {
  std::shared_ptr<const planning::OccupancyMap> map;
  std::shared_ptr<const planning::DistanceField> field;
  std::shared_ptr<const planning::PrimitiveSet> solids;
  double ground_height_m = -1e9;  ///< −1e9: the scenario has no ground
  planning::MapConfig grid;       ///< the map's resolution and bounds (a live map's grid)
};

inline bool loadWorldMap(const std::string& scenario_file, ParamLoader& params, WorldMap& out) {
  if (scenario_file.empty()) return false;
  auto sc = planning::loadScenario(scenario_file);
  if (!sc) {
    params.addError("scenario_file: " + sc.reason());
    return false;
  }
  auto map = planning::OccupancyMap::fromScenario(*sc);
  if (!map) {
    params.addError("scenario_file: " + scenario_file + ": map: " + map.reason());
    return false;
  }
  out.map = std::make_shared<const planning::OccupancyMap>(std::move(*map));
  out.field = std::make_shared<const planning::DistanceField>(*out.map);
  out.solids = std::make_shared<const planning::PrimitiveSet>(sc->primitives());
  out.ground_height_m = sc->ground.enabled ? sc->ground.height_m : -1e9;
  out.grid = sc->map;
  return true;
}

/// Loads the product settings of `mission_file`'s `mission` section (onboard::OnboardSettings:
/// the very parse gfctl simulate uses; every problem into `params`), with the fault profile of
/// the optional ~faults_file merged in (as `gfctl simulate --faults FILE`; every nodelet of a
/// simulation gets the same pair).
inline bool loadOnboard(const std::string& mission_file, ParamLoader& params, onboard::OnboardSettings& out) {
  std::string faults_file;
  params.loadOptional("faults_file", faults_file, "");
  auto m = onboard::loadOnboardSettings(mission_file, faults_file);
  if (!m) {
    params.addError((faults_file.empty() ? "mission_file: " : "mission_file + faults_file: ") + m.reason());
    return false;
  }
  out = std::move(*m);
  return true;
}

inline bool loadFormation(const std::string& path, ParamLoader& params, formation::FormationConfig& out) {
  std::vector<std::string> unknown;
  auto c = formation::loadFormationConfig(path, common::ConfigReader::MissingKeys::kError, &unknown);
  refuseUnknown("formation_config", unknown, params);
  if (!c) {
    params.addError("formation_config: " + c.reason());
    return false;
  }
  out = *c;
  return true;
}

inline bool loadPlanner(const std::string& path, ParamLoader& params, planning::PlannerConfig& out) {
  std::vector<std::string> unknown;
  auto c = planning::loadPlannerConfig(path, common::ConfigReader::MissingKeys::kError, &unknown);
  refuseUnknown("planner_config", unknown, params);
  if (!c) {
    params.addError("planner_config: " + c.reason());
    return false;
  }
  out = *c;
  return true;
}

/// config/gestures.yaml: the filter keys, `mapping` (checked against `follower_count`) and
/// `view_fusion.*` (every key required; min_agreeing_views at most the follower_count + 1 cameras).
inline bool loadGestures(const std::string& path, int follower_count, ParamLoader& params,
                         gesture::GestureFilterConfig& filter, gesture::GestureMapping& mapping,
                         gesture::ViewFusionConfig& fusion) {
  auto reader = common::ConfigReader::fromFile(path, common::ConfigReader::MissingKeys::kError);
  filter = gesture::readGestureFilterConfig(reader);
  mapping = gesture::GestureMapping::paperDefault();
  gesture::readGestureMapping(reader, filter.max_gesture_id, follower_count, mapping);
  fusion = gesture::readViewFusionConfig(reader);
  for (const auto& k : reader.unusedKeysOfWholeDocument()) params.addError("gesture_config: " + path + ": unknown key '" + k + "'");
  if (!reader.ok()) {
    for (const auto& e : reader.errors()) params.addError("gesture_config: " + e);
    return false;
  }
  if (fusion.min_agreeing_views > follower_count + 1) {
    params.addError("gesture_config: " + path + ": view_fusion.min_agreeing_views: value " +
                    std::to_string(fusion.min_agreeing_views) + " exceeds the number of UAVs (cameras) " +
                    std::to_string(follower_count + 1));
  }
  return true;
}

/// The scenario map's RetreatSpace (where an abort finds its goals), as gfctl simulate builds it.
/// `world` must outlive every user.
inline planning::RetreatSpace retreatSpace(const WorldMap& world) {
  planning::RetreatSpace space;
  space.field = world.field.get();
  if (world.map) {
    space.bounds = world.map->gridBounds();
    space.resolution_m = world.map->resolution();
  }
  space.ground_height_m = world.ground_height_m;
  return space;
}

/// `~abort` (config/ros/nodelets.yaml formation_planner.abort: every planning::AbortConfig key,
/// all required), read with one parameter look-up and the core's own reader (planning::readAbortConfig,
/// as a mission's `abort:`); every problem into `params`, named `abort/<key>`.
inline void loadAbortParams(const ros::NodeHandle& pnh, ParamLoader& params, planning::AbortConfig& out) {
  XmlRpc::XmlRpcValue v;
  std::string yaml;
  const bool found = pnh.getParam("abort", v);
  if (found && v.getType() == XmlRpc::XmlRpcValue::TypeStruct) {
    for (auto& [key, value] : v) {
      std::ostringstream text;
      switch (value.getType()) {
        case XmlRpc::XmlRpcValue::TypeDouble: text << std::setprecision(17) << static_cast<double>(value); break;
        case XmlRpc::XmlRpcValue::TypeInt: text << static_cast<int>(value); break;
        case XmlRpc::XmlRpcValue::TypeString: text << '"' << static_cast<std::string>(value) << '"'; break;
        default: params.addError(pnh.resolveName("abort/" + key) + ": not a number or a string"); continue;
      }
      yaml += key + ": " + text.str() + "\n";
    }
  } else {
    params.addError(pnh.resolveName("abort") + (found ? ": not a map of the abort settings" : ": missing (required; a map of the abort settings)"));
    return;
  }
  auto reader = common::ConfigReader::fromString(yaml.empty() ? "{}" : yaml, pnh.resolveName("abort"),
                                                 common::ConfigReader::MissingKeys::kError);
  out = planning::readAbortConfig(reader);
  for (const auto& e : reader.errors()) params.addError(e);
  params.note("abort: retreat_distance_m " + std::to_string(out.retreat_distance_m) + ", after " +
              planning::toString(out.after) + ", repeats " + std::to_string(out.repeats));
}

/// The FormationPlanner's settings, from either source (see the file comment).
struct PlannerSettings {
  formation::FormationConfig formation;
  planning::PlannerConfig planner;
  planning::ReplanConfig replan;  ///< horizon, freshness, avoidance, search, brake, abort
  double replanning_period_s = 0.0;
  double max_command_age_s = 5.0;  ///< a command kept through a lease gap is dropped when older at the resumption
  bool formation_loaded = false;
};

/// Simulation (`mission_file` non-empty): the mission's settings — the values gfctl simulate runs
/// with — win over every parameter. Onboard: ~replanning_period_s, the replanning numbers of
/// planning::replanConfigFields() (each under its last key segment), ~avoid_all_plans, ~abort,
/// ~formation_config and ~planner_config. Every problem into `params`.
inline void loadPlannerSettings(const ros::NodeHandle& pnh, ParamLoader& params, const std::string& mission_file,
                                PlannerSettings& out) {
  if (!mission_file.empty()) {
    onboard::OnboardSettings mission;
    if (!loadOnboard(mission_file, params, mission)) return;
    out.formation_loaded = true;
    out.formation = mission.formation;
    out.planner = mission.planner;
    out.replanning_period_s = mission.replanning_period_s;
    out.replan = mission.replan;
    out.max_command_age_s = mission.max_command_age_s;
    params.note("from mission_file: replanning_period_s " + std::to_string(out.replanning_period_s) +
                ", horizon_dt_s " + std::to_string(out.replan.dt_s) + ", horizon_steps " +
                std::to_string(out.replan.steps) + ", faults.* limits (max_command_age_s too), controller.brake_accel_mps2, abort.*, " +
                "formation, planner");
    return;
  }
  std::string formation_file, planner_file;
  params.load("replanning_period_s", out.replanning_period_s, onboard::ranges::kReplanningPeriodS);
  params.load("max_command_age_s", out.max_command_age_s, onboard::ranges::kMaxCommandAgeS);
  params.loadFields(planning::replanConfigFields(), out.replan);  // horizon_*, *_age_s, brake_accel_mps2, search_*
  params.load("avoid_all_plans", out.replan.rule.avoid_all_plans);
  loadAbortParams(pnh, params, out.replan.abort);
  params.load("formation_config", formation_file);
  params.load("planner_config", planner_file);
  out.formation_loaded = !formation_file.empty() && loadFormation(formation_file, params, out.formation);
  // Γ_dis that the worker's reach keeps while holding (as OnboardSettings sets it from a mission).
  if (out.formation_loaded) out.replan.reach.worker_min_distance_m = out.formation.limits.safety_distance_m;
  if (!planner_file.empty() && loadPlanner(planner_file, params, out.planner)) {
    for (const auto& e : planning::abortPlannerProblems(out.replan.abort, out.planner.mutual_distance_m,
                                                        out.planner.limits.max_speed_mps, "abort/")) {
      params.addError(e.key + ": " + e.message);
    }
    for (const auto& e : planning::brakeHorizonProblems(out.planner.limits, out.replan.dt_s, out.replan.steps, "")) {
      params.addError(pnh.resolveName(e.key) + ": " + e.message);
    }
  }
}

}  // namespace gesture_formation::nodelets

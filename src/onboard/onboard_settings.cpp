#include "gesture_formation/onboard/onboard_settings.hpp"

#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/planning/brake_horizon.hpp"

namespace gesture_formation::onboard {

using common::ConfigReader;
using common::Range;

void readOnboardSettings(ConfigReader& r, const std::string& m, OnboardSettings& c) {
  r.readDouble(m + "replanning_period_s", c.replanning_period_s, ranges::kReplanningPeriodS);
  planning::replanConfigFields().readFields(r, m, c.replan);
  r.readBool(m + "faults.avoid_all_plans", c.replan.rule.avoid_all_plans);
  r.readDouble(m + "faults.max_command_age_s", c.max_command_age_s, ranges::kMaxCommandAgeS);

  common::withSubReader(r, m + "formation", ConfigReader::MissingKeys::kUseDefaults,
                        [&](ConfigReader& s) { c.formation = formation::readFormationConfig(s); });
  c.replan.reach.worker_min_distance_m = c.formation.limits.safety_distance_m;  // Γ_dis: the reach keeps it
  common::withSubReader(r, m + "gestures", ConfigReader::MissingKeys::kUseDefaults, [&](ConfigReader& s) {
    c.gesture_filter = gesture::readGestureFilterConfig(s);
    gesture::readGestureMapping(s, c.gesture_filter.max_gesture_id,
                                static_cast<int>(c.formation.params.followers.size()), c.gesture_mapping);
    c.view_fusion = gesture::readViewFusionConfig(s);
  });
  if (c.view_fusion.min_agreeing_views > c.formation.params.uavCount()) {
    r.addError(m + "gestures.view_fusion.min_agreeing_views",
               "value " + std::to_string(c.view_fusion.min_agreeing_views) + " exceeds the number of UAVs (cameras) " +
                   std::to_string(c.formation.params.uavCount()) + ": no gesture could ever be accepted");
  }
  common::withSubReader(r, m + "planner", ConfigReader::MissingKeys::kUseDefaults,
                        [&](ConfigReader& s) { c.planner = planning::readPlannerConfig(s); });
  common::withSubReader(r, m + "estimator", ConfigReader::MissingKeys::kUseDefaults,
                        [&](ConfigReader& s) { c.estimator = estimation::readEstimatorConfig(s); });
  common::withSubReader(r, m + "abort", ConfigReader::MissingKeys::kUseDefaults,
                        [&](ConfigReader& s) { c.replan.abort = planning::readAbortConfig(s); });
  common::addProblems(r, "", planning::abortPlannerProblems(c.replan.abort, c.planner.mutual_distance_m,
                                                            c.planner.limits.max_speed_mps, m + "abort."));
  common::addProblems(r, "", planning::brakeHorizonProblems(c.planner.limits, c.replan.dt_s, c.replan.steps, m));
}

namespace {

common::Result<std::string> readText(const std::string& path) {
  std::ifstream in(path);
  if (!in) return common::Result<std::string>::fail(path + ": cannot open file\n");
  std::stringstream ss;
  ss << in.rdbuf();
  return common::Result<std::string>::ok(ss.str());
}

}  // namespace

common::Result<std::string> loadMissionYaml(const std::string& scenario_path, const std::string& faults_path) {
  using R = common::Result<std::string>;
  auto scenario = readText(scenario_path);
  if (!scenario) return scenario;
  if (faults_path.empty()) return scenario;
  auto fault_text = readText(faults_path);
  if (!fault_text) return fault_text;
  YAML::Node root, faults;
  try {
    root = YAML::Load(*scenario);
  } catch (const YAML::Exception& e) {
    return R::fail(scenario_path + ": YAML: " + e.what() + "\n");
  }
  try {
    faults = YAML::Load(*fault_text);
  } catch (const YAML::Exception& e) {
    return R::fail(faults_path + ": YAML: " + e.what() + "\n");
  }
  std::string problems;
  if (!faults.IsMap() || !faults["faults"].IsDefined()) {
    problems += faults_path + ": faults: missing (a fault file has one top-level key, faults)\n";
  } else {
    for (const auto& kv : faults) {
      const std::string key = kv.first.IsScalar() ? kv.first.Scalar() : std::string("?");
      if (key != "faults") problems += faults_path + ": " + key + ": unknown key (a fault file has only faults)\n";
    }
    if (!faults["faults"].IsMap() && !faults["faults"].IsNull()) {
      problems += faults_path + ": faults: must be a mapping of mission.faults keys\n";
    }
  }
  if (!root.IsMap() || !root["mission"].IsMap()) problems += scenario_path + ": mission: missing\n";
  if (!problems.empty()) return R::fail(problems);
  root["mission"]["faults"] = faults["faults"].IsNull() ? YAML::Node(YAML::NodeType::Map) : faults["faults"];
  YAML::Emitter emitter;
  emitter << root;
  return R::ok(std::string(emitter.c_str()));
}

common::Result<OnboardSettings> loadOnboardSettings(const std::string& scenario_path, const std::string& faults_path) {
  using R = common::Result<OnboardSettings>;
  auto yaml = loadMissionYaml(scenario_path, faults_path);
  if (!yaml) return R::fail(yaml.reason());
  const std::string source = faults_path.empty() ? scenario_path : scenario_path + " + " + faults_path;
  ConfigReader r = ConfigReader::fromString(*yaml, source, ConfigReader::MissingKeys::kUseDefaults);
  if (!r.has("mission")) {
    r.addError("mission", "missing: the scenario has no mission section");
    return R::fail(r.errorReport());
  }
  OnboardSettings s;
  readOnboardSettings(r, "mission.", s);
  if (!r.ok()) return R::fail(r.errorReport());
  return R::ok(s);
}

}  // namespace gesture_formation::onboard

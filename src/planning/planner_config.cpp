#include "gesture_formation/planning/planner_config.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::planning {

using common::ConfigReader;
using common::Range;

namespace {

/// PlannerConfig's numbers: key, range — the only place it is written — and place.
const common::FieldTable<PlannerConfig>& fields() {
  using C = PlannerConfig;
  static const common::FieldTable<PlannerConfig> t{{
      {"limits.max_speed_mps", Range::positive(), [](C& c) { return &c.limits.max_speed_mps; }},
      {"limits.max_vertical_speed_mps", Range::positive(), [](C& c) { return &c.limits.max_vertical_speed_mps; }},
      {"limits.max_acceleration_mps2", Range::positive(), [](C& c) { return &c.limits.max_acceleration_mps2; }},
      {"limits.max_vertical_acceleration_mps2", Range::positive(),
       [](C& c) { return &c.limits.max_vertical_acceleration_mps2; }},
      {"limits.max_heading_rate_radps", Range::positive(), [](C& c) { return &c.limits.max_heading_rate_radps; }},
      {"limits.max_pitch_rate_radps", Range::positive(), [](C& c) { return &c.limits.max_pitch_rate_radps; }},
      {"limits.min_pitch_rad", Range::closed(-M_PI / 2, M_PI / 2), [](C& c) { return &c.limits.min_pitch_rad; }},
      {"limits.max_pitch_rad", Range::closed(-M_PI / 2, M_PI / 2), [](C& c) { return &c.limits.max_pitch_rad; }},
      {"weights.reference", Range::positive(), [](C& c) { return &c.weights.reference; }},
      {"weights.acceleration", Range::nonNegative(), [](C& c) { return &c.weights.acceleration; }},
      {"weights.jerk", Range::nonNegative(), [](C& c) { return &c.weights.jerk; }},
      {"weights.terminal_velocity", Range::nonNegative(), [](C& c) { return &c.weights.terminal_velocity; }},
      {"path.obstacle_clearance_m", Range::positive(), [](C& c) { return &c.obstacle_clearance_m; }},
      {"path.path_clearance_m", Range::positive(), [](C& c) { return &c.path_clearance_m; }},
      {"path.tracking_allowance_min_m", Range::nonNegative(), [](C& c) { return &c.tracking_allowance_min_m; }},
      {"path.tracking_allowance_max_m", Range::nonNegative(), [](C& c) { return &c.tracking_allowance_max_m; }},
      {"path.tracking_allowance_decay_mps", Range::positive(), [](C& c) { return &c.tracking_allowance_decay_mps; }},
      {"path.wind_allowance_from_mps", Range::nonNegative(), [](C& c) { return &c.wind_allowance_from_mps; }},
      {"path.wind_allowance_m_per_mps", Range::nonNegative(), [](C& c) { return &c.wind_allowance_m_per_mps; }},
      {"path.wind_allowance_max_m", Range::nonNegative(), [](C& c) { return &c.wind_allowance_max_m; }},
      {"path.wind_window_s", Range::positive(), [](C& c) { return &c.wind_window_s; }},
      {"path.max_projection_m", Range::positive(), [](C& c) { return &c.max_projection_m; }},
      {"path.merge_tolerance_m", Range::nonNegative(), [](C& c) { return &c.path_merge_tolerance_m; }},
      {"path.search_margin_m", Range::positive(), [](C& c) { return &c.search_margin_m; }},
      {"qp.corridor_box_margin_m", Range{0.01, std::numeric_limits<double>::infinity(), false, true},
       [](C& c) { return &c.corridor_box_margin_m; }},
      {"qp.corridor_margin_m", Range::nonNegative(), [](C& c) { return &c.corridor_margin_m; }},
      {"qp.mutual_distance_m", Range::positive(), [](C& c) { return &c.mutual_distance_m; }},
      {"qp.age_margin_speed_mps", Range::nonNegative(), [](C& c) { return &c.age_margin_speed_mps; }},
      {"qp.age_margin_max_m", Range::nonNegative(), [](C& c) { return &c.age_margin_max_m; }},
      {"qp.brake_envelope_age_s", Range::nonNegative(), [](C& c) { return &c.brake_envelope_age_s; }},
      {"qp.brake_envelope_lead_s", Range::nonNegative(), [](C& c) { return &c.brake_envelope_lead_s; }},
      {"qp.worker_safety_distance_m", Range::positive(), [](C& c) { return &c.worker_safety_distance_m; }},
      {"qp.distance_buffer_m", Range::nonNegative(), [](C& c) { return &c.qp_distance_buffer_m; }},
      {"qp.eps_abs", Range::openClosed(0.0, 1e-3), [](C& c) { return &c.qp_eps_abs; }},
      {"qp.solve_timeout_s", Range::positive(), [](C& c) { return &c.qp_solve_timeout_s; }},
      {"camera.heading_weight", Range::positive(), [](C& c) { return &c.heading_weight; }},
      {"camera.smoothness_weight", Range::nonNegative(), [](C& c) { return &c.heading_smoothness_weight; }},
      {"verify.clearance_m", Range::positive(), [](C& c) { return &c.verify_clearance_m; }},
      {"verify.tolerance", Range{0.0, 0.1, true, false}, [](C& c) { return &c.verify_tolerance; }},
      {"verify.recovery_speed_mps", Range::positive(), [](C& c) { return &c.recovery_speed_mps; }},
      {"verify.recovery_acceleration_mps2", Range::positive(), [](C& c) { return &c.recovery_acceleration_mps2; }},
      {"verify.recovery_slack_m", Range::positive(), [](C& c) { return &c.recovery_slack_m; }},
      {"fallback.min_horizon_s", Range::positive(), [](C& c) { return &c.fallback_min_horizon_s; }},
      {"fallback.max_deviation_m", Range::positive(), [](C& c) { return &c.fallback_max_deviation_m; }},
      {"fallback.time_budget_ms", Range::nonNegative(), [](C& c) { return &c.time_budget_ms; }},
      {"path.search_max_expansions", Range::atLeast(100), [](C& c) { return &c.search_max_expansions; }},
      {"qp.max_iterations", Range::atLeast(10), [](C& c) { return &c.qp_max_iterations; }},
      {"verify.substeps", Range::closed(1, 100), [](C& c) { return &c.verify_substeps; }},
  }};
  return t;
}

/// The rules between fields (each single field is in its range or reported by the table).
void crossFieldProblems(const PlannerConfig& c, std::vector<common::ConfigError>& e) {
  const auto rule = [&e](bool ok, const char* key, double value, const char* what) {
    common::checkRule(e, ok, key, value, what);
  };
  const DynamicLimits& l = c.limits;
  rule(l.max_vertical_speed_mps < l.max_speed_mps, "limits.max_vertical_speed_mps", l.max_vertical_speed_mps,
       "must be < limits.max_speed_mps");
  rule(l.max_vertical_acceleration_mps2 < l.max_acceleration_mps2, "limits.max_vertical_acceleration_mps2",
       l.max_vertical_acceleration_mps2, "must be < limits.max_acceleration_mps2");
  rule(l.max_pitch_rad > l.min_pitch_rad, "limits.max_pitch_rad", l.max_pitch_rad, "must be > limits.min_pitch_rad");
  rule(c.path_clearance_m >= c.obstacle_clearance_m, "path.path_clearance_m", c.path_clearance_m,
       "must be >= path.obstacle_clearance_m");
  rule(c.tracking_allowance_max_m >= c.tracking_allowance_min_m, "path.tracking_allowance_max_m",
       c.tracking_allowance_max_m, "must be >= path.tracking_allowance_min_m");
  rule(c.age_margin_max_m >= c.tracking_allowance_max_m + c.wind_allowance_max_m, "qp.age_margin_max_m", c.age_margin_max_m,
       "must be >= path.tracking_allowance_max_m + path.wind_allowance_max_m (a silent UAV's reach off its last plan)");
  rule(c.corridor_margin_m < c.corridor_box_margin_m, "qp.corridor_margin_m", c.corridor_margin_m,
       "must be < qp.corridor_box_margin_m");
}

/// Every problem of `c`: each field outside its range, then the rules between fields.
std::vector<common::ConfigError> problems(const PlannerConfig& c) {
  std::vector<common::ConfigError> e = fields().rangeProblems(c);
  crossFieldProblems(c, e);
  return e;
}

}  // namespace

std::vector<std::string> PlannerConfig::validate() const {
  return common::problemLines(problems(*this));
}

PlannerConfig readPlannerConfig(ConfigReader& r, const std::string& prefix) {
  PlannerConfig c;
  fields().readFields(r, prefix, c);
  std::string solver = c.camera_solver == PlannerConfig::CameraSolver::kCeres ? "ceres" : "filter";
  r.readString(prefix + "camera.solver", solver, {"filter", "ceres"});
  c.camera_solver = solver == "ceres" ? PlannerConfig::CameraSolver::kCeres : PlannerConfig::CameraSolver::kFilter;
  r.readBool(prefix + "qp.truncate_on_infeasible", c.qp_truncate_on_infeasible);
  // The rules between fields, always: a key outside its range was reported while reading and
  // kept its default, so these add only what is new.
  common::addProblems(r, prefix, problems(c));
  return c;
}

common::Result<PlannerConfig> loadPlannerConfig(const std::string& path, ConfigReader::MissingKeys mode,
                                                std::vector<std::string>* warnings) {
  ConfigReader r = ConfigReader::fromFile(path, mode);
  const PlannerConfig c = readPlannerConfig(r);
  if (warnings) {
    for (const auto& k : r.unusedKeysOfWholeDocument()) warnings->push_back(path + ": unknown key '" + k + "' ignored");
  }
  if (!r.ok()) return common::Result<PlannerConfig>::fail(r.errorReport());
  return common::Result<PlannerConfig>::ok(c);
}

}  // namespace gesture_formation::planning

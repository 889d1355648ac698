#include "gesture_formation/planning/planner_config.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "gesture_formation/common/format_number.hpp"

namespace gesture_formation::planning {

using common::ConfigReader;
using common::Range;

namespace {

/// One number of PlannerConfig: its key, its range — the only place the range is written, used
/// by validate() and by the reader alike — and where it lives in the struct.
template <class T>
struct Field {
  const char* key;
  Range range;
  T* (*ref)(PlannerConfig&);
};

const std::vector<Field<double>>& doubleFields() {
  static const std::vector<Field<double>> f = {
      {"limits.max_speed_mps", Range::positive(), [](PlannerConfig& c) { return &c.limits.max_speed_mps; }},
      {"limits.max_vertical_speed_mps", Range::positive(), [](PlannerConfig& c) { return &c.limits.max_vertical_speed_mps; }},
      {"limits.max_acceleration_mps2", Range::positive(), [](PlannerConfig& c) { return &c.limits.max_acceleration_mps2; }},
      {"limits.max_vertical_acceleration_mps2", Range::positive(),
       [](PlannerConfig& c) { return &c.limits.max_vertical_acceleration_mps2; }},
      {"limits.max_heading_rate_radps", Range::positive(), [](PlannerConfig& c) { return &c.limits.max_heading_rate_radps; }},
      {"limits.max_pitch_rate_radps", Range::positive(), [](PlannerConfig& c) { return &c.limits.max_pitch_rate_radps; }},
      {"limits.min_pitch_rad", Range::closed(-M_PI / 2, M_PI / 2), [](PlannerConfig& c) { return &c.limits.min_pitch_rad; }},
      {"limits.max_pitch_rad", Range::closed(-M_PI / 2, M_PI / 2), [](PlannerConfig& c) { return &c.limits.max_pitch_rad; }},
      {"weights.reference", Range::positive(), [](PlannerConfig& c) { return &c.weights.reference; }},
      {"weights.acceleration", Range::nonNegative(), [](PlannerConfig& c) { return &c.weights.acceleration; }},
      {"weights.jerk", Range::nonNegative(), [](PlannerConfig& c) { return &c.weights.jerk; }},
      {"weights.terminal_velocity", Range::nonNegative(), [](PlannerConfig& c) { return &c.weights.terminal_velocity; }},
      {"path.obstacle_clearance_m", Range::positive(), [](PlannerConfig& c) { return &c.obstacle_clearance_m; }},
      {"path.path_clearance_m", Range::positive(), [](PlannerConfig& c) { return &c.path_clearance_m; }},
      {"path.tracking_allowance_min_m", Range::nonNegative(), [](PlannerConfig& c) { return &c.tracking_allowance_min_m; }},
      {"path.tracking_allowance_max_m", Range::nonNegative(), [](PlannerConfig& c) { return &c.tracking_allowance_max_m; }},
      {"path.tracking_allowance_decay_mps", Range::positive(), [](PlannerConfig& c) { return &c.tracking_allowance_decay_mps; }},
      {"path.wind_allowance_from_mps", Range::nonNegative(), [](PlannerConfig& c) { return &c.wind_allowance_from_mps; }},
      {"path.wind_allowance_m_per_mps", Range::nonNegative(), [](PlannerConfig& c) { return &c.wind_allowance_m_per_mps; }},
      {"path.wind_allowance_max_m", Range::nonNegative(), [](PlannerConfig& c) { return &c.wind_allowance_max_m; }},
      {"path.wind_window_s", Range::positive(), [](PlannerConfig& c) { return &c.wind_window_s; }},
      {"path.max_projection_m", Range::positive(), [](PlannerConfig& c) { return &c.max_projection_m; }},
      {"path.merge_tolerance_m", Range::nonNegative(), [](PlannerConfig& c) { return &c.path_merge_tolerance_m; }},
      {"path.search_margin_m", Range::positive(), [](PlannerConfig& c) { return &c.search_margin_m; }},
      {"qp.corridor_box_margin_m", Range{0.01, std::numeric_limits<double>::infinity(), false, true},
       [](PlannerConfig& c) { return &c.corridor_box_margin_m; }},
      {"qp.corridor_margin_m", Range::nonNegative(), [](PlannerConfig& c) { return &c.corridor_margin_m; }},
      {"qp.mutual_distance_m", Range::positive(), [](PlannerConfig& c) { return &c.mutual_distance_m; }},
      {"qp.age_margin_speed_mps", Range::nonNegative(), [](PlannerConfig& c) { return &c.age_margin_speed_mps; }},
      {"qp.brake_envelope_age_s", Range::nonNegative(), [](PlannerConfig& c) { return &c.brake_envelope_age_s; }},
      {"qp.brake_envelope_lead_s", Range::nonNegative(), [](PlannerConfig& c) { return &c.brake_envelope_lead_s; }},
      {"qp.worker_safety_distance_m", Range::positive(), [](PlannerConfig& c) { return &c.worker_safety_distance_m; }},
      {"qp.distance_buffer_m", Range::nonNegative(), [](PlannerConfig& c) { return &c.qp_distance_buffer_m; }},
      {"qp.eps_abs", Range::openClosed(0.0, 1e-3), [](PlannerConfig& c) { return &c.qp_eps_abs; }},
      {"qp.solve_timeout_s", Range::positive(), [](PlannerConfig& c) { return &c.qp_solve_timeout_s; }},
      {"camera.heading_weight", Range::positive(), [](PlannerConfig& c) { return &c.heading_weight; }},
      {"camera.smoothness_weight", Range::nonNegative(), [](PlannerConfig& c) { return &c.heading_smoothness_weight; }},
      {"verify.clearance_m", Range::positive(), [](PlannerConfig& c) { return &c.verify_clearance_m; }},
      {"verify.tolerance", Range{0.0, 0.1, true, false}, [](PlannerConfig& c) { return &c.verify_tolerance; }},
      {"verify.recovery_speed_mps", Range::positive(), [](PlannerConfig& c) { return &c.recovery_speed_mps; }},
      {"verify.recovery_acceleration_mps2", Range::positive(), [](PlannerConfig& c) { return &c.recovery_acceleration_mps2; }},
      {"verify.recovery_slack_m", Range::positive(), [](PlannerConfig& c) { return &c.recovery_slack_m; }},
      {"fallback.min_horizon_s", Range::positive(), [](PlannerConfig& c) { return &c.fallback_min_horizon_s; }},
      {"fallback.max_deviation_m", Range::positive(), [](PlannerConfig& c) { return &c.fallback_max_deviation_m; }},
      {"fallback.time_budget_ms", Range::nonNegative(), [](PlannerConfig& c) { return &c.time_budget_ms; }},
  };
  return f;
}

const std::vector<Field<int>>& intFields() {
  static const std::vector<Field<int>> f = {
      {"path.search_max_expansions", Range::atLeast(100), [](PlannerConfig& c) { return &c.search_max_expansions; }},
      {"qp.max_iterations", Range::atLeast(10), [](PlannerConfig& c) { return &c.qp_max_iterations; }},
      {"verify.substeps", Range::closed(1, 100), [](PlannerConfig& c) { return &c.verify_substeps; }},
  };
  return f;
}

/// The rules between fields (each single field is in its range or reported by the table).
void crossFieldProblems(const PlannerConfig& c, std::vector<common::ConfigError>& e) {
  const auto rule = [&e](bool ok, const char* key, double value, const char* what) {
    if (!ok) e.push_back({key, std::string(what) + ", got " + common::formatNumber(value)});
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
  rule(c.corridor_margin_m < c.corridor_box_margin_m, "qp.corridor_margin_m", c.corridor_margin_m,
       "must be < qp.corridor_box_margin_m");
}

/// Every problem of `c`: each field outside its range, then the rules between fields.
std::vector<common::ConfigError> problems(const PlannerConfig& config) {
  std::vector<common::ConfigError> e;
  PlannerConfig c = config;  // the table's accessors take a mutable config
  for (const auto& f : doubleFields()) {
    const double v = *f.ref(c);
    if (!f.range.contains(v)) e.push_back({f.key, "must be in " + f.range.describe() + ", got " + common::formatNumber(v)});
  }
  for (const auto& f : intFields()) {
    const int v = *f.ref(c);
    if (!f.range.contains(v)) e.push_back({f.key, "must be in " + f.range.describe() + ", got " + std::to_string(v)});
  }
  crossFieldProblems(config, e);
  return e;
}

}  // namespace

std::vector<std::string> PlannerConfig::validate() const {
  std::vector<std::string> lines;
  for (const auto& p : problems(*this)) lines.push_back(p.key + " " + p.message);
  return lines;
}

PlannerConfig readPlannerConfig(ConfigReader& r, const std::string& prefix) {
  PlannerConfig c;
  for (const auto& f : doubleFields()) r.readDouble(prefix + f.key, *f.ref(c), f.range);
  for (const auto& f : intFields()) r.readInt(prefix + f.key, *f.ref(c), f.range);
  std::string solver = c.camera_solver == PlannerConfig::CameraSolver::kCeres ? "ceres" : "filter";
  r.readString(prefix + "camera.solver", solver, {"filter", "ceres"});
  c.camera_solver = solver == "ceres" ? PlannerConfig::CameraSolver::kCeres : PlannerConfig::CameraSolver::kFilter;
  // The rules between fields, always: a key outside its range was reported while reading and
  // kept its default, so these add only what is new.
  for (const auto& p : problems(c)) r.addError(prefix + p.key, p.message);
  return c;
}

common::Result<PlannerConfig> loadPlannerConfig(const std::string& path, ConfigReader::MissingKeys mode,
                                                std::vector<std::string>* warnings) {
  ConfigReader r = ConfigReader::fromFile(path, mode);
  const PlannerConfig c = readPlannerConfig(r);
  if (warnings) {
    for (const auto& k : r.unusedKeys()) warnings->push_back(path + ": unknown key '" + k + "' ignored");
  }
  if (!r.ok()) return common::Result<PlannerConfig>::fail(r.errorReport());
  return common::Result<PlannerConfig>::ok(c);
}

}  // namespace gesture_formation::planning

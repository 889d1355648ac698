#include "gesture_formation/planning/planner_config.hpp"

#include <cmath>
#include <sstream>

#include "gesture_formation/common/format_number.hpp"

namespace gesture_formation::planning {

using common::ConfigReader;
using common::Range;

namespace {

void require(std::vector<std::string>& e, bool ok, const std::string& field, double value, const std::string& rule) {
  if (!ok) e.push_back(field + " " + rule + ", got " + common::formatNumber(value));
}

}  // namespace

std::vector<std::string> PlannerConfig::validate() const {
  std::vector<std::string> e;
  const auto pos = [](double v) { return std::isfinite(v) && v > 0.0; };
  const auto nonneg = [](double v) { return std::isfinite(v) && v >= 0.0; };
  const DynamicLimits& l = limits;
  require(e, pos(l.max_speed_mps), "limits.max_speed_mps", l.max_speed_mps, "must be > 0");
  require(e, pos(l.max_vertical_speed_mps) && l.max_vertical_speed_mps < l.max_speed_mps, "limits.max_vertical_speed_mps",
          l.max_vertical_speed_mps, "must be in (0, limits.max_speed_mps)");
  require(e, pos(l.max_acceleration_mps2), "limits.max_acceleration_mps2", l.max_acceleration_mps2, "must be > 0");
  require(e, pos(l.max_vertical_acceleration_mps2) && l.max_vertical_acceleration_mps2 < l.max_acceleration_mps2,
          "limits.max_vertical_acceleration_mps2", l.max_vertical_acceleration_mps2,
          "must be in (0, limits.max_acceleration_mps2)");
  require(e, pos(l.max_heading_rate_radps), "limits.max_heading_rate_radps", l.max_heading_rate_radps, "must be > 0");
  require(e, pos(l.max_pitch_rate_radps), "limits.max_pitch_rate_radps", l.max_pitch_rate_radps, "must be > 0");
  require(e, std::isfinite(l.min_pitch_rad) && l.min_pitch_rad >= -M_PI / 2, "limits.min_pitch_rad", l.min_pitch_rad,
          "must be in [-pi/2, limits.max_pitch_rad)");
  require(e, std::isfinite(l.max_pitch_rad) && l.max_pitch_rad <= M_PI / 2 && l.max_pitch_rad > l.min_pitch_rad,
          "limits.max_pitch_rad", l.max_pitch_rad, "must be in (limits.min_pitch_rad, pi/2]");

  require(e, pos(weights.reference), "weights.reference", weights.reference, "must be > 0");
  require(e, nonneg(weights.acceleration), "weights.acceleration", weights.acceleration, "must be >= 0");
  require(e, nonneg(weights.jerk), "weights.jerk", weights.jerk, "must be >= 0");
  require(e, nonneg(weights.terminal_velocity), "weights.terminal_velocity", weights.terminal_velocity, "must be >= 0");

  require(e, pos(obstacle_clearance_m), "path.obstacle_clearance_m", obstacle_clearance_m, "must be > 0");
  require(e, std::isfinite(path_clearance_m) && path_clearance_m >= obstacle_clearance_m, "path.path_clearance_m",
          path_clearance_m, "must be >= path.obstacle_clearance_m");
  require(e, nonneg(tracking_allowance_min_m), "path.tracking_allowance_min_m", tracking_allowance_min_m, "must be >= 0");
  require(e, nonneg(tracking_allowance_max_m) && tracking_allowance_max_m >= tracking_allowance_min_m,
          "path.tracking_allowance_max_m", tracking_allowance_max_m, "must be >= path.tracking_allowance_min_m");
  require(e, pos(tracking_allowance_decay_mps), "path.tracking_allowance_decay_mps", tracking_allowance_decay_mps, "must be > 0");
  require(e, nonneg(wind_allowance_from_mps), "path.wind_allowance_from_mps", wind_allowance_from_mps, "must be >= 0");
  require(e, nonneg(wind_allowance_m_per_mps), "path.wind_allowance_m_per_mps", wind_allowance_m_per_mps, "must be >= 0");
  require(e, nonneg(wind_allowance_max_m), "path.wind_allowance_max_m", wind_allowance_max_m, "must be >= 0");
  require(e, pos(wind_window_s), "path.wind_window_s", wind_window_s, "must be > 0");
  require(e, pos(max_projection_m), "path.max_projection_m", max_projection_m, "must be > 0");
  require(e, nonneg(path_merge_tolerance_m), "path.merge_tolerance_m", path_merge_tolerance_m, "must be >= 0");
  require(e, pos(search_margin_m), "path.search_margin_m", search_margin_m, "must be > 0");
  require(e, search_max_expansions >= 100, "path.search_max_expansions", search_max_expansions, "must be >= 100");

  require(e, std::isfinite(corridor_box_margin_m) && corridor_box_margin_m > 0.01, "qp.corridor_box_margin_m",
          corridor_box_margin_m, "must be > 0.01");
  require(e, nonneg(corridor_margin_m) && corridor_margin_m < corridor_box_margin_m, "qp.corridor_margin_m",
          corridor_margin_m, "must be in [0, qp.corridor_box_margin_m)");
  require(e, pos(mutual_distance_m), "qp.mutual_distance_m", mutual_distance_m, "must be > 0");
  require(e, nonneg(age_margin_speed_mps), "qp.age_margin_speed_mps", age_margin_speed_mps, "must be >= 0");
  require(e, nonneg(brake_envelope_age_s), "qp.brake_envelope_age_s", brake_envelope_age_s, "must be >= 0");
  require(e, nonneg(brake_envelope_lead_s), "qp.brake_envelope_lead_s", brake_envelope_lead_s, "must be >= 0");
  require(e, pos(worker_safety_distance_m), "qp.worker_safety_distance_m", worker_safety_distance_m, "must be > 0");
  require(e, nonneg(qp_distance_buffer_m), "qp.distance_buffer_m", qp_distance_buffer_m, "must be >= 0");
  require(e, pos(qp_eps_abs) && qp_eps_abs <= 1e-3, "qp.eps_abs", qp_eps_abs, "must be in (0, 1e-3]");
  require(e, qp_max_iterations >= 10, "qp.max_iterations", qp_max_iterations, "must be >= 10");
  require(e, pos(qp_solve_timeout_s), "qp.solve_timeout_s", qp_solve_timeout_s, "must be > 0");

  require(e, pos(heading_weight), "camera.heading_weight", heading_weight, "must be > 0");
  require(e, nonneg(heading_smoothness_weight), "camera.smoothness_weight", heading_smoothness_weight, "must be >= 0");

  require(e, pos(verify_clearance_m), "verify.clearance_m", verify_clearance_m, "must be > 0");
  require(e, verify_substeps >= 1 && verify_substeps <= 100, "verify.substeps", verify_substeps, "must be in [1, 100]");
  require(e, nonneg(verify_tolerance) && verify_tolerance < 0.1, "verify.tolerance", verify_tolerance, "must be in [0, 0.1)");
  require(e, pos(recovery_speed_mps), "verify.recovery_speed_mps", recovery_speed_mps, "must be > 0");
  require(e, pos(recovery_acceleration_mps2), "verify.recovery_acceleration_mps2", recovery_acceleration_mps2, "must be > 0");
  require(e, pos(recovery_slack_m), "verify.recovery_slack_m", recovery_slack_m, "must be > 0");
  require(e, pos(fallback_min_horizon_s), "fallback.min_horizon_s", fallback_min_horizon_s, "must be > 0");
  require(e, pos(fallback_max_deviation_m), "fallback.max_deviation_m", fallback_max_deviation_m, "must be > 0");
  require(e, nonneg(time_budget_ms), "fallback.time_budget_ms", time_budget_ms, "must be >= 0 (0 disables)");
  return e;
}

PlannerConfig readPlannerConfig(ConfigReader& r, const std::string& prefix) {
  PlannerConfig c;
  const auto key = [&prefix](const char* k) { return prefix + k; };
  DynamicLimits& l = c.limits;
  r.readDouble(key("limits.max_speed_mps"), l.max_speed_mps, Range::positive());
  r.readDouble(key("limits.max_vertical_speed_mps"), l.max_vertical_speed_mps, Range::positive());
  r.readDouble(key("limits.max_acceleration_mps2"), l.max_acceleration_mps2, Range::positive());
  r.readDouble(key("limits.max_vertical_acceleration_mps2"), l.max_vertical_acceleration_mps2, Range::positive());
  r.readDouble(key("limits.max_heading_rate_radps"), l.max_heading_rate_radps, Range::positive());
  r.readDouble(key("limits.max_pitch_rate_radps"), l.max_pitch_rate_radps, Range::positive());
  r.readDouble(key("limits.min_pitch_rad"), l.min_pitch_rad, Range::closed(-M_PI / 2, M_PI / 2));
  r.readDouble(key("limits.max_pitch_rad"), l.max_pitch_rad, Range::closed(-M_PI / 2, M_PI / 2));

  r.readDouble(key("weights.reference"), c.weights.reference, Range::positive());
  r.readDouble(key("weights.acceleration"), c.weights.acceleration, Range::nonNegative());
  r.readDouble(key("weights.jerk"), c.weights.jerk, Range::nonNegative());
  r.readDouble(key("weights.terminal_velocity"), c.weights.terminal_velocity, Range::nonNegative());

  r.readDouble(key("path.obstacle_clearance_m"), c.obstacle_clearance_m, Range::positive());
  r.readDouble(key("path.path_clearance_m"), c.path_clearance_m, Range::positive());
  r.readDouble(key("path.tracking_allowance_min_m"), c.tracking_allowance_min_m, Range::nonNegative());
  r.readDouble(key("path.tracking_allowance_max_m"), c.tracking_allowance_max_m, Range::nonNegative());
  r.readDouble(key("path.tracking_allowance_decay_mps"), c.tracking_allowance_decay_mps, Range::positive());
  r.readDouble(key("path.wind_allowance_from_mps"), c.wind_allowance_from_mps, Range::nonNegative());
  r.readDouble(key("path.wind_allowance_m_per_mps"), c.wind_allowance_m_per_mps, Range::nonNegative());
  r.readDouble(key("path.wind_allowance_max_m"), c.wind_allowance_max_m, Range::nonNegative());
  r.readDouble(key("path.wind_window_s"), c.wind_window_s, Range::positive());
  r.readDouble(key("path.max_projection_m"), c.max_projection_m, Range::positive());
  r.readDouble(key("path.merge_tolerance_m"), c.path_merge_tolerance_m, Range::nonNegative());
  r.readDouble(key("path.search_margin_m"), c.search_margin_m, Range::positive());
  r.readInt(key("path.search_max_expansions"), c.search_max_expansions, Range::atLeast(100));

  r.readDouble(key("qp.corridor_box_margin_m"), c.corridor_box_margin_m, Range::positive());
  r.readDouble(key("qp.corridor_margin_m"), c.corridor_margin_m, Range::nonNegative());
  r.readDouble(key("qp.mutual_distance_m"), c.mutual_distance_m, Range::positive());
  r.readDouble(key("qp.age_margin_speed_mps"), c.age_margin_speed_mps, Range::nonNegative());
  r.readDouble(key("qp.brake_envelope_age_s"), c.brake_envelope_age_s, Range::nonNegative());
  r.readDouble(key("qp.brake_envelope_lead_s"), c.brake_envelope_lead_s, Range::nonNegative());
  r.readDouble(key("qp.worker_safety_distance_m"), c.worker_safety_distance_m, Range::positive());
  r.readDouble(key("qp.distance_buffer_m"), c.qp_distance_buffer_m, Range::nonNegative());
  r.readDouble(key("qp.eps_abs"), c.qp_eps_abs, Range::openClosed(0.0, 1e-3));
  r.readInt(key("qp.max_iterations"), c.qp_max_iterations, Range::atLeast(10));
  r.readDouble(key("qp.solve_timeout_s"), c.qp_solve_timeout_s, Range::positive());

  std::string solver = c.camera_solver == PlannerConfig::CameraSolver::kCeres ? "ceres" : "filter";
  r.readString(key("camera.solver"), solver, {"filter", "ceres"});
  c.camera_solver = solver == "ceres" ? PlannerConfig::CameraSolver::kCeres : PlannerConfig::CameraSolver::kFilter;
  r.readDouble(key("camera.heading_weight"), c.heading_weight, Range::positive());
  r.readDouble(key("camera.smoothness_weight"), c.heading_smoothness_weight, Range::nonNegative());

  r.readDouble(key("verify.clearance_m"), c.verify_clearance_m, Range::positive());
  r.readInt(key("verify.substeps"), c.verify_substeps, Range::closed(1, 100));
  r.readDouble(key("verify.tolerance"), c.verify_tolerance, Range{0.0, 0.1, true, false});
  r.readDouble(key("verify.recovery_speed_mps"), c.recovery_speed_mps, Range::positive());
  r.readDouble(key("verify.recovery_acceleration_mps2"), c.recovery_acceleration_mps2, Range::positive());
  r.readDouble(key("verify.recovery_slack_m"), c.recovery_slack_m, Range::positive());
  r.readDouble(key("fallback.min_horizon_s"), c.fallback_min_horizon_s, Range::positive());
  r.readDouble(key("fallback.max_deviation_m"), c.fallback_max_deviation_m, Range::positive());
  r.readDouble(key("fallback.time_budget_ms"), c.time_budget_ms, Range::nonNegative());

  // Cross-field rules; single-key ranges were reported while reading (the bad value kept its
  // default, so these lines only add what is new).
  if (r.ok()) {
    for (const auto& line : c.validate()) {
      const auto sp = line.find(' ');
      r.addError(prefix + line.substr(0, sp), line.substr(sp + 1));
    }
  }
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

#include "gesture_formation/planning/brake_horizon.hpp"

#include <algorithm>
#include <cmath>

#include "gesture_formation/common/format_number.hpp"

namespace gesture_formation::planning {

double longestBrakeS(const DynamicLimits& l) {
  // Along a direction with vertical share c the speed is at most min(V, vz/c) and the deceleration
  // min(A, az/c); their ratio is largest at c = 0 (V/A) or where the vertical bounds bind (vz/az).
  return std::max(l.max_speed_mps / l.max_acceleration_mps2, l.max_vertical_speed_mps / l.max_vertical_acceleration_mps2);
}

std::vector<common::ConfigError> brakeHorizonProblems(const DynamicLimits& limits, double dt_s, int steps,
                                                      const std::string& prefix) {
  std::vector<common::ConfigError> out;
  if (!(dt_s > 0.0) || steps < 2) return out;  // the fields' own ranges report these
  const double brake_s = longestBrakeS(limits);
  if (!std::isfinite(brake_s)) return out;
  const double stop_s = std::ceil(brake_s / dt_s - 1e-9) * dt_s;
  const double horizon_s = (steps - 1) * dt_s;
  if (horizon_s + 1e-9 < stop_s) {
    out.push_back({prefix + "horizon_steps",
                   "the horizon (horizon_steps " + std::to_string(steps) + " - 1) x horizon_dt_s " +
                       common::formatNumber(dt_s) + " = " + common::formatNumber(horizon_s) +
                       " s is shorter than the longest brake " + common::formatNumber(stop_s) +
                       " s (max_speed_mps / max_acceleration_mps2, max_vertical_speed_mps / "
                       "max_vertical_acceleration_mps2, rounded up to a sample): a brake plan would end moving; "
                       "need horizon_steps >= " + std::to_string(static_cast<int>(std::ceil(stop_s / dt_s - 1e-9)) + 1)});
  }
  return out;
}

}  // namespace gesture_formation::planning

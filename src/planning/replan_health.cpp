#include "gesture_formation/planning/replan_health.hpp"

#include <algorithm>
#include <sstream>
#include <utility>

namespace gesture_formation::planning {

void ReplanHealth::record(const ReplanOutcome& outcome, double t_s) {
  if (!outcome.planned()) return;
  ++next_.plans;
  if (outcome.fallback) ++next_.fallbacks;
  next_.mode = toString(outcome.mode);
  next_.last_status = toString(outcome.result.status);
  next_.last_planning_ms = outcome.result.timings.total_ms;
  const double excess = outcome.result.tracking_deviation_m - outcome.result.tracking_allowance_m;
  if (excess > 1e-9) {
    ++next_.off_plan;
    next_.max_off_plan_m = std::max(next_.max_off_plan_m, excess);
  }
  last_plan_s_ = t_s;
}

ReplanHealthReport ReplanHealth::report(double now_s, double period_s) {
  ReplanHealthReport r = next_;
  r.last_plan_age_s = last_plan_s_ < 0.0 ? -1.0 : now_s - last_plan_s_;
  using L = ReplanHealthReport::Level;
  if (r.last_plan_age_s > 3.0 * period_s) {
    r.level = L::kError;
    r.message = "no plan for " + std::to_string(r.last_plan_age_s) + " s";
  } else if (r.mode != "track") {
    r.level = L::kWarn;
    r.message = r.mode;
  } else if (r.fallbacks > 0) {
    r.level = L::kWarn;
    r.message = std::to_string(r.fallbacks) + " fallback plan(s)";
  } else if (r.off_plan > 0) {
    r.level = L::kWarn;
    std::ostringstream os;
    os.precision(3);
    os << "off its plan by up to " << r.max_off_plan_m << " m beyond the tracking allowance in " << r.off_plan
       << " replanning(s): the flight stack lags its setpoints, or wind beyond the allowance";
    r.message = os.str();
  }
  next_.plans = 0;
  next_.fallbacks = 0;
  next_.off_plan = 0;
  next_.max_off_plan_m = 0.0;
  return r;
}

}  // namespace gesture_formation::planning

#include "gesture_formation/planning/replan_health.hpp"

#include <utility>

namespace gesture_formation::planning {

void ReplanHealth::record(const ReplanOutcome& outcome, double t_s) {
  if (!outcome.planned()) return;
  ++next_.plans;
  if (outcome.fallback) ++next_.fallbacks;
  next_.mode = toString(outcome.mode);
  next_.last_status = toString(outcome.result.status);
  next_.last_planning_ms = outcome.result.timings.total_ms;
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
  }
  next_.plans = 0;
  next_.fallbacks = 0;
  return r;
}

}  // namespace gesture_formation::planning

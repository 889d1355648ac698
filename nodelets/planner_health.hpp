#pragma once
// The FormationPlanner's /diagnostics status (planning::ReplanHealth's report) and its log lines
// about a plan that was not optimized or a QP solve that was stopped.
#include <string>

#include <diagnostic_msgs/DiagnosticStatus.h>
#include <ros/console.h>

#include "diagnostics.hpp"
#include "gesture_formation/planning/replan_health.hpp"
#include "gesture_formation/planning/uav_planner.hpp"

namespace gesture_formation::nodelets {

/// UAV `uav`'s planner on /diagnostics from its report over the last `since_s` seconds.
inline diagnostic_msgs::DiagnosticStatus plannerHealth(const planning::ReplanHealthReport& r, int uav, double since_s) {
  Health h("FormationPlanner uav" + std::to_string(uav), "uav" + std::to_string(uav));
  h.error(r.level == planning::ReplanHealthReport::Level::kError, r.message)
      .warn(r.level == planning::ReplanHealthReport::Level::kWarn, r.message)
      .value("mode", r.mode)
      .value("plans_per_s", since_s > 0.0 ? r.plans / since_s : 0.0)
      .value("fallbacks", r.fallbacks)
      .value("last_status", r.last_status)
      .value("last_planning_ms", r.last_planning_ms)
      .value("last_plan_age_s", r.last_plan_age_s)
      .value("off_plan_replannings", r.off_plan)
      .value("max_off_plan_m", r.max_off_plan_m);
  return h.status();
}

/// A plan that was not optimized (throttled warning) and QP solves that were stopped (error).
inline void logPlanProblems(const planning::PlanResult& res, int uav) {
  if (res.status != planning::PlanStatus::kOptimized) {
    ROS_WARN_STREAM_THROTTLE(2.0, "FormationPlanner UAV " << uav << ": " << planning::toString(res.status) << ": " << res.reason);
  }
  if (res.qp_sparse_timeouts > 0) {
    ROS_ERROR_STREAM("FormationPlanner UAV " << uav << ": " << res.qp_sparse_timeouts
                                             << " QP solve(s) stopped (deadline qp.solve_timeout_s, or ProxQP's sparse "
                                             << "solver broke an invariant: dense backend; docs/safety.md 4.5)");
  }
}

}  // namespace gesture_formation::nodelets

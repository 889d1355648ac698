#pragma once
/// \file
/// \brief A UAV's replanning as a health report (the FormationPlanner's /diagnostics status,
/// docs/ros.md "Diagnostics"): what happened since the previous report and how old the last plan
/// is. ROS-free; not thread-safe (the caller's lock).

#include <string>

#include "gesture_formation/planning/replan_step.hpp"

namespace gesture_formation::planning {

/// \brief One report.
struct ReplanHealthReport {
  enum class Level { kOk, kWarn, kError } level = Level::kOk;
  std::string message = "ok";   ///< the most severe condition
  std::string mode = "track";   ///< the last replanning's mode
  int plans = 0;                ///< plans since the previous report
  int fallbacks = 0;            ///< of which fell back / held (others must avoid them)
  std::string last_status = "none";
  double last_planning_ms = 0.0;
  double last_plan_age_s = -1.0;  ///< −1: no plan yet
  /// Replannings whose measured tracking deviation exceeded the allowance they planned with
  /// (PlanResult::tracking_deviation_m > tracking_allowance_m), and the largest excess [m].
  int off_plan = 0;
  double max_off_plan_m = 0.0;
};

class ReplanHealth {
 public:
  /// \brief A replanning at t_s (only planned ones count).
  void record(const ReplanOutcome& outcome, double t_s);
  /// \brief The report at now_s, then a new interval: ERROR when the last plan is older than 3
  /// replanning periods (after the first plan), WARN while not tracking, after a fallback, or when
  /// the UAV was farther off its plan than the tracking allowance (off_plan).
  ReplanHealthReport report(double now_s, double period_s);

 private:
  ReplanHealthReport next_;
  double last_plan_s_ = -1.0;
};

}  // namespace gesture_formation::planning

// planning::ReplanHealth (the FormationPlanner's /diagnostics status): counts per report, the
// last plan's age, and the level's rules.
#include <gtest/gtest.h>

#include "gesture_formation/planning/replan_health.hpp"

using namespace gesture_formation::planning;
using Level = ReplanHealthReport::Level;

namespace {

ReplanOutcome outcome(ReplanMode mode, bool fallback) {
  ReplanOutcome o;
  o.mode = mode;
  o.fallback = fallback;
  o.result.status = PlanStatus::kOptimized;
  o.result.timings.total_ms = 3.5;
  return o;
}

}  // namespace

TEST(ReplanHealthTest, CountsPerReportAndTheLastPlansAge) {
  ReplanHealth h;
  EXPECT_EQ(h.report(1.0, 0.2).last_plan_age_s, -1.0);  // nothing yet: no error either
  h.record(outcome(ReplanMode::kTrack, false), 2.0);
  h.record(outcome(ReplanMode::kTrack, false), 2.2);
  h.record(outcome(ReplanMode::kSkipped, false), 2.4);  // not planned: not counted
  const ReplanHealthReport r = h.report(2.5, 0.2);
  EXPECT_EQ(r.plans, 2);
  EXPECT_EQ(r.fallbacks, 0);
  EXPECT_NEAR(r.last_plan_age_s, 0.3, 1e-12);
  EXPECT_EQ(r.level, Level::kOk);
  EXPECT_EQ(r.mode, "track");
  EXPECT_DOUBLE_EQ(r.last_planning_ms, 3.5);
  EXPECT_EQ(h.report(2.6, 0.2).plans, 0);  // a new interval
}

TEST(ReplanHealthTest, HoldingOrFallingBackWarnsAndSilenceIsAnError) {
  ReplanHealth h;
  h.record(outcome(ReplanMode::kHold, true), 1.0);
  ReplanHealthReport r = h.report(1.1, 0.2);
  EXPECT_EQ(r.level, Level::kWarn);
  EXPECT_EQ(r.message, "hold");
  EXPECT_EQ(r.fallbacks, 1);
  h.record(outcome(ReplanMode::kTrack, true), 1.2);
  r = h.report(1.3, 0.2);
  EXPECT_EQ(r.level, Level::kWarn);
  EXPECT_EQ(r.message, "1 fallback plan(s)");
  r = h.report(1.2 + 3 * 0.2 + 0.01, 0.2);
  EXPECT_EQ(r.level, Level::kError);
  EXPECT_EQ(r.message.rfind("no plan for", 0), 0u) << r.message;
}

// A UAV farther off its plan than the tracking allowance it planned with (a flight stack lagging
// position-only setpoints, wind beyond the allowance) warns with the largest excess; within the
// allowance it does not.
TEST(ReplanHealthTest, BeingOffThePlanBeyondTheAllowanceWarns) {
  ReplanHealth h;
  ReplanOutcome o = outcome(ReplanMode::kTrack, false);
  o.result.tracking_allowance_m = 0.5;
  o.result.tracking_deviation_m = 0.4;
  h.record(o, 1.0);
  EXPECT_EQ(h.report(1.1, 0.2).level, Level::kOk);
  o.result.tracking_deviation_m = 3.2;
  h.record(o, 1.2);
  o.result.tracking_deviation_m = 1.0;
  h.record(o, 1.4);
  const ReplanHealthReport r = h.report(1.5, 0.2);
  EXPECT_EQ(r.level, Level::kWarn);
  EXPECT_EQ(r.off_plan, 2);
  EXPECT_NEAR(r.max_off_plan_m, 2.7, 1e-12);
  EXPECT_EQ(r.message.rfind("off its plan by up to 2.7 m beyond the tracking allowance in 2 replanning(s)", 0), 0u)
      << r.message;
  EXPECT_EQ(h.report(1.6, 0.2).off_plan, 0);  // a new interval
}

// planning::ReplanStep — the one replanning step of gfctl simulate's UAVs and the
// FormationPlanner nodelet: skip, freshness, listen before moving (with its time limit), the
// worker's extrapolation, hold / search, the start's acceleration from the flown plan, restart.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "gesture_formation/planning/replan_step.hpp"

namespace gf = gesture_formation;
namespace pl = gf::planning;

namespace {

/// Test-only planner: records every request; returns a plan along the reference that accelerates
/// from rest at `accel` (p_k = reference_k + accel·t_k²/2, v_k = accel·t_k: with a reference
/// standing still, a constant acceleration on the plan's Hermite curve too), so that the next
/// request's start acceleration can be checked.
class RecordingPlanner : public pl::Planner {
 public:
  RecordingPlanner(std::shared_ptr<std::vector<pl::PlanRequest>> log, Eigen::Vector3d accel,
                   std::shared_ptr<const pl::PlanStatus> status)
      : log_(std::move(log)), accel_(std::move(accel)), status_(std::move(status)) {}
  pl::PlanResult plan(const pl::PlanRequest& r) override {
    log_->push_back(r);
    pl::PlanResult res;
    res.status = *status_;
    res.verified = true;
    res.trajectory.uav_index = r.uav_index;
    res.trajectory.t0_s = r.t_now_s;
    res.trajectory.dt_s = r.dt_s;
    for (int k = 0; k < r.reference.steps(); ++k) {
      pl::TrajectorySample s;
      const double t = k * r.dt_s;
      s.p_world = r.reference.p_world.col(k) + 0.5 * t * t * accel_;
      s.v_world = t * accel_;
      s.a_world = accel_;
      res.trajectory.samples.push_back(s);
    }
    return res;
  }

 private:
  std::shared_ptr<std::vector<pl::PlanRequest>> log_;
  Eigen::Vector3d accel_;
  std::shared_ptr<const pl::PlanStatus> status_;  ///< what every plan reports (the fixture may change it)
};

pl::ReplanConfig config(int uav) {
  pl::ReplanConfig c;
  c.uav_index = uav;
  c.uav_count = 3;
  c.dt_s = 0.2;
  c.steps = 10;
  c.freshness = pl::FreshnessLimits{2.0, 3.0};
  c.rule = pl::AvoidanceRule{true, 1.0};
  return c;
}

pl::WorkerKnowledge fresh(double t, const Eigen::Vector3d& p, const Eigen::Vector3d& v) {
  pl::WorkerKnowledge w;
  w.stamp_s = t;
  w.fused_s = t;
  w.p_world = p;
  w.v_world = v;
  return w;
}

/// A received plan from `uav` made at t0.
std::optional<pl::ReceivedPlan> planFrom(int uav, double t0) {
  pl::ReceivedPlan r;
  r.plan.uav_index = uav;
  r.plan.t0_s = t0;
  r.plan.dt_s = 0.2;
  r.plan.samples.resize(10);
  for (auto& s : r.plan.samples) s.p_world = Eigen::Vector3d(40.0 + uav, 0.0, 10.0);
  return r;
}

struct Fixture {
  explicit Fixture(int uav, Eigen::Vector3d accel = Eigen::Vector3d::Zero(),
                   pl::PlanStatus status_all = pl::PlanStatus::kOptimized)
      : log(std::make_shared<std::vector<pl::PlanRequest>>()),
        status(std::make_shared<pl::PlanStatus>(status_all)),
        step(config(uav), std::make_unique<RecordingPlanner>(log, accel, status)) {
    received.resize(3);
    in.params = &params;
    in.received = &received;
    in.leader_plan_in_share = true;  // as gfctl simulate (LeaderShare.plan); ROS: ListeningWaitsForTheLeadersPlan…
    in.state.p_world = Eigen::Vector3d(0.0, -8.0, 6.0);
  }
  pl::ReplanOutcome at(double t, const pl::WorkerKnowledge* w) {
    in.t_s = t;
    in.worker = w;
    return step.step(in);
  }
  std::shared_ptr<std::vector<pl::PlanRequest>> log;
  std::shared_ptr<pl::PlanStatus> status;  ///< the recording planner's status (verified) from now on
  pl::ReplanStep step;
  gf::formation::FormationParams params;  // paper Table II: leader + 2 followers
  std::vector<std::optional<pl::ReceivedPlan>> received;
  pl::ReplanInputs in;
};

}  // namespace

TEST(ReplanStepTest, SkipsWithoutWorkerKnowledgeAndCallsNoPlanner) {
  Fixture f(0);
  const auto out = f.at(1.0, nullptr);
  EXPECT_FALSE(out.planned());
  EXPECT_EQ(out.mode, pl::ReplanMode::kSkipped);
  EXPECT_FALSE(out.reason.empty());
  EXPECT_TRUE(f.log->empty());
}

TEST(ReplanStepTest, ListensAtStartUntilEveryOtherFollowerPlannedSinceThen) {
  Fixture f(1);
  const Eigen::Vector3d p(0.0, 0.0, 0.0);
  f.received[2] = planFrom(2, 0.5);  // made before this UAV's first replanning: does not count
  auto w = fresh(1.0, p, Eigen::Vector3d::Zero());
  auto out = f.at(1.0, &w);
  EXPECT_EQ(out.mode, pl::ReplanMode::kHold);
  EXPECT_NE(out.reason.find("listening"), std::string::npos) << out.reason;
  EXPECT_TRUE(out.fallback);
  w = fresh(1.2, p, Eigen::Vector3d::Zero());
  f.received[2] = planFrom(2, 1.1);  // made since: heard
  out = f.at(1.2, &w);
  EXPECT_EQ(out.mode, pl::ReplanMode::kTrack) << out.reason;
  EXPECT_TRUE(out.note.empty());
  EXPECT_FALSE(out.fallback);
  // Once done, the rule stays done (a later silence is the avoidance rule's business).
  f.received[2].reset();
  w = fresh(1.4, p, Eigen::Vector3d::Zero());
  EXPECT_EQ(f.at(1.4, &w).mode, pl::ReplanMode::kTrack);
}

// Over ROS the leader's share (WorkerState) carries no plan: a (re)started follower that heard the
// other follower but not the leader kept listening only for followers and tracked without avoiding
// the leader. It waits for the leader's plan on the plan link unless the plan came with the share
// (gfctl simulate); a UAV missing from a short received table is waited for too.
TEST(ReplanStepTest, ListeningWaitsForTheLeadersPlanUnlessItCameWithTheShare) {
  const Eigen::Vector3d p(0.0, 0.0, 0.0);
  for (const bool in_share : {false, true}) {
    Fixture f(1);
    f.in.leader_plan_in_share = in_share;
    f.received[2] = planFrom(2, 1.1);
    for (const double t : {1.0, 1.2}) {
      const auto w = fresh(t, p, Eigen::Vector3d::Zero());
      const auto out = f.at(t, &w);
      if (in_share && t > 1.0) {
        EXPECT_EQ(out.mode, pl::ReplanMode::kTrack) << out.reason;
      } else if (!in_share) {
        EXPECT_EQ(out.mode, pl::ReplanMode::kHold) << "t " << t;
        EXPECT_NE(out.reason.find("listening"), std::string::npos) << out.reason;
      }
    }
    if (in_share) continue;
    f.received[0] = planFrom(0, 1.3);  // the leader's plan since the start: heard
    const auto w = fresh(1.4, p, Eigen::Vector3d::Zero());
    EXPECT_EQ(f.at(1.4, &w).mode, pl::ReplanMode::kTrack);
  }
  // After a hand-over UAV 1 leads (its plan with the share) and UAV 0 flies on as a follower: a
  // restarted UAV 2 waits for UAV 0's plan too.
  {
    Fixture f(2);
    f.in.leader_index = 1;
    f.received[1] = planFrom(1, 1.1);
    auto w = fresh(1.0, p, Eigen::Vector3d::Zero());
    f.at(1.0, &w);
    w = fresh(1.2, p, Eigen::Vector3d::Zero());
    const auto waiting = f.at(1.2, &w);
    EXPECT_EQ(waiting.mode, pl::ReplanMode::kHold) << "UAV 0, demoted, not heard yet";
    f.received[0] = planFrom(0, 1.3);
    w = fresh(1.4, p, Eigen::Vector3d::Zero());
    EXPECT_EQ(f.at(1.4, &w).mode, pl::ReplanMode::kTrack);
  }
  Fixture short_table(1);
  short_table.in.leader_plan_in_share = true;
  short_table.received.resize(2);  // follower 2 has no entry at all
  const auto w = fresh(1.2, p, Eigen::Vector3d::Zero());
  short_table.at(1.0, &w);
  const auto out = short_table.at(1.2, &w);
  EXPECT_EQ(out.mode, pl::ReplanMode::kHold) << "follower 2, missing from the table, is waited for";
}

// Odometry gone wrong (a NaN position or velocity) plans nothing: a hold or abort point latched
// from it would stay NaN for the rest of the hold.
TEST(ReplanStepTest, ANonFiniteStatePlansNothing) {
  Fixture f(0);
  const auto w = fresh(1.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  f.in.state.v_world.x() = std::nan("");
  const auto out = f.at(1.0, &w);
  EXPECT_FALSE(out.planned());
  EXPECT_NE(out.reason.find("not finite"), std::string::npos) << out.reason;
  EXPECT_TRUE(f.log->empty());
}

TEST(ReplanStepTest, ListeningEndsAfterMaxPlanAgeNamingTheUnheard) {
  Fixture f(0);  // the leader listens for followers 1 and 2
  f.received[1] = planFrom(1, 10.1);
  const Eigen::Vector3d p(0.0, 0.0, 0.0);
  int holds = 0;
  pl::ReplanOutcome out;
  for (double t = 10.0; t < 11.5; t += 0.2) {
    const auto w = fresh(t, p, Eigen::Vector3d::Zero());
    out = f.at(t, &w);
    if (out.mode == pl::ReplanMode::kHold) {
      ++holds;
    } else {
      break;
    }
  }
  EXPECT_EQ(out.mode, pl::ReplanMode::kTrack);
  EXPECT_EQ(holds, 6);  // t = 10.0 … 11.0 (age ≤ max_plan_age_s 1.0 s); tracks at 11.2
  EXPECT_NE(out.note.find("UAV(s) 2"), std::string::npos) << out.note;
}

TEST(ReplanStepTest, FreshWorkerIsExtrapolatedFromItsStampStaleIsFrozen) {
  Fixture f(0);
  f.received[1] = planFrom(1, 5.0);  // made at this UAV's first replanning: heard
  f.received[2] = planFrom(2, 5.0);
  const Eigen::Vector3d p(1.0, 2.0, 0.0), v(0.5, 0.0, 0.0);
  auto w = fresh(4.6, p, v);
  auto out = f.at(5.0, &w);
  ASSERT_EQ(out.mode, pl::ReplanMode::kTrack) << out.reason;
  EXPECT_NEAR((out.worker.p_world.col(0) - (p + 0.4 * v)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((out.worker.p_world.col(3) - (p + (0.4 + 3 * 0.2) * v)).norm(), 0.0, 1e-12);
  // The last fused measurement older than max_worker_age_s: hold, the worker frozen where the
  // estimate puts him, every reference step at one point.
  w = fresh(7.5, p, v);
  w.fused_s = 3.0;
  out = f.at(7.5, &w);
  EXPECT_EQ(out.mode, pl::ReplanMode::kHold);
  EXPECT_NE(out.reason.find("max_worker_age_s"), std::string::npos);
  EXPECT_NEAR((out.worker.p_world.col(5) - p).norm(), 0.0, 1e-12);
  EXPECT_NEAR((out.reference.p_world.col(0) - out.reference.p_world.col(9)).norm(), 0.0, 1e-12);
}

// A UAV listening after its (re)start holds, but the worker's data is fresh: his prediction
// moves with him (frozen, a worker walking up to the holding UAV was checked where he had been).
TEST(ReplanStepTest, AListeningHoldPredictsAFreshWorkerMoving) {
  Fixture f(0);  // nothing heard from UAVs 1 and 2: listening
  const Eigen::Vector3d p(1.0, 2.0, 0.0), v(0.5, 0.0, 0.0);
  auto w = fresh(4.6, p, v);
  const auto out = f.at(5.0, &w);
  ASSERT_EQ(out.mode, pl::ReplanMode::kHold) << out.reason;
  EXPECT_NE(out.reason.find("listening"), std::string::npos) << out.reason;
  EXPECT_NEAR((out.worker.p_world.col(0) - (p + 0.4 * v)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((out.worker.p_world.col(3) - (p + (0.4 + 3 * 0.2) * v)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((out.reference.p_world.col(0) - out.reference.p_world.col(9)).norm(), 0.0, 1e-12);  // it holds
}

TEST(ReplanStepTest, LeaderThatLostTheWorkerSearchesAFollowerHolds) {
  for (int uav : {0, 1}) {
    Fixture f(uav);
    f.received[1] = planFrom(1, 20.0);
    f.received[2] = planFrom(2, 20.0);
    f.in.leader_plan = &f.received[1]->plan;
    auto w = fresh(20.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
    w.fused_s = 10.0;  // 10 s without a measurement
    w.lost = true;
    const auto out = f.at(20.0, &w);
    EXPECT_EQ(out.mode, uav == 0 ? pl::ReplanMode::kSearch : pl::ReplanMode::kHold) << "uav " << uav;
    EXPECT_TRUE(out.holding());
    EXPECT_TRUE(out.fallback);
  }
}

TEST(ReplanStepTest, StartAccelerationIsWhatTheFlownPlanCommandsNotTheInput) {
  const Eigen::Vector3d accel(0.7, -0.2, 0.1);
  Fixture f(0, accel);
  f.received[1] = planFrom(1, 1.0);
  f.received[2] = planFrom(2, 1.0);
  f.in.state.a_world = Eigen::Vector3d(9.0, 9.0, 9.0);  // ignored: odometry carries no acceleration
  auto w = fresh(1.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  f.at(1.0, &w);
  ASSERT_EQ(f.log->size(), 1u);
  EXPECT_NEAR(f.log->back().state.a_world.norm(), 0.0, 1e-12);  // no plan flown yet
  w = fresh(1.2, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  f.at(1.2, &w);
  ASSERT_EQ(f.log->size(), 2u);
  EXPECT_NEAR((f.log->back().state.a_world - accel).norm(), 0.0, 1e-12);
  EXPECT_EQ(f.step.flownPlan().t0_s, 1.2);
}

// The planner's first fallback re-flies its last verified plan. A hold must not fly on the
// tracking plan (it follows the stale prediction the hold is for, for up to the horizon), an
// abort on nothing but its own (it would not retreat); a verified brake plan (a stop) may be
// re-flown in any mode.
TEST(ReplanStepTest, AHoldOrAbortDoesNotFallBackToAPlanMadeForAnotherMode) {
  Fixture f(0);
  f.received[1] = planFrom(1, 1.0);
  f.received[2] = planFrom(2, 1.0);
  const Eigen::Vector3d p(0.0, 0.0, 0.0);
  auto w = fresh(1.0, p, Eigen::Vector3d::Zero());
  struct Step {
    double t;
    pl::ReplanMode mode;
    bool reuse;
  };
  const auto expectStep = [&](const Step& s) {
    const auto out = f.at(s.t, &w);
    ASSERT_EQ(out.mode, s.mode) << "t=" << s.t << ": " << out.reason;
    EXPECT_EQ(f.log->back().reuse_previous, s.reuse) << "t=" << s.t << " (" << pl::toString(s.mode) << ")";
  };
  expectStep({1.0, pl::ReplanMode::kTrack, true});  // nothing verified yet
  w = fresh(1.2, p, Eigen::Vector3d::Zero());
  expectStep({1.2, pl::ReplanMode::kTrack, true});  // a tracking plan, tracking
  // The worker's data goes stale (max_worker_age_s 3 s): hold.
  expectStep({4.6, pl::ReplanMode::kHold, false});  // the last verified plan tracked
  EXPECT_EQ(f.log->back().no_reuse_reason, "previous plan made for track, not hold");
  expectStep({4.8, pl::ReplanMode::kHold, true});   // now a hold plan
  ASSERT_EQ(f.step.receiveAbort(pl::AbortCommand{{"gcs", 7}, pl::AbortSource::kOperator, 4.9}, 4.9),
            pl::AbortAcceptance::kAccepted);
  expectStep({5.0, pl::ReplanMode::kAbort, false});  // the last verified plan held
  expectStep({5.2, pl::ReplanMode::kAbort, true});   // its own
  // A verified brake plan (a stop) is re-flown in any mode; a tracking plan in a track again.
  Fixture g(0);
  g.received[1] = planFrom(1, 1.0);
  g.received[2] = planFrom(2, 1.0);
  w = fresh(1.0, p, Eigen::Vector3d::Zero());
  g.at(1.0, &w);
  *g.status = pl::PlanStatus::kFallbackBrake;
  w = fresh(1.2, p, Eigen::Vector3d::Zero());
  g.at(1.2, &w);
  *g.status = pl::PlanStatus::kOptimized;
  const auto hold = g.at(4.6, &w);
  ASSERT_EQ(hold.mode, pl::ReplanMode::kHold) << hold.reason;
  EXPECT_TRUE(g.log->back().reuse_previous);
  w = fresh(4.8, p, Eigen::Vector3d::Zero());
  ASSERT_EQ(g.at(4.8, &w).mode, pl::ReplanMode::kTrack);
  EXPECT_TRUE(g.log->back().reuse_previous);  // a hold plan stands: tracking may re-fly it
}

TEST(ReplanStepTest, PlannerFallbackIsFlaggedForTheOthers) {
  Fixture f(2, Eigen::Vector3d::Zero(), pl::PlanStatus::kFallbackPrevious);
  f.received[1] = planFrom(1, 1.0);
  auto w = fresh(1.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  const auto out = f.at(1.0, &w);
  EXPECT_EQ(out.mode, pl::ReplanMode::kTrack);
  EXPECT_TRUE(out.fallback);
}

TEST(ReplanStepTest, RestartForgetsAndListensAgain) {
  Fixture f(1, Eigen::Vector3d(0.3, 0.0, 0.0));
  f.received[2] = planFrom(2, 1.0);
  auto w = fresh(1.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  ASSERT_EQ(f.at(1.0, &w).mode, pl::ReplanMode::kTrack);
  ASSERT_FALSE(f.step.flownPlan().empty());
  f.step.restart(std::make_unique<RecordingPlanner>(f.log, Eigen::Vector3d::Zero(), f.status));
  EXPECT_TRUE(f.step.flownPlan().empty());
  w = fresh(5.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  const auto out = f.at(5.0, &w);  // follower 2's plan is from before the restart
  EXPECT_EQ(out.mode, pl::ReplanMode::kHold);
  EXPECT_NE(out.reason.find("listening"), std::string::npos);
  EXPECT_NEAR(f.log->back().state.a_world.norm(), 0.0, 1e-12);
}

TEST(ReplanStepTest, StaleLeaderPlanIsAvoidedButDoesNotShapeTheReference) {
  Fixture f(1);
  f.received[2] = planFrom(2, 10.0);
  auto leader = planFrom(0, 5.0);  // 5 s old (> max_share_age_s 2 s)
  for (auto& s : leader->plan.samples) s.heading_rad = 2.5;
  f.in.leader_plan = &leader->plan;
  auto w = fresh(10.0, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  const auto out = f.at(10.0, &w);
  ASSERT_EQ(out.mode, pl::ReplanMode::kTrack) << out.reason;
  ASSERT_FALSE(f.log->empty());
  bool avoided = false;
  for (const auto& p : f.log->back().higher_priority_plans) avoided = avoided || p.uav_index == 0;
  EXPECT_TRUE(avoided);
  // Without a fresh leader plan the follower's reference uses the leader's desired heading, the
  // same as with no leader plan at all.
  Fixture g(1);
  g.received[2] = planFrom(2, 10.0);
  const auto ref = g.at(10.0, &w);
  EXPECT_NEAR((out.reference.p_world - ref.reference.p_world).norm(), 0.0, 1e-9);
  // … whereas the same plan, fresh, turns the follower's reference with the leader's heading.
  Fixture h(1);
  h.received[2] = planFrom(2, 10.0);
  auto fresh_leader = planFrom(0, 10.0);
  for (auto& s : fresh_leader->plan.samples) s.heading_rad = 2.5;
  h.in.leader_plan = &fresh_leader->plan;
  const auto turned = h.at(10.0, &w);
  EXPECT_GT((turned.reference.p_world - ref.reference.p_world).norm(), 1.0);
}

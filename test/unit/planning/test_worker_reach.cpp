// planning::workerReach / ReachKeeper and the replanning step's back-off (docs/safety.md §3): the
// reach grows at the walking speed bound with the estimate's age and stops at its maximum; a
// holding UAV closer to it than Γ_dis + margin backs off, once, to a goal of the abort's kind that
// the largest reach cannot come near; centred where the worker was at his last fused measurement.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/replan_step.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/planning/worker_reach.hpp"

namespace gf = gesture_formation;
namespace pl = gf::planning;

namespace {

/// A 80 × 80 × 30 m world with ground at z = 0 and a wall north of the worker (y in [14, 24]).
struct WallWorld {
  pl::PrimitiveSet solids;
  pl::OccupancyMap map;
  pl::DistanceField field;
  WallWorld() : solids(makeSolids()), map(makeMap(solids)), field(map) {}
  static pl::PrimitiveSet makeSolids() {
    pl::PrimitiveSet s;
    pl::OrientedBox wall;
    wall.center_world = Eigen::Vector3d(0.0, 19.0, 12.5);
    wall.size_m = Eigen::Vector3d(80.0, 10.0, 25.0);
    s.boxes.push_back(wall);
    return s;
  }
  static pl::OccupancyMap makeMap(const pl::PrimitiveSet& s) {
    pl::MapConfig mc;
    mc.resolution_m = 0.4;
    mc.bounds = pl::Aabb{Eigen::Vector3d(-40, -40, 0), Eigen::Vector3d(40, 40, 30)};
    return pl::OccupancyMap::fromPrimitives(mc, s, pl::GroundSpec{true, 0.0});
  }
  pl::RetreatSpace space() const {
    pl::RetreatSpace r;
    r.field = &field;
    r.bounds = map.gridBounds();
    r.resolution_m = map.resolution();
    r.ground_height_m = 0.0;
    return r;
  }
};

const WallWorld& world() {
  static const WallWorld w;
  return w;
}

const Eigen::Vector3d kWorker(0.0, 0.0, 0.9);

pl::ReachConfig reachConfig() {
  pl::ReachConfig c;
  c.walking_speed_mps = 1.5;
  c.base_m = 1.0;
  c.max_radius_m = 10.0;
  c.margin_m = 1.0;
  c.worker_min_distance_m = 2.5;
  return c;
}

}  // namespace

// ---- the reach ------------------------------------------------------------------------------

TEST(WorkerReachTest, GrowsAtTheWalkingSpeedWithTheAgeAndStopsAtItsMaximum) {
  const pl::ReachConfig c = reachConfig();
  struct Case {
    double age_s, radius_m;
    bool capped;
  };
  for (const Case& k : {Case{0.0, 1.0, false}, Case{2.0, 4.0, false}, Case{5.9, 9.85, false}, Case{6.0, 10.0, true},
                        Case{100.0, 10.0, true}}) {
    const pl::WorkerReach r = pl::workerReach(kWorker, k.age_s, c);
    EXPECT_NEAR(r.radius_m, k.radius_m, 1e-9) << k.age_s;
    EXPECT_EQ(r.capped, k.capped) << k.age_s;
    EXPECT_EQ(r.centre_world, kWorker);
  }
  // Never fused (non-finite age) or a stamp from the future: the largest reach.
  EXPECT_NEAR(pl::workerReach(kWorker, std::nan(""), c).radius_m, 10.0, 1e-12);
  EXPECT_TRUE(pl::workerReach(kWorker, -1.0, c).capped);
  // Walking speed 0: the reach does not grow, however old the estimate.
  pl::ReachConfig still = c;
  still.walking_speed_mps = 0.0;
  EXPECT_NEAR(pl::workerReach(kWorker, 1e6, still).radius_m, 1.0, 1e-12);
  EXPECT_NEAR(pl::workerReach(kWorker, std::nan(""), still).radius_m, 1.0, 1e-12);
}

TEST(WorkerReachTest, TooCloseExactlyBelowGammaDisPlusTheMargin) {
  const pl::ReachConfig c = reachConfig();
  const pl::WorkerReach r = pl::workerReach(kWorker, 2.0, c);  // 4 m
  const double limit = r.radius_m + c.worker_min_distance_m + c.margin_m;  // 7.5 m from the centre
  for (const Eigen::Vector3d& dir : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, -0.6, 0.8)}) {
    EXPECT_TRUE(pl::reachTooClose(r, kWorker + dir * (limit - 0.01), c));
    EXPECT_FALSE(pl::reachTooClose(r, kWorker + dir * (limit + 0.01), c));
  }
}

// ---- the back-off goal ----------------------------------------------------------------------

class BackoffGoalAroundTheWorker : public ::testing::TestWithParam<int> {};

TEST_P(BackoffGoalAroundTheWorker, TheLargestReachStaysClearOfItAndOfTheObstaclesInTheUavsLayer) {
  const pl::ReachConfig c = reachConfig();
  const pl::AbortConfig abort;
  const double bearing = GetParam() * M_PI / 4.0;  // all round, also towards the wall
  std::vector<Eigen::Vector3d> goals;
  for (int uav = 0; uav < 3; ++uav) {
    const Eigen::Vector3d p = kWorker + Eigen::Vector3d(6.0 * std::cos(bearing), 6.0 * std::sin(bearing), 1.0);
    const pl::WorkerReach reach = pl::workerReach(kWorker, 2.0, c);
    const auto g = pl::chooseBackoffGoal(uav, 3, p, reach, world().space(), abort, c);
    ASSERT_TRUE(g) << g.reason();
    // The largest reach stays Γ_dis + margin away, horizontally already.
    const pl::WorkerReach largest = pl::workerReach(kWorker, 1e9, c);
    EXPECT_GE((*g - kWorker).head<2>().norm(), c.max_radius_m + c.worker_min_distance_m + c.margin_m - 1e-9);
    EXPECT_FALSE(pl::reachTooClose(largest, *g, c));
    EXPECT_GE(world().field.clearance(*g), abort.goal_clearance_m);
    EXPECT_DOUBLE_EQ(g->z(), abort.retreat_height_m + uav * abort.layer_spacing_m);  // its own layer
    for (const auto& other : goals) EXPECT_GE((*g - other).norm(), abort.layer_spacing_m);
    goals.push_back(*g);
    // Deterministic: the same inputs, the same goal.
    EXPECT_EQ(*pl::chooseBackoffGoal(uav, 3, p, reach, world().space(), abort, c), *g);
  }
}
INSTANTIATE_TEST_SUITE_P(Bearings, BackoffGoalAroundTheWorker, ::testing::Range(0, 8));

TEST(BackoffGoalTest, WithoutAMapItFailsSayingWhy) {
  const auto g = pl::chooseBackoffGoal(1, 3, Eigen::Vector3d(5, 0, 2), pl::workerReach(kWorker, 1.0, reachConfig()),
                                       pl::RetreatSpace{}, pl::AbortConfig{}, reachConfig());
  ASSERT_FALSE(g);
  EXPECT_NE(g.reason().find("no map"), std::string::npos) << g.reason();
}

// ---- ReachKeeper: the centre and the trigger -------------------------------------------------

TEST(ReachKeeperTest, CentreIsTheEstimateTakenBackToItsLastFusedMeasurementAndKeptOnceLost) {
  pl::ReachKeeper k(1, 3, reachConfig(), pl::AbortConfig{}, world().space());
  pl::WorkerKnowledge w;
  w.fused_s = 10.0;
  w.stamp_s = 13.0;  // extrapolated 3 s at 1 m/s east
  w.p_world = kWorker + Eigen::Vector3d(3.0, 0.0, 0.0);
  w.v_world = Eigen::Vector3d(1.0, 0.0, 0.0);
  k.observe(w);
  pl::ReachKeeper::Situation s;
  s.t_s = 13.0;
  s.p_world = s.hold_world = kWorker + Eigen::Vector3d(-30.0, 0.0, 0.0);  // far: no back-off
  pl::ReachKeeper::Decision d = k.decide(s);
  EXPECT_LT((d.reach.centre_world - kWorker).norm(), 1e-12);
  EXPECT_NEAR(d.reach.age_s, 3.0, 1e-12);
  EXPECT_FALSE(d.goal);
  EXPECT_FALSE(d.started);
  // The estimator lost him: it holds a position further on, with no velocity; the centre stays.
  w.lost = true;
  w.stamp_s = 20.0;
  w.p_world = kWorker + Eigen::Vector3d(5.0, 0.0, 0.0);
  w.v_world.setZero();
  k.observe(w);
  s.t_s = 20.0;
  d = k.decide(s);
  EXPECT_LT((d.reach.centre_world - kWorker).norm(), 1e-12);
  EXPECT_TRUE(d.reach.capped);  // 1 + 1.5 · 10 > 10
}

TEST(ReachKeeperTest, BacksOffOnceWhenTheReachComesWithinGammaDisPlusMarginAndReleases) {
  const pl::ReachConfig c = reachConfig();
  pl::ReachKeeper k(1, 3, c, pl::AbortConfig{}, world().space());
  pl::WorkerKnowledge w;
  w.fused_s = w.stamp_s = 0.0;
  w.p_world = kWorker;
  k.observe(w);
  pl::ReachKeeper::Situation s;
  s.p_world = s.hold_world = kWorker + Eigen::Vector3d(0.0, -8.0, 1.0);  // |·| = 8.06 m
  // Too close once 1 + 1.5·age > 8.06 − 3.5, i.e. from age 2.375 s on.
  s.t_s = 2.2;
  EXPECT_FALSE(k.decide(s).goal);
  s.t_s = 2.6;
  const pl::ReachKeeper::Decision first = k.decide(s);
  ASSERT_TRUE(first.goal) << first.reason;
  EXPECT_TRUE(first.started);
  EXPECT_NE(first.reason.find("backing off"), std::string::npos) << first.reason;
  // Latched: later replannings keep the goal (it was chosen for the largest reach).
  s.t_s = 30.0;
  s.p_world = *first.goal;
  const pl::ReachKeeper::Decision later = k.decide(s);
  ASSERT_TRUE(later.goal);
  EXPECT_FALSE(later.started);
  EXPECT_EQ(*later.goal, *first.goal);
  EXPECT_TRUE(later.reach.capped);
  EXPECT_FALSE(pl::reachTooClose(later.reach, *later.goal, c));
  // The hold point counts too: the UAV far away but its hold point near the reach.
  k.release();
  EXPECT_FALSE(k.goal());
  s.t_s = 2.6;
  s.p_world = kWorker + Eigen::Vector3d(0.0, -30.0, 1.0);
  s.hold_world = kWorker + Eigen::Vector3d(0.0, -8.0, 1.0);
  EXPECT_TRUE(k.decide(s).goal);
}

// ---- in the replanning step --------------------------------------------------------------------

namespace {

class FlyingPlanner : public pl::Planner {
 public:
  explicit FlyingPlanner(std::shared_ptr<std::vector<pl::PlanRequest>> log) : log_(std::move(log)) {}
  pl::PlanResult plan(const pl::PlanRequest& r) override {
    log_->push_back(r);
    pl::PlanResult res;
    res.status = pl::PlanStatus::kOptimized;
    res.trajectory.uav_index = r.uav_index;
    res.trajectory.t0_s = r.t_now_s;
    res.trajectory.dt_s = r.dt_s;
    for (int k = 0; k < r.reference.steps(); ++k) {
      pl::TrajectorySample s;
      s.p_world = r.reference.p_world.col(k);
      res.trajectory.samples.push_back(s);
    }
    return res;
  }

 private:
  std::shared_ptr<std::vector<pl::PlanRequest>> log_;
};

struct HoldingFollower {
  std::shared_ptr<std::vector<pl::PlanRequest>> log = std::make_shared<std::vector<pl::PlanRequest>>();
  pl::ReplanStep step;
  gf::formation::FormationParams params;
  std::vector<std::optional<pl::ReceivedPlan>> received;
  pl::WorkerKnowledge w;
  explicit HoldingFollower(const pl::ReachConfig& reach)
      : step(config(reach), std::make_unique<FlyingPlanner>(log), world().space()), received(3) {
    w.stamp_s = w.fused_s = 0.0;  // the share and the estimate from 0 s: stale from 3 s on
    w.p_world = kWorker;
  }
  static pl::ReplanConfig config(const pl::ReachConfig& reach) {
    pl::ReplanConfig c;
    c.uav_index = 1;
    c.uav_count = 3;
    c.steps = 10;
    c.freshness = pl::FreshnessLimits{2.0, 3.0};
    c.rule = pl::AvoidanceRule{true, 1.0};
    c.reach = reach;
    return c;
  }
  pl::ReplanOutcome at(double t, const Eigen::Vector3d& p) {
    pl::ReceivedPlan m;
    m.plan.uav_index = 2;
    m.plan.t0_s = t - 0.1;
    m.plan.dt_s = 0.2;
    m.plan.samples.resize(3);
    received[2] = m;
    pl::ReplanInputs in;
    in.t_s = t;
    in.state.p_world = p;
    in.worker = &w;
    in.params = &params;
    in.leader_plan_in_share = true;  // as gfctl simulate's share: listening ends by hearing follower 2
    in.received = &received;
    return step.step(in);
  }
};

}  // namespace

TEST(ReplanStepReachTest, AHoldingFollowerBacksOffFromTheGrowingReachAlongAnOrdinaryFlaggedPlan) {
  HoldingFollower f(reachConfig());
  const Eigen::Vector3d p(0.0, -8.0, 1.9);  // 8 m south of the worker
  f.at(0.0, p);                                  // listening: follower 2's plan predates it
  const pl::ReplanOutcome before = f.at(2.0, p);  // the reach 4 m: 4 m clear of the UAV
  EXPECT_EQ(before.mode, pl::ReplanMode::kTrack);
  EXPECT_FALSE(before.backing_off);
  const pl::ReplanOutcome out = f.at(3.2, p);  // stale: hold; reach 5.8 m, 2.2 m clear < 3.5 m
  EXPECT_EQ(out.mode, pl::ReplanMode::kHold) << out.reason;
  EXPECT_NE(out.reason.find("max_share_age_s"), std::string::npos) << out.reason;  // the hold's reason, unchanged
  EXPECT_TRUE(out.backing_off);
  EXPECT_TRUE(out.backoff_started);
  EXPECT_TRUE(out.fallback);  // right of way, as any hold
  const pl::PlanRequest& r = f.log->back();
  // Towards the goal, away from the worker, around the other UAVs' plans; the worker keep-out and
  // the camera stay on the estimate.
  const Eigen::Vector3d end = r.reference.p_world.col(r.reference.steps() - 1);
  EXPECT_GT((end - kWorker).norm(), (p - kWorker).norm());
  EXPECT_EQ(r.higher_priority_plans.size(), 1u);
  EXPECT_NEAR((Eigen::Vector3d(r.worker.p_world.col(0)) - kWorker).norm(), 0.0, 1e-12);
  // Flying on: the goal is kept; no new start.
  const pl::ReplanOutcome next = f.at(3.6, end);
  EXPECT_TRUE(next.backing_off);
  EXPECT_FALSE(next.backoff_started);
  // Fresh data again: tracking, the back-off released.
  f.w.stamp_s = f.w.fused_s = 4.0;
  const pl::ReplanOutcome back = f.at(4.0, end);
  EXPECT_EQ(back.mode, pl::ReplanMode::kTrack);
  EXPECT_FALSE(back.backing_off);
  EXPECT_TRUE(back.backoff.empty());
}

// Power towers, leader_dropout seed 51: a follower backing off became the leader and tracked again,
// its track plans failed for 5.6 s and each failure flew the back-off on — 10 m further and 7 m
// lower, out of the camera's view of the worker, who was then lost for the rest of the mission. A
// back-off is not the fallback of a UAV that no longer backs off: its failed plans brake.
TEST(ReplanStepReachTest, AUavThatNoLongerBacksOffDoesNotFallBackToTheBackOff) {
  HoldingFollower f(reachConfig());
  const Eigen::Vector3d p(0.0, -8.0, 1.9);
  f.at(0.0, p);
  f.at(2.0, p);
  EXPECT_TRUE(f.log->back().reuse_previous);  // tracking: the previous plan is an ordinary fallback
  ASSERT_TRUE(f.at(3.2, p).backing_off);
  EXPECT_TRUE(f.log->back().reuse_previous);  // backing off: its own plan may be flown on
  ASSERT_TRUE(f.at(3.6, p).backing_off);
  EXPECT_TRUE(f.log->back().reuse_previous);
  f.w.stamp_s = f.w.fused_s = 4.0;
  ASSERT_EQ(f.at(4.0, p).mode, pl::ReplanMode::kTrack);
  EXPECT_FALSE(f.log->back().reuse_previous);  // the plan flown is the back-off: a failure brakes
  f.w.stamp_s = f.w.fused_s = 4.4;
  ASSERT_EQ(f.at(4.4, p).mode, pl::ReplanMode::kTrack);
  EXPECT_TRUE(f.log->back().reuse_previous);  // an optimized track plan since: ordinary again
}

TEST(ReplanStepReachTest, WithAWalkingSpeedOfZeroTheHoldKeepsItsPoint) {
  pl::ReachConfig still = reachConfig();
  still.walking_speed_mps = 0.0;
  HoldingFollower f(still);
  const Eigen::Vector3d p(0.0, -8.0, 1.9);
  f.at(0.0, p);
  for (double t = 3.2; t < 60.0; t += 0.4) {
    const pl::ReplanOutcome out = f.at(t, p);
    ASSERT_EQ(out.mode, pl::ReplanMode::kHold);
    ASSERT_FALSE(out.backing_off) << t;
    const pl::PlanRequest& r = f.log->back();
    ASSERT_LT((Eigen::Vector3d(r.reference.p_world.col(9)) - p).norm(), 1e-9) << t;  // the braking point (at rest)
  }
}

TEST(ReplanStepReachTest, WithoutAGoalTheUavKeepsItsHoldPointAndSaysWhy) {
  // No map: no back-off goal can be chosen.
  pl::ReplanConfig c = HoldingFollower::config(reachConfig());
  auto log = std::make_shared<std::vector<pl::PlanRequest>>();
  pl::ReplanStep step(c, std::make_unique<FlyingPlanner>(log));
  gf::formation::FormationParams params;
  pl::WorkerKnowledge w;
  w.stamp_s = w.fused_s = 0.0;
  w.p_world = kWorker;
  pl::ReplanInputs in;
  in.worker = &w;
  in.params = &params;
  in.state.p_world = Eigen::Vector3d(0.0, -6.0, 1.9);
  in.t_s = 3.2;
  const pl::ReplanOutcome out = step.step(in);
  EXPECT_EQ(out.mode, pl::ReplanMode::kHold);
  EXPECT_FALSE(out.backing_off);
  EXPECT_TRUE(out.backoff_started);
  EXPECT_NE(out.backoff.find("no back-off goal"), std::string::npos) << out.backoff;
  EXPECT_LT((Eigen::Vector3d(log->back().reference.p_world.col(9)) - in.state.p_world).norm(), 1e-9);
}

TEST(ReplanConfigTest, TheReachSettingsAreValidatedByKey) {
  pl::ReplanConfig c;
  c.reach.walking_speed_mps = -1.0;
  c.reach.max_radius_m = 0.0;
  c.reach.base_m = std::nan("");
  c.reach.margin_m = -0.5;
  const auto problems = c.validate("mission.");
  ASSERT_EQ(problems.size(), 4u);
  for (const char* key : {"mission.faults.reach_walking_speed_mps", "mission.faults.reach_base_m",
                          "mission.faults.reach_max_m", "mission.faults.reach_margin_m"}) {
    bool found = false;
    for (const auto& p : problems) found = found || p.find(key) != std::string::npos;
    EXPECT_TRUE(found) << key;
  }
}

// The mission runner with a test-only stand-in planner (the product uses planning::UavPlanner):
// the plan is the stage-1 reference itself, which is safe in an empty world.
#include <gtest/gtest.h>

#include <fstream>

#include "gesture_formation/sim/mission_runner.hpp"
#include "sim_test_support.hpp"

namespace gf = gesture_formation;

namespace {

/// Test-only: returns the reference as the plan (or nothing when `fail` is set).
class ReferencePlanner : public gf::sim::MissionPlanner {
 public:
  explicit ReferencePlanner(bool fail) : fail_(fail) {}
  gf::planning::PlanResult plan(const gf::planning::PlanRequest& r) override {
    gf::planning::PlanResult res;
    if (fail_) {
      res.status = gf::planning::PlanStatus::kFallbackBrake;
      return res;  // empty trajectory: the controller must brake to hover
    }
    return gf::sim::test::referenceAsPlan(r);
  }

 private:
  bool fail_;
};

using World = gf::sim::test::EmptyWorld;

gf::sim::MissionConfig openFieldMission() {
  gf::sim::MissionConfig c = gf::sim::test::openFieldWithoutRequests();
  gf::sim::OperatorRequest q;
  q.t_s = 5.0;
  q.target_text = "[2]";
  q.target = gf::formation::CommandTarget::list({2});
  q.parameter = gf::formation::Parameter::kDistance;
  q.amount = 2.0;
  c.requests.push_back(q);
  return c;
}

}  // namespace

TEST(MissionRunnerTest, SubsetRequestChangesOnlyItsUavAndRunIsDeterministic) {
  World w;
  const auto cfg = openFieldMission();
  gf::sim::MissionWorld world{&w.map, &w.field, 0.0};
  const gf::sim::PlannerFactory factory = [](int) { return std::make_unique<ReferencePlanner>(false); };
  const auto a = gf::sim::runMission(cfg, world, factory, nullptr, 7, 20.0);
  const auto b = gf::sim::runMission(cfg, world, factory, nullptr, 7, 20.0);
  ASSERT_TRUE(a) << a.reason();
  ASSERT_TRUE(b);
  ASSERT_EQ(a->timeline.size(), b->timeline.size());
  for (std::size_t i = 0; i < a->timeline.size(); ++i) {
    for (std::size_t u = 0; u < 3; ++u) ASSERT_EQ(a->timeline[i].uavs[u].p_world, b->timeline[i].uavs[u].p_world);
  }
  EXPECT_EQ(a->metrics.requests_applied, 1);
  ASSERT_EQ(a->requests.size(), 1u);
  EXPECT_EQ(a->requests[0].uavs, std::vector<int>({2}));
  EXPECT_NEAR(a->requests[0].applied_s, 5.1, 1e-9);  // operator link 0.1 s
  EXPECT_GE(a->requests[0].adaptation_start_s, a->requests[0].applied_s);
  for (const auto& row : a->timeline) {
    EXPECT_EQ(row.uavs[0].d_ref, 10.0);
    EXPECT_EQ(row.uavs[1].d_ref, 8.0);
    EXPECT_EQ(row.uavs[2].d_ref, row.t_s < 5.1 ? 8.0 : 10.0);
  }
  EXPECT_NEAR(a->timeline.back().uavs[2].d_t, 10.0, 1.0);  // follower 2 moved out
  EXPECT_NEAR(a->timeline.back().uavs[1].d_t, 8.0, 1.0);   // follower 1 stayed
  EXPECT_EQ(a->metrics.collisions, 0);
  EXPECT_LT(a->metrics.human_estimate_error_rms_m, 0.5);
  EXPECT_GT(a->metrics.visible_fraction, 0.8);
}

TEST(MissionRunnerTest, UavWithoutPlanBrakesToHover) {
  World w;
  const auto cfg = openFieldMission();
  gf::sim::MissionWorld world{&w.map, &w.field, 0.0};
  const gf::sim::PlannerFactory factory = [](int i) { return std::make_unique<ReferencePlanner>(i == 1); };
  const auto out = gf::sim::runMission(cfg, world, factory, nullptr, 3, 20.0);
  ASSERT_TRUE(out) << out.reason();
  // Follower 1 never gets a plan: it stays near its start while the worker walks away.
  const Eigen::Vector3d start = out->timeline.front().uavs[1].p_world;
  for (const auto& row : out->timeline) EXPECT_LT((row.uavs[1].p_world - start).norm(), 1.0) << row.t_s;
  EXPECT_GT((out->timeline.back().uavs[0].p_world - out->timeline.front().uavs[0].p_world).norm(), 5.0);
  EXPECT_GT(out->metrics.plans_fallback_brake, 0);
}

TEST(MissionRunnerTest, InitialPositionInsideObstacleIsRefused) {
  World w;
  auto cfg = openFieldMission();
  cfg.uavs[1].initial_position = Eigen::Vector3d(0, 0, 0.1);  // in the ground
  gf::sim::MissionWorld world{&w.map, &w.field, 0.0};
  const gf::sim::PlannerFactory factory = [](int) { return std::make_unique<ReferencePlanner>(false); };
  const auto out = gf::sim::runMission(cfg, world, factory, nullptr, 1, 5.0);
  ASSERT_FALSE(out);
  EXPECT_NE(out.reason().find("mission.uavs[1].initial_position"), std::string::npos) << out.reason();
}

namespace {

/// Test-only classifier: every camera reads "extend arm" (gesture 2) in every frame.
class AlwaysExtendArm : public gf::sim::MissionClassifier {
 public:
  gf::common::Result<gf::gesture::Classification> classify(const gf::gesture::SkeletonWindow&) override {
    gf::gesture::Classification c;
    c.gesture_id = 2;
    return gf::common::Result<gf::gesture::Classification>::ok(c);
  }
};

/// The 20-s mission of `cfg` with every camera reading "extend arm" and reference-following
/// planners: the gesture commands it fired, and the inter-UAV messages the links lost.
struct ExtendArmRun {
  int gestures_fired = 0;
  long messages_lost = 0;
};
ExtendArmRun runEveryCameraReadingExtendArm(const gf::sim::MissionConfig& cfg) {
  World w;
  gf::sim::MissionWorld world{&w.map, &w.field, 0.0};
  const gf::sim::PlannerFactory factory = [](int) { return std::make_unique<ReferencePlanner>(false); };
  AlwaysExtendArm classifier;
  const auto out = gf::sim::runMission(cfg, world, factory, &classifier, 3, 20.0);
  EXPECT_TRUE(out) << out.reason();
  ExtendArmRun run;
  if (!out) return run;
  for (const auto& r : out->requests) run.gestures_fired += r.source == "gesture" ? 1 : 0;
  run.messages_lost = out->metrics.messages_lost;
  return run;
}

}  // namespace

// The followers' gesture votes reach the leader over the inter-UAV link (as over LCM in the ROS
// system), so they share its faults: with every message lost, the leader's own view is 1 of the
// 2 agreeing views the vote needs and nothing fires; with a working link the same readings fire.
// The test's readings are made up (the simulated worker does not extend an arm), so the vote is
// tested without the 3-D check of every gesture; with it (the default) they fire nothing.
TEST(MissionRunnerTest, FollowerGestureVotesTravelTheLossyLink) {
  auto cfg = gf::sim::test::openFieldWithoutRequests();
  ASSERT_EQ(cfg.view_fusion.min_agreeing_views, 2);
  ASSERT_TRUE(cfg.view_fusion.require_3d);
  cfg.view_fusion.require_3d = false;
  const ExtendArmRun ok = runEveryCameraReadingExtendArm(cfg);
  EXPECT_GE(ok.gestures_fired, 1);
  EXPECT_EQ(ok.messages_lost, 0);
  cfg.link.loss_probability = 1.0;
  const ExtendArmRun lost = runEveryCameraReadingExtendArm(cfg);
  EXPECT_EQ(lost.gestures_fired, 0);
  EXPECT_GT(lost.messages_lost, 0);
  // The 3-D check (docs/gestures.md §6): every view reads "extend", the triangulated arm is not.
  cfg.link.loss_probability = 0.0;
  cfg.view_fusion.require_3d = true;
  EXPECT_EQ(runEveryCameraReadingExtendArm(cfg).gestures_fired, 0);
}

// A slow link (safety.md §2.1): every follower vote arrives 0.35 s after its frame, older than
// view_fusion.max_age_s (0.25 s). Fused at the newest frame only the leader's view votes and no
// gesture fires; fused view_fusion.fusion_lag_s (0.4 s) in the past the same readings fire.
TEST(MissionRunnerTest, DelayedFollowerVotesCountWhenTheViewsAreFusedAtALag) {
  auto cfg = gf::sim::test::openFieldWithoutRequests();
  ASSERT_EQ(cfg.view_fusion.min_agreeing_views, 2);
  cfg.view_fusion.require_3d = false;  // made-up readings (above): the lag is tested, not the 3-D check
  cfg.link.delay_s = 0.35;
  cfg.view_fusion.fusion_lag_s = 0.0;  // fused at the newest frame (the default is 0.4 s)
  EXPECT_EQ(runEveryCameraReadingExtendArm(cfg).gestures_fired, 0);
  cfg.view_fusion.fusion_lag_s = 0.4;
  EXPECT_GE(runEveryCameraReadingExtendArm(cfg).gestures_fired, 1);
}

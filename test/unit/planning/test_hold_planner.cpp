// The hold / search / listening rules of one replanning (docs/safety.md §1 rules 2–4, §2.2,
// §2.4): planning::holdReason, brakingPoint, holdReference, searching, searchTargets,
// HoldPlanner — the parts planning::ReplanStep is made of (listening: test_replan_step.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "gesture_formation/planning/replan_step.hpp"
#include "gesture_formation/planning/plan_request_builder.hpp"

namespace gf = gesture_formation;

TEST(HoldReferenceTest, StopsAtTheBrakingPointAndLooksAtTheWorker) {
  const Eigen::Vector3d stop = gf::planning::brakingPoint(Eigen::Vector3d(0, 0, 5), Eigen::Vector3d(2, 0, 0), 4.0);
  EXPECT_TRUE(stop.isApprox(Eigen::Vector3d(0.5, 0, 5)));  // v²/(2a) = 0.5 m ahead
  const auto ref = gf::planning::holdReference(stop, Eigen::Vector3d(10.5, 5, 1), 0.3, 10);
  ASSERT_EQ(ref.steps(), 10);
  for (int k = 0; k < 10; ++k) {
    EXPECT_TRUE(ref.p_world.col(k).isApprox(stop));
    EXPECT_NEAR(ref.heading_rad(k), std::atan2(5.0, 10.0), 1e-12);
    EXPECT_NEAR(ref.pitch_rad(k), std::atan2(-4.0, std::hypot(10.0, 5.0)), 1e-12);
  }
}

TEST(SearchTest, OnlyTheLeaderSearchesForALostWorkerForABoundedTime) {
  const gf::planning::FreshnessLimits lim{2.0, 3.0};
  gf::planning::SearchConfig cfg;  // 60 s, 15 m, 8 s
  const std::string lost = "worker not seen for more than max_worker_age_s";
  EXPECT_TRUE(gf::planning::searching(0, lost, 10.0, 5.0, lim, cfg));
  EXPECT_TRUE(gf::planning::searching(0, lost, 68.0, 5.0, lim, cfg));    // 3 + 60 s after the last fusion
  EXPECT_FALSE(gf::planning::searching(0, lost, 68.1, 5.0, lim, cfg));   // then it only holds
  EXPECT_FALSE(gf::planning::searching(1, "worker estimate older than max_worker_age_s", 10.0, 5.0, lim, cfg));
  EXPECT_FALSE(gf::planning::searching(0, "", 10.0, 9.0, lim, cfg));
  cfg.timeout_s = 0.0;
  EXPECT_FALSE(gf::planning::searching(0, lost, 10.0, 5.0, lim, cfg));
  EXPECT_FALSE(gf::planning::searching(0, lost, 10.0, std::numeric_limits<double>::quiet_NaN(), lim, gf::planning::SearchConfig{}));
  // The sweep: from the estimate when the sweep began (here 8 s), up, back, down, back every 8 s,
  // as far as 0.5 m/s × the estimate's age (last fused at 5 s). The vertical sweep alone here (the
  // sideways one, on by default, is the next test).
  gf::planning::SearchConfig vertical_only;
  vertical_only.horizontal_speed_mps = 0.0;
  const Eigen::Vector3d last(1, 2, 3);
  const auto tg = gf::planning::searchTargets(last, Eigen::Vector3d(11, 2, 8), 8.0, 1.0, 10, 5.0, 8.0, vertical_only);
  ASSERT_EQ(tg.cols(), 10);
  const double want[] = {0, 1.0, 2.5, 1.5, 0, -2.0, -4.5, -2.5, 0, 3.0};
  for (int k = 0; k < 10; ++k) {
    EXPECT_NEAR(tg(2, k) - 3.0, want[k], 1e-9) << k;
    EXPECT_EQ(tg.col(k).head<2>(), last.head<2>());
  }
  // The search's ranges live in planning::replanConfigFields() (mission keys faults.search_*).
  EXPECT_EQ(gf::planning::ReplanConfig{}.validate("mission.").size(), 0u);
  gf::planning::ReplanConfig bad;
  bad.search = gf::planning::SearchConfig{-1.0, 0.0, 0.0, std::nan(""), -0.5};
  const auto problems = bad.validate("mission.");
  ASSERT_EQ(problems.size(), 5u);
  EXPECT_NE(problems[0].find("mission.faults.search_timeout_s"), std::string::npos);
  EXPECT_NE(problems[1].find("mission.faults.search_height_m"), std::string::npos);
  EXPECT_NE(problems[2].find("mission.faults.search_vertical_speed_mps"), std::string::npos);
  EXPECT_NE(problems[3].find("mission.faults.search_period_s"), std::string::npos);
  EXPECT_NE(problems[4].find("mission.faults.search_horizontal_speed_mps must be >= 0, got -0.5"), std::string::npos)
      << problems[4];
  // The amplitude stops at height_m.
  const auto late = gf::planning::searchTargets(last, Eigen::Vector3d(11, 2, 8), 70.0, 1.0, 8, 5.0, 8.0, vertical_only);
  EXPECT_LE(late.row(2).maxCoeff(), 3.0 + 15.0 + 1e-9);
  EXPECT_NEAR(late.row(2).maxCoeff() - 3.0, 15.0, 1e-9);  // the top of the cycle at 74 s (phase 8.25)
}

// The sideways sweep (search_horizontal_speed_mps): the estimate turned about the vertical through
// the camera, left, back, right, back every 2 × period_s, by atan(speed × age / horizontal distance),
// while the vertical sweep goes on as before; the distance from the camera stays that of the estimate.
TEST(SearchTest, TheSidewaysSweepTurnsAsFarAsHeCouldHaveWalked) {
  gf::planning::SearchConfig cfg;  // period 8 s
  EXPECT_EQ(cfg.horizontal_speed_mps, 1.5);  // on by default since 2026-12-03
  cfg.horizontal_speed_mps = 1.0;
  gf::planning::SearchConfig vertical_only;
  vertical_only.horizontal_speed_mps = 0.0;
  const Eigen::Vector3d camera(0, 0, 10), est(10, 0, 1);
  // Last fused at 0 s, the sweep began at 10 s; steps every 2 s from 10 s.
  const auto tg = gf::planning::searchTargets(est, camera, 10.0, 2.0, 9, 0.0, 10.0, cfg);
  const auto vertical = gf::planning::searchTargets(est, camera, 10.0, 2.0, 9, 0.0, 10.0, vertical_only);
  ASSERT_EQ(tg.cols(), 9);
  const double w_h[] = {0, 0.5, 1, 0.5, 0, -0.5, -1, -0.5, 0};  // triangle wave over 16 s, sampled every 2 s
  for (int k = 0; k < 9; ++k) {
    const double age = 10.0 + 2.0 * k;
    const double want = std::atan2(1.0 * age, 10.0) * w_h[k];
    EXPECT_NEAR(std::atan2(tg(1, k) - camera.y(), tg(0, k) - camera.x()), want, 1e-9) << k;
    EXPECT_NEAR((tg.col(k) - camera).head<2>().norm(), 10.0, 1e-9) << k;
    EXPECT_NEAR(tg(2, k), vertical(2, k), 1e-12) << k;  // the vertical sweep unchanged
  }
  // Off (0), or straight above the estimate: no turn.
  for (int k = 0; k < 9; ++k) EXPECT_EQ(vertical.col(k).head<2>(), est.head<2>());
  const auto above = gf::planning::searchTargets(est, Eigen::Vector3d(10, 0, 12), 10.0, 2.0, 9, 0.0, 10.0, cfg);
  for (int k = 0; k < 9; ++k) EXPECT_EQ(above.col(k).head<2>(), est.head<2>());
}

// The stateful sequence gfctl simulate and the FormationPlanner share: latch the braking point,
// look at the prediction while the estimator extrapolates, sweep once it has lost the worker.
TEST(HoldPlannerTest, HoldsAtTheLatchedPointAndSweepsOnlyOnceTheEstimatorLostTheWorker) {
  const gf::planning::FreshnessLimits lim{2.0, 3.0};
  gf::planning::HoldPlanner hp(lim, gf::planning::SearchConfig{}, 4.0);
  gf::planning::HoldPlanner::Situation s;
  s.uav_index = 0;
  s.dt_s = 1.0;
  s.steps = 10;
  s.worker_stamp_s = 5.0;
  s.p_world = Eigen::Vector3d(0, 0, 5);
  s.v_world = Eigen::Vector3d(2, 0, 0);
  s.worker_world = Eigen::Vector3d(10.5, 0, 1);
  s.t_s = 7.0;  // fresh
  auto d = hp.decide(s);
  EXPECT_EQ(d.mode, gf::planning::HoldMode::kTrack);
  EXPECT_FALSE(d.holding());
  EXPECT_FALSE(hp.holdPoint());
  EXPECT_EQ(d.camera_target.cols(), 0);
  // 3.2 s without a fusion: hold; the estimator still extrapolates, so the camera follows it.
  s.t_s = 8.2;
  s.hold_reason = "worker not seen for more than max_worker_age_s";
  d = hp.decide(s);
  EXPECT_EQ(d.mode, gf::planning::HoldMode::kHold);
  ASSERT_TRUE(hp.holdPoint());
  EXPECT_TRUE(hp.holdPoint()->isApprox(Eigen::Vector3d(0.5, 0, 5)));
  ASSERT_EQ(d.reference.steps(), 10);
  EXPECT_TRUE(d.reference.p_world.col(9).isApprox(Eigen::Vector3d(0.5, 0, 5)));
  EXPECT_NEAR(d.reference.pitch_rad(0), std::atan2(-4.0, 10.0), 1e-12);
  EXPECT_EQ(d.camera_target.cols(), 0);
  // The UAV drifts while braking: the hold point stays latched.
  s.t_s = 9.0;
  s.p_world = Eigen::Vector3d(0.3, 0, 5);
  s.v_world = Eigen::Vector3d(1, 0, 0);
  d = hp.decide(s);
  EXPECT_TRUE(d.reference.p_world.col(0).isApprox(Eigen::Vector3d(0.5, 0, 5)));
  // The estimator has lost him (5 s): the sweep starts at the estimate, phase 0 now.
  s.t_s = 10.4;
  s.worker_lost = true;
  d = hp.decide(s);
  EXPECT_EQ(d.mode, gf::planning::HoldMode::kSearch);
  ASSERT_EQ(d.camera_target.cols(), 10);
  EXPECT_TRUE(d.camera_target.col(0).isApprox(s.worker_world));
  EXPECT_NEAR(d.camera_target(2, 2) - 1.0, std::min(15.0, 0.5 * (12.4 - 5.0)) * 1.0, 1e-9);  // 2 s: the top
  EXPECT_TRUE(d.reference.p_world.col(0).isApprox(Eigen::Vector3d(0.5, 0, 5)));
  // The next replanning continues the same sweep (phase from 10.4 s).
  s.t_s = 11.4;
  const auto again = hp.decide(s);
  EXPECT_NEAR(again.camera_target(2, 0), d.camera_target(2, 1), 1e-12);
  // A follower in the same situation only holds.
  gf::planning::HoldPlanner follower(lim, gf::planning::SearchConfig{}, 4.0);
  auto fs = s;
  fs.uav_index = 1;
  fs.hold_reason = "worker estimate older than max_worker_age_s";
  EXPECT_EQ(follower.decide(fs).mode, gf::planning::HoldMode::kHold);
  // 60 s after the hold began the search ends: hold, camera on the estimate.
  s.t_s = 68.1;
  d = hp.decide(s);
  EXPECT_EQ(d.mode, gf::planning::HoldMode::kHold);
  EXPECT_EQ(d.camera_target.cols(), 0);
  // Fresh data: track, the latch released; the next hold latches where the UAV is then.
  s.hold_reason.clear();
  s.worker_lost = false;
  EXPECT_EQ(hp.decide(s).mode, gf::planning::HoldMode::kTrack);
  EXPECT_FALSE(hp.holdPoint());
  s.hold_reason = "worker not seen for more than max_worker_age_s";
  s.v_world.setZero();
  s.p_world = Eigen::Vector3d(3, 3, 6);
  hp.decide(s);
  ASSERT_TRUE(hp.holdPoint());
  EXPECT_TRUE(hp.holdPoint()->isApprox(Eigen::Vector3d(3, 3, 6)));
}

// The rule-2 decision gfctl simulate and the FormationPlanner nodelet share (docs/safety.md §1).
TEST(HoldReasonTest, EachAgeLimitDecidesWithItsOwnStamp) {
  const gf::planning::FreshnessLimits lim{2.0, 3.0};
  // Leader: only the estimate's age (the last fused measurement) counts.
  EXPECT_EQ(gf::planning::holdReason(0, 10.0, 10.0, 7.0, lim), "");  // exactly 3 s: still fresh
  EXPECT_EQ(gf::planning::holdReason(0, 10.0, 10.0, 6.9, lim), "worker not seen for more than max_worker_age_s");
  EXPECT_EQ(gf::planning::holdReason(0, 10.0, -100.0, 9.0, lim), "");  // the share stamp is not the leader's
  // Follower: the share's age first, then the estimate it carries.
  EXPECT_EQ(gf::planning::holdReason(1, 10.0, 8.5, 9.0, lim), "");
  EXPECT_EQ(gf::planning::holdReason(1, 10.0, 7.9, 9.0, lim), "leader share older than max_share_age_s");
  EXPECT_EQ(gf::planning::holdReason(2, 10.0, 7.9, 1.0, lim), "leader share older than max_share_age_s");
  EXPECT_EQ(gf::planning::holdReason(2, 10.0, 9.9, 6.5, lim), "worker estimate older than max_worker_age_s");
  // Stamped further in the future than the limit (ROS time went back): unusable, like an old one.
  EXPECT_EQ(gf::planning::holdReason(0, 10.0, 10.0, 500.0, lim), "worker not seen for more than max_worker_age_s");
  EXPECT_EQ(gf::planning::holdReason(1, 10.0, 500.0, 500.0, lim), "leader share older than max_share_age_s");
  // No stamp at all (NaN / inf) is infinitely old, never fresh.
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(gf::planning::holdReason(0, 10.0, 10.0, nan, lim).empty());
  EXPECT_FALSE(gf::planning::holdReason(0, 10.0, 10.0, -inf, lim).empty());
  EXPECT_FALSE(gf::planning::holdReason(1, 10.0, nan, 10.0, lim).empty());
  EXPECT_FALSE(gf::planning::holdReason(1, 10.0, 10.0, inf, lim).empty());
}


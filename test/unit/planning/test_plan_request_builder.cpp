// planning::buildPlanRequest: which received plans each UAV avoids (avoid_all_plans vs the
// priority rule, right of way of fallback and silent UAVs) and its references (leader, follower
// on the leader's plan, hold).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "gesture_formation/planning/plan_request_builder.hpp"

namespace gf = gesture_formation;

namespace {

gf::planning::PlannedTrajectory planOf(int uav, double t0_s, double heading_rad) {
  gf::planning::PlannedTrajectory p;
  p.uav_index = uav;
  p.t0_s = t0_s;
  p.dt_s = 0.2;
  for (int k = 0; k < 20; ++k) {
    gf::planning::TrajectorySample s;
    s.p_world = Eigen::Vector3d(uav * 10.0, k * 0.1, 5.0);
    s.heading_rad = heading_rad;
    s.pitch_rad = -0.1;
    p.samples.push_back(s);
  }
  return p;
}

std::vector<int> senders(const gf::planning::PlanRequest& r) {
  std::vector<int> v;
  for (const auto& p : r.higher_priority_plans) v.push_back(p.uav_index);
  return v;
}

struct RequestFixture {
  gf::formation::FormationParams params;
  gf::planning::PlannedTrajectory leader = planOf(0, 10.0, 0.7);
  std::vector<std::optional<gf::planning::ReceivedPlan>> received;
  RequestFixture() {
    received.resize(3);
    received[1] = gf::planning::ReceivedPlan{planOf(1, 9.9, 0.0), false};
    received[2] = gf::planning::ReceivedPlan{planOf(2, 9.95, 0.0), false};
  }
  gf::planning::PlanRequestInputs inputs(int uav, bool avoid_all) const {
    gf::planning::PlanRequestInputs in;
    in.uav_index = uav;
    in.t_s = 10.0;
    in.dt_s = 0.2;
    in.worker = gf::formation::constantVelocityHorizon(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0.5, 0, 0), 0.0, 10, 0.2);
    in.params = &params;
    in.leader_plan = uav == 0 ? nullptr : &leader;
    in.received = &received;
    in.rule = gf::planning::AvoidanceRule{avoid_all, 1.0};
    return in;
  }
};

}  // namespace

TEST(PlanRequestBuilderTest, AvoidAllPlansVersusThePriorityRule) {
  RequestFixture f;
  ASSERT_EQ(f.params.uavCount(), 3);
  EXPECT_EQ(senders(gf::planning::buildPlanRequest(f.inputs(1, true))), std::vector<int>({0, 2}));
  EXPECT_EQ(senders(gf::planning::buildPlanRequest(f.inputs(1, false))), std::vector<int>({0}));
  EXPECT_EQ(senders(gf::planning::buildPlanRequest(f.inputs(2, false))), std::vector<int>({0, 1}));
  EXPECT_EQ(senders(gf::planning::buildPlanRequest(f.inputs(0, true))), std::vector<int>({1, 2}));
  EXPECT_TRUE(senders(gf::planning::buildPlanRequest(f.inputs(0, false))).empty());
  // Right of way under the priority rule: a fallback plan, or a silent UAV.
  f.received[2]->fallback = true;
  EXPECT_EQ(senders(gf::planning::buildPlanRequest(f.inputs(1, false))), std::vector<int>({0, 2}));
  f.received[2]->fallback = false;
  f.received[2]->plan.t0_s = 8.5;  // 1.5 s > max_plan_age_s
  EXPECT_EQ(senders(gf::planning::buildPlanRequest(f.inputs(0, false))), std::vector<int>({2}));
}

TEST(PlanRequestBuilderTest, ReferencesAndHold) {
  const RequestFixture f;
  // Follower: eq. follower_ref on the leader's planned heading and pitch.
  const auto in = f.inputs(1, true);
  const auto req = gf::planning::buildPlanRequest(in);
  gf::formation::LeaderPlan lp;
  lp.heading_rad.resize(1, 10);
  lp.pitch_rad.resize(1, 10);
  lp.heading_rad.setConstant(0.7);
  lp.pitch_rad.setConstant(-0.1);
  gf::formation::ReferenceTrajectory expected;
  gf::formation::followerHorizon(in.worker, f.params.leader, &lp, f.params.followers[0], expected);
  ASSERT_EQ(req.reference.steps(), 10);
  EXPECT_TRUE(req.reference.p_world.isApprox(expected.p_world, 1e-12));
  EXPECT_TRUE(req.reference.heading_rad.isApprox(expected.heading_rad, 1e-12));
  EXPECT_EQ(req.uav_index, 1);
  EXPECT_DOUBLE_EQ(req.t_now_s, 10.0);
  EXPECT_DOUBLE_EQ(req.state.t_s, 10.0);
  // Without the leader's plan: the leader's desired heading (a different reference).
  auto no_plan = f.inputs(1, true);
  no_plan.leader_plan = nullptr;
  const auto req2 = gf::planning::buildPlanRequest(no_plan);
  EXPECT_FALSE(req2.reference.p_world.isApprox(expected.p_world, 1e-6));
  EXPECT_EQ(senders(req2), std::vector<int>({2}));
  // Hold: the given reference, and every received plan even under the priority rule.
  gf::formation::ReferenceTrajectory hold;
  hold.resize(10);
  hold.p_world.setConstant(3.0);
  hold.heading_rad.setZero();
  hold.pitch_rad.setZero();
  auto h = f.inputs(1, false);
  h.hold_reference = &hold;
  const auto req3 = gf::planning::buildPlanRequest(h);
  EXPECT_TRUE(req3.reference.p_world.isApprox(hold.p_world));
  EXPECT_EQ(senders(req3), std::vector<int>({0, 2}));
}

// Review finding: a leader above the worker plans its camera steeply down (to the gimbal's −80°);
// a follower with γ_i 20° then got an elevation γ_i − ξ_L of 100°: its reference over the worker's
// head, which limits.gamma_max_deg (60°) is there to prevent. With the limits the leader's planned
// pitch is clamped for the follower's reference: its elevation is 60° at most; within the limits
// nothing changes.
TEST(PlanRequestBuilderTest, AFollowersElevationOverTheLeadersPlannedPitchKeepsTheLimits) {
  RequestFixture f;
  f.params.followers[0].gamma_deg = 20.0;
  for (auto& s : f.leader.samples) s.pitch_rad = -80.0 * M_PI / 180.0;
  const gf::formation::FormationLimits limits;  // gamma -30 .. 60
  auto in = f.inputs(1, true);
  const auto unclamped = gf::planning::buildPlanRequest(in);
  in.limits = &limits;
  const auto clamped = gf::planning::buildPlanRequest(in);
  for (int k = 0; k < clamped.reference.steps(); ++k) {
    const Eigen::Vector3d worker = in.worker.p_world.col(k);
    const auto elevation = [&](const gf::planning::PlanRequest& r) {
      return gf::formation::viewGeometry(r.reference.p_world.col(k), worker).elevation_deg;
    };
    EXPECT_NEAR(elevation(unclamped), 80.0, 1e-6) << k;  // 100° folded over the head: asin gives 80
    EXPECT_NEAR(elevation(clamped), 60.0, 1e-6) << k;
    // On the leader's side of the worker, not beyond his head: the horizontal offset along the
    // leader's planned heading points away from the leader's camera.
    const Eigen::Vector2d off = (Eigen::Vector3d(clamped.reference.p_world.col(k)) - worker).head<2>();
    EXPECT_LT(off.dot(Eigen::Vector2d(std::cos(0.7 - f.params.followers[0].beta_deg * M_PI / 180.0),
                                      std::sin(0.7 - f.params.followers[0].beta_deg * M_PI / 180.0))),
              0.0)
        << k;
  }
  // Within the limits the planned pitch is used as it is.
  RequestFixture g;
  auto plain = g.inputs(1, true);
  const auto before = gf::planning::buildPlanRequest(plain);
  plain.limits = &limits;
  EXPECT_TRUE(gf::planning::buildPlanRequest(plain).reference.p_world.isApprox(before.reference.p_world, 1e-12));
}

// A hand-over (docs/safety.md §1.2): follower 1 leads — it flies the leader's slot and avoids UAV 0's
// last plan and follower 2's; follower 2 follows UAV 1's plan (leader_index 1), avoids it once (as
// the leader's plan, not again as received[1]) and avoids UAV 0's last plan; UAV 0, back as a
// follower, flies the slot UAV 1 left.
TEST(PlanRequestBuilderTest, SlotsAndTheLeadersPlanAfterAHandOver) {
  RequestFixture f;
  f.received[0] = gf::planning::ReceivedPlan{planOf(0, 9.0, 0.7), false};
  auto lead = f.inputs(1, true);
  lead.slot = 0;
  lead.leader_index = 1;
  lead.leader_plan = nullptr;
  const auto req_lead = gf::planning::buildPlanRequest(lead);
  gf::formation::ReferenceTrajectory expected_lead;
  gf::formation::leaderHorizon(lead.worker, f.params.leader, expected_lead);
  EXPECT_TRUE(req_lead.reference.p_world.isApprox(expected_lead.p_world, 1e-12));
  EXPECT_EQ(req_lead.uav_index, 1);  // its identity (priority, abort layer) is unchanged
  EXPECT_EQ(senders(req_lead), std::vector<int>({0, 2}));
  const gf::planning::PlannedTrajectory new_leader = planOf(1, 10.0, 0.4);
  auto follower = f.inputs(2, true);
  follower.leader_plan = &new_leader;
  follower.leader_index = 1;
  EXPECT_EQ(senders(gf::planning::buildPlanRequest(follower)), std::vector<int>({1, 0}));
  auto back = f.inputs(0, true);
  back.slot = 1;
  back.leader_index = 1;
  back.leader_plan = &new_leader;
  const auto req_back = gf::planning::buildPlanRequest(back);
  gf::formation::LeaderPlan lp;
  lp.heading_rad.resize(1, 10);
  lp.pitch_rad.resize(1, 10);
  lp.heading_rad.setConstant(0.4);
  lp.pitch_rad.setConstant(-0.1);
  gf::formation::ReferenceTrajectory expected_back;
  gf::formation::followerHorizon(back.worker, f.params.leader, &lp, f.params.followers[0], expected_back);
  EXPECT_TRUE(req_back.reference.p_world.isApprox(expected_back.p_world, 1e-12));
  EXPECT_EQ(senders(req_back), std::vector<int>({1, 2}));
  // Without a hand-over (leader_index 0) a received copy of the leader's plan is not avoided twice.
  EXPECT_EQ(senders(gf::planning::buildPlanRequest(f.inputs(1, true))), std::vector<int>({0, 2}));
}

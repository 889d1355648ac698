// The relay's sampling core (onboard::SetpointRelay, docs/ros.md "Flight stacks"): no plan → no
// setpoint; inside the plan the tracker's interpolation with the segment's yaw rate; past the end
// the last point held with zero velocity (docs/safety.md §1 rule 5); an older or broken plan
// refused with its reason and the held plan kept.
#include <cmath>

#include <gtest/gtest.h>

#include "gesture_formation/onboard/setpoint_relay.hpp"
#include "gesture_formation/planning/trajectory_verifier.hpp"

namespace go = gesture_formation::onboard;
namespace gp = gesture_formation::planning;

namespace {
/// A straight plan: sample k at t0 + k·0.2 s, x = k m (5 m/s), heading 0.1·k rad, pitch −0.2 rad.
gp::PlannedTrajectory straightPlan(double t0_s, int samples = 6, std::uint32_t sequence = 1) {
  gp::PlannedTrajectory p;
  p.t0_s = t0_s;
  p.dt_s = 0.2;
  p.sequence = sequence;
  for (int k = 0; k < samples; ++k) {
    gp::TrajectorySample s;
    s.p_world = Eigen::Vector3d(k, 2.0, 10.0);
    s.v_world = Eigen::Vector3d(5.0, 0.0, 0.0);
    s.heading_rad = 0.1 * k;
    s.pitch_rad = -0.2;
    p.samples.push_back(s);
  }
  return p;
}
}  // namespace

TEST(SetpointRelayTest, NoPlanNoSetpoint) {
  go::SetpointRelay relay;
  EXPECT_FALSE(relay.hasPlan());
  EXPECT_FALSE(relay.sample(100.0));
}

TEST(SetpointRelayTest, InsideThePlanInterpolatesLikeTheTracker) {
  go::SetpointRelay relay;
  ASSERT_FALSE(relay.accept(straightPlan(100.0)));
  const auto s = relay.sample(100.3);  // halfway between samples 1 and 2
  ASSERT_TRUE(s);
  EXPECT_EQ(s->mode, go::RelayMode::kTracking);
  EXPECT_NEAR(s->p_world.x(), 1.5, 1e-12);
  EXPECT_NEAR(s->v_world.x(), 5.0, 1e-12);
  EXPECT_NEAR(s->heading_rad, 0.15, 1e-12);
  EXPECT_NEAR(s->yaw_rate_radps, 0.5, 1e-12);  // 0.1 rad per 0.2 s
  EXPECT_NEAR(s->pitch_rad, -0.2, 1e-12);
  EXPECT_DOUBLE_EQ(s->past_end_s, 0.0);
}

// The setpoints lie on the curve the verifier checked (the cubic Hermite through the samples,
// here exactly the plan's x = 1.5·t² from rest at 3 m/s²); linear interpolation between the
// samples cut it by a·dt²/8 = 1.5 cm halfway between samples 1 and 2.
TEST(SetpointRelayTest, InsideThePlanSetpointsLieOnTheVerifiedCurve) {
  gp::PlannedTrajectory p = straightPlan(100.0);
  const double a = 3.0;
  for (std::size_t k = 0; k < p.samples.size(); ++k) {
    const double t = 0.2 * static_cast<double>(k);
    p.samples[k].p_world.x() = 0.5 * a * t * t;
    p.samples[k].v_world.x() = a * t;
    p.samples[k].a_world.x() = a;
  }
  go::SetpointRelay relay;
  ASSERT_FALSE(relay.accept(p));
  for (double tau : {0.05, 0.3, 0.47, 0.9}) {
    const auto s = relay.sample(100.0 + tau);
    ASSERT_TRUE(s);
    EXPECT_NEAR(s->p_world.x(), 0.5 * a * tau * tau, 1e-12) << "t0 + " << tau;
    EXPECT_NEAR(s->v_world.x(), a * tau, 1e-12) << "t0 + " << tau;
    EXPECT_NEAR((s->p_world - gp::evaluateTrajectory(p, 100.0 + tau).p).norm(), 0.0, 1e-12) << "t0 + " << tau;
  }
}

TEST(SetpointRelayTest, YawRateWrapsAcrossPi) {
  gp::PlannedTrajectory p = straightPlan(0.0, 2);
  p.samples[0].heading_rad = 3.1;
  p.samples[1].heading_rad = -3.1;  // +0.0832 rad across ±π, not −6.2
  go::SetpointRelay relay;
  ASSERT_FALSE(relay.accept(p));
  const auto s = relay.sample(0.1);
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->yaw_rate_radps, (2.0 * M_PI - 6.2) / 0.2, 1e-9);
}

TEST(SetpointRelayTest, PastTheEndHoldsTheLastPointWithZeroVelocity) {
  go::SetpointRelay relay;
  ASSERT_FALSE(relay.accept(straightPlan(100.0)));  // ends at 101.0 s
  const auto s = relay.sample(103.5);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->mode, go::RelayMode::kHoldingEnd);
  EXPECT_NEAR(s->past_end_s, 2.5, 1e-12);
  EXPECT_TRUE(s->p_world.isApprox(Eigen::Vector3d(5.0, 2.0, 10.0)));
  EXPECT_TRUE(s->v_world.isZero());
  EXPECT_DOUBLE_EQ(s->yaw_rate_radps, 0.0);
  EXPECT_NEAR(s->heading_rad, 0.5, 1e-12);  // the last sample's camera
  EXPECT_NEAR(s->pitch_rad, -0.2, 1e-12);
}

TEST(SetpointRelayTest, ASingleSamplePlanIsHeldWithZeroVelocity) {
  go::SetpointRelay relay;
  ASSERT_FALSE(relay.accept(straightPlan(10.0, 1)));
  const auto s = relay.sample(10.5);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->mode, go::RelayMode::kHoldingEnd);
  EXPECT_TRUE(s->v_world.isZero());
}

TEST(SetpointRelayTest, ANewerPlanReplacesAnOlderOneIsRefusedAndTheHeldPlanKept) {
  go::SetpointRelay relay;
  ASSERT_FALSE(relay.accept(straightPlan(100.0, 6, 1)));
  gp::PlannedTrajectory newer = straightPlan(100.4, 6, 2);
  for (auto& s : newer.samples) s.p_world.y() = -7.0;
  ASSERT_FALSE(relay.accept(newer));
  EXPECT_DOUBLE_EQ(relay.planT0(), 100.4);
  const auto late = relay.accept(straightPlan(100.2, 6, 3));  // delivered late: older t0
  ASSERT_TRUE(late);
  EXPECT_NE(late->find("not newer"), std::string::npos) << *late;
  EXPECT_DOUBLE_EQ(relay.planT0(), 100.4);
  EXPECT_NEAR(relay.sample(100.5)->p_world.y(), -7.0, 1e-12);
}

TEST(SetpointRelayTest, BrokenPlansRefusedNamingTheField) {
  go::SetpointRelay relay;
  gp::PlannedTrajectory empty = straightPlan(1.0, 0);
  EXPECT_NE(relay.accept(empty).value_or("").find("no samples"), std::string::npos);
  gp::PlannedTrajectory bad_dt = straightPlan(1.0);
  bad_dt.dt_s = 0.0;
  EXPECT_NE(relay.accept(bad_dt).value_or("").find("dt_s"), std::string::npos);
  gp::PlannedTrajectory nan_sample = straightPlan(1.0);
  nan_sample.samples[3].p_world.z() = std::nan("");
  EXPECT_NE(relay.accept(nan_sample).value_or("").find("sample 3"), std::string::npos);
  EXPECT_FALSE(relay.hasPlan());
}

TEST(SetpointRelayTest, ConfigRefusesAnOutOfRangeRateNamingIt) {
  go::RelayConfig c;
  EXPECT_TRUE(c.validate().empty());
  c.rate_hz = 0.5;
  const auto problems = c.validate();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("rate_hz: value 0.5"), std::string::npos) << problems[0];
}

TEST(SetpointRelayTest, SetpointOutputsParseAndRefuseNamingTheValue) {
  EXPECT_EQ(*go::parseSetpointOutputs("position"), go::SetpointOutputs::kPosition);
  EXPECT_EQ(*go::parseSetpointOutputs("velocity"), go::SetpointOutputs::kVelocity);
  EXPECT_EQ(*go::parseSetpointOutputs("both"), go::SetpointOutputs::kBoth);
  const auto bad = go::parseSetpointOutputs("attitude");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.reason().find("'attitude'"), std::string::npos);
}

// ROS time went back (the simulation restarted, a bag looped): the held plan was made in the old
// future; a new plan at the new time replaces it (before: refused as older until the clock caught
// up, the UAV holding the old plan's end). Without the jump an older plan is still refused.
TEST(SetpointRelayTest, AfterRosTimeWentBackANewPlanReplacesTheHeldOne) {
  go::SetpointRelay relay;
  ASSERT_FALSE(relay.accept(straightPlan(100.0), 100.05));
  EXPECT_TRUE(relay.accept(straightPlan(99.0, 6, 2), 100.1));  // older, the clock did not go back
  EXPECT_TRUE(relay.accept(straightPlan(99.5, 6, 2), 99.6));   // 0.4 s back: within kClockBackS, a late plan
  EXPECT_FALSE(relay.heldPlanAhead(99.6));
  EXPECT_TRUE(relay.heldPlanAhead(5.05));                       // what the nodelet warns about
  EXPECT_FALSE(relay.accept(straightPlan(5.0, 6, 2), 5.05));   // 95 s back
  EXPECT_FALSE(relay.heldPlanAhead(5.05));
  EXPECT_DOUBLE_EQ(relay.planT0(), 5.0);
  EXPECT_TRUE(relay.accept(straightPlan(4.8, 6, 3), 5.1));     // and from then on the usual order
  // A plan of the old timeline still queued does not swap back in.
  EXPECT_TRUE(relay.accept(straightPlan(100.4, 6, 4), 5.2));
  EXPECT_DOUBLE_EQ(relay.planT0(), 5.0);
}

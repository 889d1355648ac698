// Multirotor plant, tracking controller, wind and odometry (issue 7 step 1).
#include <gtest/gtest.h>

#include <cmath>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/sim/multirotor.hpp"
#include "gesture_formation/sim/odometry.hpp"
#include "gesture_formation/sim/random.hpp"
#include "gesture_formation/sim/tracking_controller.hpp"
#include "gesture_formation/sim/wind.hpp"

namespace gf = gesture_formation;
using gf::sim::ControllerConfig;
using gf::sim::EstimatedState;
using gf::sim::Multirotor;
using gf::sim::MultirotorParams;
using gf::sim::MultirotorState;
using gf::sim::TrackingController;

namespace {

EstimatedState perfect(const MultirotorState& s) {
  EstimatedState e;
  e.p_world = s.p_world;
  e.v_world = s.v_world;
  e.heading_rad = s.heading_rad;
  e.pitch_rad = s.pitch_rad;
  return e;
}

/// A constant plan holding `p` (heading, pitch) for 100 s.
gf::planning::PlannedTrajectory holdPlan(const Eigen::Vector3d& p, double heading = 0.0, double pitch = 0.0) {
  gf::planning::PlannedTrajectory plan;
  plan.t0_s = 0.0;
  plan.dt_s = 1.0;
  gf::planning::TrajectorySample s;
  s.p_world = p;
  s.heading_rad = heading;
  s.pitch_rad = pitch;
  plan.samples.assign(101, s);
  return plan;
}

struct Loop {
  Multirotor uav;
  TrackingController ctl;
  double t = 0.0;
  double max_tilt = 0.0;
  Loop(const MultirotorParams& p, const MultirotorState& s0, const ControllerConfig& c = {})
      : uav(p, s0), ctl(c, p) {}
  void run(double seconds, const Eigen::Vector3d& wind = Eigen::Vector3d::Zero(), double dt = 0.01) {
    const int n = static_cast<int>(std::lround(seconds / dt));
    for (int i = 0; i < n; ++i) {
      const auto cmd = ctl.update(t, dt, perfect(uav.state()));
      uav.step(dt, cmd, wind, -1000.0);
      t += dt;
      max_tilt = std::max(max_tilt, uav.tiltRad());
    }
  }
};

}  // namespace

TEST(MultirotorTest, ParamsValidateNamesEveryBadField) {
  MultirotorParams p;
  p.mass_kg = -1.0;
  p.max_tilt_deg = 95.0;
  p.max_thrust_to_weight = 0.5;
  const auto e = p.validate("uavs[0].plant.");
  ASSERT_EQ(e.size(), 3u);
  EXPECT_NE(e[0].find("uavs[0].plant.mass_kg"), std::string::npos);
  EXPECT_NE(e[0].find("-1"), std::string::npos);
  EXPECT_NE(e[1].find("max_thrust_to_weight"), std::string::npos);
  EXPECT_NE(e[2].find("max_tilt_deg"), std::string::npos);
  EXPECT_TRUE(MultirotorParams{}.validate().empty());
}

TEST(MultirotorTest, HoverThrustHoldsStill) {
  MultirotorState s0;
  s0.p_world = Eigen::Vector3d(1, 2, 10);
  Multirotor uav(MultirotorParams{}, s0);
  gf::sim::MultirotorCommand cmd;  // exactly g up
  for (int i = 0; i < 1000; ++i) uav.step(0.01, cmd, Eigen::Vector3d::Zero());
  EXPECT_LT((uav.state().p_world - s0.p_world).norm(), 1e-9);
}

TEST(MultirotorTest, ThrustLimitsKeepTiltAndMagnitude) {
  MultirotorParams p;
  Multirotor uav(p, MultirotorState{});
  for (const Eigen::Vector3d& a : {Eigen::Vector3d(100, 0, 9.8), Eigen::Vector3d(-3, 40, 1), Eigen::Vector3d(0, 0, 500),
                                   Eigen::Vector3d(5, 5, -20)}) {
    const Eigen::Vector3d l = uav.limitThrust(a);
    EXPECT_LE(std::atan2(l.head<2>().norm(), l.z()), gf::common::degToRad(p.max_tilt_deg) + 1e-12) << a.transpose();
    EXPECT_LE(l.norm(), p.max_thrust_to_weight * gf::sim::kGravityMps2 + 1e-9) << a.transpose();
    EXPECT_GE(l.z(), p.min_thrust_to_weight * gf::sim::kGravityMps2 - 1e-9) << a.transpose();
  }
}

TEST(TrackingControllerTest, HoverHoldsPosition) {
  MultirotorState s0;
  s0.p_world = Eigen::Vector3d(0, 0, 5);
  Loop loop(MultirotorParams{}, s0);
  loop.ctl.setPlan(holdPlan(s0.p_world));
  loop.run(20.0);
  EXPECT_LT((loop.uav.state().p_world - s0.p_world).norm(), 1e-3);
  EXPECT_LT(loop.uav.state().v_world.norm(), 1e-3);
}

TEST(TrackingControllerTest, StepResponseSettlesWithoutLargeOvershoot) {
  MultirotorState s0;
  s0.p_world = Eigen::Vector3d(0, 0, 5);
  Loop loop(MultirotorParams{}, s0);
  const Eigen::Vector3d goal(5, -3, 7);
  loop.ctl.setPlan(holdPlan(goal, 1.0, -0.3));
  double max_overshoot = 0.0;
  for (int k = 0; k < 100; ++k) {
    loop.run(0.1);
    // overshoot: progress beyond the goal along the step direction
    const Eigen::Vector3d dir = (goal - s0.p_world).normalized();
    max_overshoot = std::max(max_overshoot, (loop.uav.state().p_world - goal).dot(dir));
  }
  EXPECT_LT((loop.uav.state().p_world - goal).norm(), 0.05);  // settled within 10 s
  EXPECT_LT(max_overshoot, 0.15 * (goal - s0.p_world).norm());
  EXPECT_NEAR(loop.uav.state().heading_rad, 1.0, 1e-3);
  EXPECT_NEAR(loop.uav.state().pitch_rad, -0.3, 1e-3);
}

TEST(TrackingControllerTest, LargeStepRespectsTiltLimit) {
  MultirotorParams p;
  p.max_tilt_deg = 20.0;
  MultirotorState s0;
  s0.p_world = Eigen::Vector3d(0, 0, 10);
  Loop loop(p, s0);
  loop.ctl.setPlan(holdPlan(Eigen::Vector3d(40, 0, 10)));
  loop.run(3.0);
  EXPECT_GT(loop.max_tilt, gf::common::degToRad(19.0));  // the limit is reached ...
  EXPECT_LE(loop.max_tilt, gf::common::degToRad(20.0) + 1e-9);  // ... never exceeded
}

TEST(TrackingControllerTest, HeadingRateIsLimited) {
  MultirotorParams p;
  p.max_yaw_rate_dps = 45.0;
  Loop loop(p, MultirotorState{});
  loop.ctl.setPlan(holdPlan(Eigen::Vector3d::Zero(), 3.0));
  loop.run(1.0);
  EXPECT_NEAR(loop.uav.state().heading_rad, gf::common::degToRad(45.0), 0.02);  // 45°/s for 1 s
}

TEST(TrackingControllerTest, RejectsSteadyWind) {
  MultirotorState s0;
  s0.p_world = Eigen::Vector3d(0, 0, 10);
  Loop loop(MultirotorParams{}, s0);
  loop.ctl.setPlan(holdPlan(s0.p_world));
  const Eigen::Vector3d wind(8.0, -3.0, 0.0);
  loop.run(5.0, wind);
  const double early = (loop.uav.state().p_world - s0.p_world).norm();
  loop.run(30.0, wind);
  const double late = (loop.uav.state().p_world - s0.p_world).norm();
  EXPECT_GT(early, 0.02);  // the wind does push it ...
  EXPECT_LT(late, 0.02);   // ... and the integral term brings it back
}

TEST(TrackingControllerTest, BrakesToHoverWithoutPlan) {
  MultirotorState s0;
  s0.p_world = Eigen::Vector3d(0, 0, 10);
  s0.v_world = Eigen::Vector3d(4, 0, 0);
  Loop loop(MultirotorParams{}, s0);
  ASSERT_FALSE(loop.ctl.hasPlan());
  loop.run(4.0);
  const Eigen::Vector3d stop = loop.uav.state().p_world;
  EXPECT_LT(loop.uav.state().v_world.norm(), 0.1);
  // stopping distance from 4 m/s at ≤ 4 m/s² plus the attitude lag: ≥ 2 m, well under 5 m
  EXPECT_GT(stop.x(), 1.9);
  EXPECT_LT(stop.x(), 5.0);
  loop.run(10.0);
  EXPECT_LT((loop.uav.state().p_world - stop).norm(), 0.2);  // holds where it stopped
  EXPECT_NEAR(loop.uav.state().p_world.z(), 10.0, 0.2);
}

TEST(TrackingControllerTest, ClearPlanBrakes) {
  MultirotorState s0;
  s0.p_world = Eigen::Vector3d(0, 0, 10);
  Loop loop(MultirotorParams{}, s0);
  gf::planning::PlannedTrajectory plan;
  plan.dt_s = 0.1;
  for (int k = 0; k <= 200; ++k) {  // 2 m/s along x for 20 s
    gf::planning::TrajectorySample s;
    s.p_world = s0.p_world + Eigen::Vector3d(0.2 * k, 0, 0);
    s.v_world = Eigen::Vector3d(2, 0, 0);
    plan.samples.push_back(s);
  }
  loop.ctl.setPlan(plan);
  loop.run(5.0);
  EXPECT_NEAR(loop.uav.state().v_world.x(), 2.0, 0.1);
  loop.ctl.clearPlan();
  loop.ctl.setPlan(gf::planning::PlannedTrajectory{});  // an empty plan is no plan
  EXPECT_FALSE(loop.ctl.hasPlan());
  const double x_clear = loop.uav.state().p_world.x();
  loop.run(5.0);
  EXPECT_LT(loop.uav.state().v_world.norm(), 0.1);
  EXPECT_LT(loop.uav.state().p_world.x() - x_clear, 2.0);
}

TEST(WindTest, DeterministicForSeedAndStatistics) {
  gf::sim::WindConfig c;
  c.mean_mps = Eigen::Vector3d(3, 0, 0);
  c.turbulence_std_mps = 1.0;
  c.gusts_per_minute = 2.0;
  c.gust_peak_mps = 4.0;
  gf::sim::WindModel a(c, gf::sim::makeRng(7, gf::sim::Stream::kWind));
  gf::sim::WindModel b(c, gf::sim::makeRng(7, gf::sim::Stream::kWind));
  gf::sim::WindModel other(c, gf::sim::makeRng(8, gf::sim::Stream::kWind));
  double sum_x = 0.0, max_speed = 0.0;
  bool differs = false;
  const int n = 60000;
  for (int i = 0; i < n; ++i) {
    const double t = 0.01 * i;
    const Eigen::Vector3d wa = a.step(t, 0.01);
    const Eigen::Vector3d wb = b.step(t, 0.01);
    ASSERT_EQ(wa, wb);
    differs = differs || (other.step(t, 0.01) - wa).norm() > 1e-6;
    sum_x += wa.x();
    max_speed = std::max(max_speed, wa.head<2>().norm());
  }
  EXPECT_TRUE(differs);
  EXPECT_NEAR(sum_x / n, 3.0, 0.8);  // mean wind (turbulence and gusts average out roughly)
  EXPECT_GT(max_speed, 5.0);         // gusts happen
}

TEST(OdometryTest, NoiseMatchesConfigAndIsDeterministic) {
  gf::sim::OdometryConfig c;
  c.position_noise_m = 0.1;
  c.bias_std_m = 0.0;
  gf::sim::Odometry a(c, gf::sim::makeRng(3, gf::sim::Stream::kOdometry));
  gf::sim::Odometry b(c, gf::sim::makeRng(3, gf::sim::Stream::kOdometry));
  MultirotorState s;
  s.p_world = Eigen::Vector3d(1, 2, 3);
  double sq = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const auto ea = a.measure(s, 0.01);
    const auto eb = b.measure(s, 0.01);
    ASSERT_EQ(ea.p_world, eb.p_world);
    sq += (ea.p_world - s.p_world).squaredNorm();
  }
  EXPECT_NEAR(std::sqrt(sq / (3.0 * n)), 0.1, 0.005);
}

TEST(PlantDeterminismTest, SameInputsSameTrajectory) {
  auto run = [](std::uint64_t seed) {
    gf::sim::WindConfig wc;
    wc.turbulence_std_mps = 1.5;
    gf::sim::WindModel wind(wc, gf::sim::makeRng(seed, gf::sim::Stream::kWind));
    gf::sim::Odometry odo(gf::sim::OdometryConfig{}, gf::sim::makeRng(seed, gf::sim::Stream::kOdometry));
    MultirotorState s0;
    s0.p_world = Eigen::Vector3d(0, 0, 5);
    Multirotor uav(MultirotorParams{}, s0);
    TrackingController ctl(ControllerConfig{}, MultirotorParams{});
    ctl.setPlan(holdPlan(Eigen::Vector3d(3, 3, 6)));
    for (int i = 0; i < 1000; ++i) {
      const double t = 0.01 * i;
      const auto w = wind.step(t, 0.01);
      uav.step(0.01, ctl.update(t, 0.01, odo.measure(uav.state(), 0.01)), w);
    }
    return uav.state().p_world;
  };
  EXPECT_EQ(run(11), run(11));
  EXPECT_NE(run(11), run(12));
}

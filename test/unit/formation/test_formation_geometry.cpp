#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <Eigen/Geometry>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"

using namespace gesture_formation::formation;
using gesture_formation::common::degToRad;
using gesture_formation::common::kPi;
using gesture_formation::common::wrapAngle;

namespace {

/// Azimuth and elevation of the unit vector from `p_uav` to `p_human`.
void lineOfSight(const Eigen::Vector3d& p_uav, const Eigen::Vector3d& p_human, double& azimuth, double& elevation) {
  const Eigen::Vector3d u = (p_human - p_uav).normalized();
  azimuth = std::atan2(u.y(), u.x());
  elevation = std::asin(u.z());
}

double angleDiff(double a, double b) { return std::remainder(a - b, 2.0 * kPi); }

}  // namespace

TEST(FormationGeometryTest, LeaderAtBetaZeroGammaZero) {
  const Eigen::Vector3d p_h(1.0, -2.0, 3.0);
  const double phi_h = 0.7;
  const UavReference r = leaderReference(p_h, phi_h, UavObservation{0.0, 0.0, 10.0});
  const Eigen::Vector3d expected = p_h - 10.0 * Eigen::Vector3d(std::cos(phi_h), std::sin(phi_h), 0.0);
  EXPECT_NEAR((r.p_world - expected).norm(), 0.0, 1e-12);
  EXPECT_NEAR(r.heading_rad, phi_h, 1e-15);
  EXPECT_EQ(r.pitch_rad, 0.0);
}

TEST(FormationGeometryTest, LeaderTableIIHandComputed) {
  // φH = 0, β = 90°, γ = 11°, d = 10: p_L − p_H = −d[cos(−90°) cos γ, sin(−90°) cos γ, −sin γ] = [0, d cos γ, d sin γ].
  const Eigen::Vector3d p_h(5.0, 6.0, 20.0);
  const UavReference r = leaderReference(p_h, 0.0, FormationParams().leader);
  const double g = degToRad(11.0);
  EXPECT_NEAR(r.p_world.x(), 5.0, 1e-12);
  EXPECT_NEAR(r.p_world.y(), 6.0 + 10.0 * std::cos(g), 1e-12);
  EXPECT_NEAR(r.p_world.z(), 20.0 + 10.0 * std::sin(g), 1e-12);
  EXPECT_NEAR(r.heading_rad, -kPi / 2, 1e-15);
  EXPECT_NEAR(r.pitch_rad, -g, 1e-15);
}

TEST(FormationGeometryTest, FollowerTableIIHandComputed) {
  // φL = −90°, ξL = −11°; follower 1: β 60°, γ 0, d 8 → az = −150°, cos(γ − ξL) = cos 11°.
  const double g = degToRad(11.0);
  const UavReference r = followerReference(Eigen::Vector3d::Zero(), -kPi / 2, -g, UavObservation{60.0, 0.0, 8.0});
  EXPECT_NEAR(r.p_world.x(), 8.0 * std::cos(kPi / 6) * std::cos(g), 1e-12);
  EXPECT_NEAR(r.p_world.y(), 4.0 * std::cos(g), 1e-12);
  EXPECT_NEAR(r.p_world.z(), 8.0 * std::sin(g), 1e-12);
  EXPECT_NEAR(r.heading_rad, -5.0 * kPi / 6, 1e-15);
  EXPECT_NEAR(r.pitch_rad, -g, 1e-15);
}

TEST(FormationGeometryTest, HeadingWrappedToHalfOpenInterval) {
  // φH − β = −180° must come out as +π.
  const UavReference r = leaderReference(Eigen::Vector3d::Zero(), 0.0, UavObservation{180.0, 0.0, 5.0});
  EXPECT_DOUBLE_EQ(r.heading_rad, kPi);
  const UavReference f = followerReference(Eigen::Vector3d::Zero(), 3.0, 0.0, UavObservation{-1.0, 0.0, 5.0});
  EXPECT_GT(f.heading_rad, -kPi);
  EXPECT_LE(f.heading_rad, kPi);
  EXPECT_NEAR(f.heading_rad, wrapAngle(3.0 + degToRad(1.0)), 1e-15);
}

// Property sweep: every UAV sits at its d from the worker and its camera points at the worker;
// followers' angles are relative to the leader's.
TEST(FormationGeometryTest, PropertiesOverRandomParameters) {
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> pos(-50.0, 50.0), heading(-20.0, 20.0), beta(-179.9, 180.0),
      gamma(-40.0, 40.0), dist(3.0, 30.0);
  for (int trial = 0; trial < 2000; ++trial) {
    const Eigen::Vector3d p_h(pos(rng), pos(rng), pos(rng));
    const double phi_h = heading(rng);
    const UavObservation leader{beta(rng), gamma(rng), dist(rng)};
    const UavObservation follower{beta(rng), gamma(rng) * 0.5, dist(rng)};
    const UavReference l = leaderReference(p_h, phi_h, leader);
    const UavReference f = followerReference(p_h, l.heading_rad, l.pitch_rad, follower);
    for (const auto& [r, d] : {std::pair{l, leader.distance_m}, std::pair{f, follower.distance_m}}) {
      EXPECT_NEAR((r.p_world - p_h).norm(), d, 1e-9);
      double az = 0.0, el = 0.0;
      lineOfSight(r.p_world, p_h, az, el);
      EXPECT_NEAR(angleDiff(az, r.heading_rad), 0.0, 1e-9);
      EXPECT_NEAR(el, r.pitch_rad, 1e-9);
      EXPECT_GT(r.heading_rad, -kPi);
      EXPECT_LE(r.heading_rad, kPi);
    }
    EXPECT_NEAR(angleDiff(l.heading_rad, phi_h - degToRad(leader.beta_deg)), 0.0, 1e-12);
    EXPECT_NEAR(l.pitch_rad, -degToRad(leader.gamma_deg), 1e-15);
    EXPECT_NEAR(angleDiff(f.heading_rad, l.heading_rad - degToRad(follower.beta_deg)), 0.0, 1e-12);
    EXPECT_NEAR(f.pitch_rad, l.pitch_rad - degToRad(follower.gamma_deg), 1e-15);
    // Height above the worker: the follower's elevation is γ_L + γ_i (formation_params.hpp).
    FormationParams params;
    params.leader = leader;
    params.followers = {follower};
    EXPECT_NEAR(f.p_world.z() - p_h.z(), follower.distance_m * std::sin(degToRad(elevationDeg(params, 1))), 1e-9);
  }
}

TEST(FormationGeometryTest, RotatingTheWorkerHeadingRotatesTheWholeFormation) {
  const FormationParams params;
  const Eigen::Vector3d p_h(1.0, 2.0, 3.0);
  const UavReference l0 = leaderReference(p_h, 0.0, params.leader);
  const UavReference l1 = leaderReference(p_h, 0.4, params.leader);
  const UavReference f0 = followerReference(p_h, l0.heading_rad, l0.pitch_rad, params.followers[0]);
  const UavReference f1 = followerReference(p_h, l1.heading_rad, l1.pitch_rad, params.followers[0]);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  EXPECT_NEAR((R * (l0.p_world - p_h) - (l1.p_world - p_h)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((R * (f0.p_world - p_h) - (f1.p_world - p_h)).norm(), 0.0, 1e-12);
  // The mutual distance does not depend on the worker's heading.
  EXPECT_NEAR((l0.p_world - f0.p_world).norm(), (l1.p_world - f1.p_world).norm(), 1e-12);
}

TEST(FormationGeometryTest, HorizonMatchesSingleStepWithoutPlan) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  WorkerHorizon w;
  w.p_world.resize(3, 40);
  w.heading_rad.resize(1, 40);
  for (int k = 0; k < 40; ++k) {
    w.p_world.col(k) = Eigen::Vector3d(0.2 * k, n(rng), 10.0 + 0.1 * n(rng));
    w.heading_rad(k) = 3.0 * n(rng);
  }
  FormationParams params;
  params.followers.push_back(UavObservation{180.0, 5.0, 12.0});
  std::vector<ReferenceTrajectory> out;
  formationHorizon(w, params, nullptr, out);
  ASSERT_EQ(out.size(), 4u);
  for (int k = 0; k < 40; ++k) {
    const UavReference l = leaderReference(w.p_world.col(k), w.heading_rad(k), params.leader);
    EXPECT_NEAR((out[0].at(k).p_world - l.p_world).norm(), 0.0, 1e-12);
    EXPECT_EQ(out[0].heading_rad(k), l.heading_rad);
    for (std::size_t i = 0; i < params.followers.size(); ++i) {
      const UavReference f = followerReference(w.p_world.col(k), l.heading_rad, l.pitch_rad, params.followers[i]);
      EXPECT_NEAR((out[i + 1].p_world.col(k) - f.p_world).norm(), 0.0, 1e-12);
      EXPECT_NEAR(out[i + 1].heading_rad(k), f.heading_rad, 1e-12);
      EXPECT_NEAR(out[i + 1].pitch_rad(k), f.pitch_rad, 1e-15);
    }
  }
}

TEST(FormationGeometryTest, FollowerHorizonUsesLeaderPlan) {
  WorkerHorizon w;
  w.p_world = HorizonPoints::Zero(3, 5);
  w.heading_rad = HorizonScalars::Zero(1, 5);
  LeaderPlan plan;
  plan.heading_rad.resize(1, 5);
  plan.pitch_rad.resize(1, 5);
  for (int k = 0; k < 5; ++k) {
    plan.heading_rad(k) = 0.1 * k;
    plan.pitch_rad(k) = -0.05 * k;
  }
  const FormationParams params;
  ReferenceTrajectory with_plan, without_plan;
  followerHorizon(w, params.leader, &plan, params.followers[1], with_plan);
  followerHorizon(w, params.leader, nullptr, params.followers[1], without_plan);
  for (int k = 0; k < 5; ++k) {
    const UavReference f = followerReference(w.p_world.col(k), plan.heading_rad(k), plan.pitch_rad(k), params.followers[1]);
    EXPECT_NEAR((with_plan.p_world.col(k) - f.p_world).norm(), 0.0, 1e-12);
    EXPECT_NEAR(with_plan.pitch_rad(k), -0.05 * k - degToRad(params.followers[1].gamma_deg), 1e-15);
    EXPECT_NEAR(without_plan.pitch_rad(k), -degToRad(11.0), 1e-15);
  }
}

TEST(FormationGeometryTest, ZeroFollowers) {
  WorkerHorizon w;
  w.p_world = HorizonPoints::Zero(3, 3);
  w.heading_rad = HorizonScalars::Zero(1, 3);
  FormationParams params;
  params.followers.clear();
  std::vector<ReferenceTrajectory> out;
  formationHorizon(w, params, nullptr, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].steps(), 3);
}

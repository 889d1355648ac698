#include "gesture_formation/formation/formation_geometry.hpp"

#include <algorithm>
#include <cmath>

#include "gesture_formation/common/angles.hpp"

namespace gesture_formation::formation {

using common::degToRad;
using common::wrapAngle;

namespace {

/// Eq. leader_ref with the angles already in radians; writes position, heading, pitch.
inline void leaderRef(const Eigen::Vector3d& p_h, double phi_h, double beta, double gamma, double d,
                      Eigen::Ref<Eigen::Vector3d> p, double& heading, double& pitch) {
  const double az = phi_h - beta;
  const double c = std::cos(gamma);
  p.x() = p_h.x() - d * std::cos(az) * c;
  p.y() = p_h.y() - d * std::sin(az) * c;
  p.z() = p_h.z() + d * std::sin(gamma);
  heading = wrapAngle(az);
  pitch = -gamma;
}

/// Eq. follower_ref with the angles already in radians.
inline void followerRef(const Eigen::Vector3d& p_h, double phi_l, double xi_l, double beta, double gamma, double d,
                        Eigen::Ref<Eigen::Vector3d> p, double& heading, double& pitch) {
  const double az = phi_l - beta;
  const double c = std::cos(gamma - xi_l);
  p.x() = p_h.x() - d * std::cos(az) * c;
  p.y() = p_h.y() - d * std::sin(az) * c;
  p.z() = p_h.z() - d * std::sin(xi_l - gamma);
  heading = wrapAngle(az);
  pitch = xi_l - gamma;
}

}  // namespace

UavReference leaderReference(const Eigen::Vector3d& p_human_world, double human_heading_rad,
                             const UavObservation& leader) {
  UavReference r;
  leaderRef(p_human_world, human_heading_rad, degToRad(leader.beta_deg), degToRad(leader.gamma_deg), leader.distance_m,
            r.p_world, r.heading_rad, r.pitch_rad);
  return r;
}

UavReference followerReference(const Eigen::Vector3d& p_human_world, double leader_heading_rad,
                               double leader_pitch_rad, const UavObservation& follower) {
  UavReference r;
  followerRef(p_human_world, leader_heading_rad, leader_pitch_rad, degToRad(follower.beta_deg),
              degToRad(follower.gamma_deg), follower.distance_m, r.p_world, r.heading_rad, r.pitch_rad);
  return r;
}

WorkerHorizon constantVelocityHorizon(const Eigen::Vector3d& p0_world, const Eigen::Vector3d& v_world,
                                      double heading_rad, int steps, double dt_s) {
  WorkerHorizon wh;
  wh.p_world.resize(3, steps);
  wh.heading_rad.resize(1, steps);
  for (int k = 0; k < steps; ++k) {
    wh.p_world.col(k) = p0_world + (k * dt_s) * v_world;
    wh.heading_rad(k) = heading_rad;
  }
  return wh;
}

void leaderHorizon(const WorkerHorizon& worker, const UavObservation& leader, ReferenceTrajectory& out) {
  const int n = worker.steps();
  out.resize(n);
  const double beta = degToRad(leader.beta_deg);
  const double gamma = degToRad(leader.gamma_deg);
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector3d p_h = worker.p_world.col(k);
    leaderRef(p_h, worker.heading_rad(k), beta, gamma, leader.distance_m, out.p_world.col(k), out.heading_rad(k),
              out.pitch_rad(k));
  }
}

void followerHorizon(const WorkerHorizon& worker, const UavObservation& leader, const LeaderPlan* plan,
                     const UavObservation& follower, ReferenceTrajectory& out) {
  const int n = worker.steps();
  out.resize(n);
  const double leader_beta = degToRad(leader.beta_deg);
  const double leader_pitch = -degToRad(leader.gamma_deg);
  const double beta = degToRad(follower.beta_deg);
  const double gamma = degToRad(follower.gamma_deg);
  for (int k = 0; k < n; ++k) {
    const double phi_l = plan ? plan->heading_rad(k) : wrapAngle(worker.heading_rad(k) - leader_beta);
    const double xi_l = plan ? plan->pitch_rad(k) : leader_pitch;
    const Eigen::Vector3d p_h = worker.p_world.col(k);
    followerRef(p_h, phi_l, xi_l, beta, gamma, follower.distance_m, out.p_world.col(k), out.heading_rad(k),
                out.pitch_rad(k));
  }
}

void formationHorizon(const WorkerHorizon& worker, const FormationParams& params, const LeaderPlan* plan,
                      std::vector<ReferenceTrajectory>& out) {
  out.resize(static_cast<std::size_t>(params.uavCount()));
  leaderHorizon(worker, params.leader, out[0]);
  for (std::size_t i = 0; i < params.followers.size(); ++i) {
    followerHorizon(worker, params.leader, plan, params.followers[i], out[i + 1]);
  }
}

ViewGeometry viewGeometry(const Eigen::Vector3d& camera_world, const Eigen::Vector3d& worker_world) {
  const Eigen::Vector3d rel = camera_world - worker_world;
  ViewGeometry g;
  g.distance_m = rel.norm();
  g.elevation_deg = g.distance_m > 1e-9 ? common::radToDeg(std::asin(std::clamp(rel.z() / g.distance_m, -1.0, 1.0)))
                                        : (std::isfinite(g.distance_m) ? 0.0 : g.distance_m);
  return g;
}

}  // namespace gesture_formation::formation

#pragma once
// Message ↔ simulator-core conversions: used by the simulation nodelets only (SimUav, SimWorld);
// the nodelets that fly never include the simulator (docs/architecture.md).
#include <cmath>
#include <string>

#include <nav_msgs/Odometry.h>

#include "conversions.hpp"
#include "gesture_formation/WorkerBody.h"
#include "gesture_formation/common/result.hpp"
#include "gesture_formation/gesture/skeleton_synth.hpp"
#include "gesture_formation/sim/multirotor.hpp"

namespace gesture_formation::nodelets {

/// A true state (ground truth odometry) as the sim core's plant state: position, velocity,
/// camera heading and pitch.
inline sim::MultirotorState toMultirotorState(const nav_msgs::Odometry& odom) {
  const planning::UavKinematicState k = toKinematicState(odom);
  sim::MultirotorState s;
  s.p_world = k.p_world;
  s.v_world = k.v_world;
  s.heading_rad = k.heading_rad;
  s.pitch_rad = k.pitch_rad;
  return s;
}

/// The worker's posed body (WorkerModel::bodyAt) with its feet and heading (sim::WorkerState).
inline gesture_formation::WorkerBody toWorkerBodyMsg(const gesture::Body3D& body, const Eigen::Vector3d& feet_world,
                                                     double heading_rad) {
  gesture_formation::WorkerBody m;
  for (const Eigen::Vector3d& p : body.p) m.keypoints_body.push_back(toPoint(p));
  m.head_top_body = toPoint(body.head_top);
  m.feet_world = toPoint(feet_world);
  m.heading_rad = heading_rad;
  return m;
}

/// The body of a WorkerBody message; fails naming the field when it does not hold 17 finite keypoints.
inline common::Result<gesture::Body3D> fromWorkerBodyMsg(const gesture_formation::WorkerBody& m) {
  using R = common::Result<gesture::Body3D>;
  if (m.keypoints_body.size() != static_cast<std::size_t>(gesture::kNumKeypoints)) {
    return R::fail("WorkerBody.keypoints_body: " + std::to_string(m.keypoints_body.size()) + " points, want " +
                   std::to_string(gesture::kNumKeypoints));
  }
  gesture::Body3D b;
  for (std::size_t k = 0; k < b.p.size(); ++k) b.p[k] = toEigen(m.keypoints_body[k]);
  b.head_top = toEigen(m.head_top_body);
  bool finite = b.head_top.allFinite() && toEigen(m.feet_world).allFinite() && std::isfinite(m.heading_rad);
  for (const Eigen::Vector3d& p : b.p) finite = finite && p.allFinite();
  if (!finite) return R::fail("WorkerBody: a coordinate or heading_rad is not finite");
  return R::ok(b);
}

}  // namespace gesture_formation::nodelets

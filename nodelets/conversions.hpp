#pragma once
// All message <-> core conversions of the nodelets (house style: one header, no math).
#include <cmath>

#include <geometry_msgs/TransformStamped.h>

#include "gesture_formation/WorkerDetection.h"
#include "gesture_formation/WorkerState.h"
#include "gesture_formation/estimation/human_kalman.hpp"
#include "gesture_formation/estimation/measurement_model.hpp"

namespace gesture_formation::nodelets {

inline estimation::Box toBox(const gesture_formation::WorkerDetection& d) {
  return estimation::Box{d.u, d.v, d.w, d.h};
}

inline estimation::CameraPose toCameraPose(const geometry_msgs::TransformStamped& T_world_camera) {
  estimation::CameraPose pose;
  const auto& t = T_world_camera.transform.translation;
  const auto& q = T_world_camera.transform.rotation;
  pose.t_world_camera = Eigen::Vector3d(t.x, t.y, t.z);
  pose.q_world_camera = Eigen::Quaterniond(q.w, q.x, q.y, q.z);
  return pose;
}

inline gesture_formation::WorkerState toWorkerState(const estimation::Vector6d& x, const estimation::Matrix6d& P) {
  gesture_formation::WorkerState s;
  s.position.x = x(0);
  s.position.y = x(1);
  s.position.z = x(2);
  s.velocity.x = x(3);
  s.velocity.y = x(4);
  s.velocity.z = x(5);
  for (int r = 0; r < 6; ++r) {
    for (int c = 0; c < 6; ++c) s.covariance[static_cast<std::size_t>(6 * r + c)] = P(r, c);
  }
  return s;
}

}  // namespace gesture_formation::nodelets

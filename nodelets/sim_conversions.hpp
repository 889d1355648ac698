#pragma once
// Message ↔ simulator-core conversions: used by the simulation nodelets only (SimUav, SimWorld);
// the nodelets that fly never include the simulator (docs/architecture.md).
#include <cmath>
#include <string>

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <sensor_msgs/Range.h>

#include "conversions.hpp"
#include "gesture_formation/Gesture.h"
#include "gesture_formation/WorkerBody.h"
#include "gesture_formation/WorkerDetection.h"
#include "gesture_formation/common/result.hpp"
#include "gesture_formation/gesture/skeleton_synth.hpp"
#include "gesture_formation/sim/leader_camera.hpp"
#include "gesture_formation/sim/multirotor.hpp"
#include "gesture_formation/sim/worker_model.hpp"
#include "gesture_formation/sim/world_record.hpp"

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
                                                     double heading_rad, const ros::Time& stamp,
                                                     const std::string& world_frame) {
  gesture_formation::WorkerBody m;
  m.header.stamp = stamp;
  m.header.frame_id = world_frame;
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

/// A planner's plan for the world's record (its `status` parsed by the caller).
inline sim::PlanReport toPlanReport(int uav, const gesture_formation::PlannedTrajectory& m, planning::PlanStatus status) {
  sim::PlanReport r;
  r.uav = uav;
  r.planned_at_s = m.planned_at.toSec();
  r.params_version = m.params_version;
  if (!m.formation.empty()) {
    if (auto used = fromMsg(m.formation)) r.formation = std::move(*used);
  }
  r.status = status;
  r.planning_ms = m.planning_ms;
  r.reason = m.reason;
  r.mode = m.mode;
  r.mode_reason = m.mode_reason;
  return r;
}
/// The leader's published parameters for the world's record.
/// One UAV's abort state as the world's record takes it (phase nullopt: PHASE_NONE or unknown).
inline sim::AbortReport toAbortReport(int uav, const gesture_formation::AbortState& m) {
  sim::AbortReport r;
  r.uav = uav;
  r.t_s = m.header.stamp.toSec();
  r.accepted_s = m.accepted_at.toSec();
  r.source = m.command.source == gesture_formation::AbortCommand::SOURCE_GESTURE ? planning::AbortSource::kGesture
                                                                                : planning::AbortSource::kOperator;
  using P = planning::AbortPhase;
  for (P p : {P::kRetreat, P::kAtRetreat, P::kReturnHome, P::kAtHome, P::kLanding, P::kLanded, P::kNoGoal}) {
    if (toMsgPhase(p) == m.phase) r.phase = p;
  }
  return r;
}

inline sim::ParamsReport toParamsReport(const gesture_formation::FormationParams& m) {
  sim::ParamsReport r;
  if (auto p = fromMsg(m)) r.params = std::move(*p);
  r.version = m.version;
  r.stamp_s = m.header.stamp.toSec();
  r.last_command = m.last_command;
  r.last_status = m.last_command_status;
  r.last_source = m.last_command_source;
  r.last_command_stamp_s = m.last_command_stamp.toSec();
  r.last_uavs.assign(m.last_command_uavs.begin(), m.last_command_uavs.end());
  return r;
}

/// UAV `uav`'s classification as its Perception nodelet would publish it. With the 3-D confirmation
/// (`skeleton` and the UAV's `truth` given) the skeleton goes along in the frame of the generator's
/// camera that rendered it, uav<i>/gesture_camera, and `camera` (to send on tf) places that frame
/// relative to the UAV's true camera axis: the pose the ViewObserver looks up through the
/// estimated axis (SimUav) is the rendering pose moved by the odometry's error, as in gfctl
/// simulate. Without them `camera`'s child_frame_id stays empty.
inline gesture_formation::Gesture toGestureMsg(int uav, const gesture::Classification& c, const ros::Time& stamp,
                                               const gesture::CalibratedSkeleton* skeleton,
                                               const sim::MultirotorState* truth, geometry_msgs::TransformStamped* camera) {
  const std::string prefix = "uav" + std::to_string(uav);
  gesture_formation::Gesture g;
  g.header.stamp = stamp;
  g.header.frame_id = prefix + "/camera_optical";
  g.gesture_id = c.gesture_id;
  g.probabilities.assign(c.probabilities.begin(), c.probabilities.end());
  if (skeleton == nullptr || truth == nullptr) return g;
  g.header.frame_id = prefix + "/gesture_camera";
  g.keypoints = toKeypoints(skeleton->skeleton);
  g.camera = toCameraInfo(skeleton->intrinsics);
  const geometry_msgs::Quaternion axis = cameraAxisOrientation(truth->heading_rad, truth->pitch_rad);
  const Eigen::Quaterniond q_axis_inv = Eigen::Quaterniond(axis.w, axis.x, axis.y, axis.z).conjugate();
  camera->header.stamp = stamp;
  camera->header.frame_id = prefix + "/camera_axis";
  camera->child_frame_id = g.header.frame_id;
  camera->transform = toTransform(toPose(q_axis_inv * Eigen::Quaterniond(skeleton->R_world_camera),
                                         q_axis_inv * (skeleton->p_world_camera - truth->p_world)));
  return g;
}
/// The worker's box and stereo distance as the leader's Perception would publish them.
inline gesture_formation::WorkerDetection toDetectionMsg(const sim::SensorFrame& sensors, const ros::Time& stamp,
                                                        const std::string& camera_frame) {
  gesture_formation::WorkerDetection d;
  d.header.stamp = stamp;
  d.header.frame_id = camera_frame;
  d.detected = true;
  d.u = sensors.box.u;
  d.v = sensors.box.v;
  d.w = sensors.box.w;
  d.h = sensors.box.h;
  d.confidence = 0.9f;
  d.stereo_distance_m = sensors.d_stereo_m;
  return d;
}
/// A UWB distance (sensor_msgs/Range has no UWB constant: INFRARED, documented in docs/ros.md).
inline sensor_msgs::Range toUwbRange(double d_m, double max_range_m, const ros::Time& stamp, const std::string& frame) {
  sensor_msgs::Range r;
  r.header.stamp = stamp;
  r.header.frame_id = frame;
  r.radiation_type = sensor_msgs::Range::INFRARED;
  r.min_range = 0.0f;
  r.max_range = static_cast<float>(max_range_m);
  r.range = static_cast<float>(d_m);
  return r;
}
/// The worker's truth as odometry (orientation: its heading).
inline nav_msgs::Odometry toWorkerTruthMsg(const sim::WorkerState& ws, const ros::Time& stamp, const std::string& world_frame) {
  nav_msgs::Odometry w;
  w.header.stamp = stamp;
  w.header.frame_id = world_frame;
  w.child_frame_id = world_frame;
  w.pose.pose.position = toPoint(ws.p_world);
  w.pose.pose.orientation = cameraAxisOrientation(ws.heading_rad, 0.0);
  w.twist.twist.linear = toVector3(ws.v_world);
  return w;
}

}  // namespace gesture_formation::nodelets

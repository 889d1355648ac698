#pragma once
// All message <-> core conversions of the nodelets (house style: one header, no math).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

#include <Eigen/Geometry>
#include <geometry_msgs/TransformStamped.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <nav_msgs/Odometry.h>
#include <trajectory_msgs/MultiDOFJointTrajectory.h>

#include "gesture_formation/AbortCommand.h"
#include "gesture_formation/AssistanceState.h"
#include "gesture_formation/CommandAck.h"
#include "gesture_formation/AbortState.h"
#include "gesture_formation/FormationCommand.h"
#include "gesture_formation/FormationParams.h"
#include "gesture_formation/GestureObservation.h"
#include "gesture_formation/PlannedTrajectory.h"
#include "gesture_formation/WorkerDetection.h"
#include "gesture_formation/WorkerState.h"
#include "gesture_formation/comm/payloads.hpp"
#include "gesture_formation/common/result.hpp"
#include "gesture_formation/estimation/camera_model.hpp"
#include "gesture_formation/estimation/human_kalman.hpp"
#include "gesture_formation/estimation/measurement_model.hpp"
#include "gesture_formation/formation/formation_commands.hpp"
#include "gesture_formation/formation/formation_params.hpp"
#include "gesture_formation/gesture/view_fusion.hpp"
#include "gesture_formation/onboard/formation_params_role.hpp"
#include "gesture_formation/planning/polytope_edges.hpp"
#include "gesture_formation/planning/replan_step.hpp"
#include "gesture_formation/planning/uav_planner.hpp"

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


// ---- points and vectors ----------------------------------------------------------------
/// Any message with x, y, z fields (Point, Vector3) from an Eigen vector.
template <typename XyzMsg>
XyzMsg toXyzMsg(const Eigen::Vector3d& v) {
  XyzMsg m;
  m.x = v.x();
  m.y = v.y();
  m.z = v.z();
  return m;
}
inline geometry_msgs::Point toPoint(const Eigen::Vector3d& p) { return toXyzMsg<geometry_msgs::Point>(p); }
inline geometry_msgs::Vector3 toVector3(const Eigen::Vector3d& v) { return toXyzMsg<geometry_msgs::Vector3>(v); }
inline Eigen::Vector3d toEigen(const geometry_msgs::Point& p) { return Eigen::Vector3d(p.x, p.y, p.z); }
inline Eigen::Vector3d toEigen(const geometry_msgs::Vector3& v) { return Eigen::Vector3d(v.x, v.y, v.z); }

// ---- odometry: pose orientation = the camera's forward axis (docs/ros.md) ---------------
// The orientation of nav_msgs/Odometry published for a UAV is the FLU body whose x axis is the
// camera's optical axis: yaw = camera heading φ, pitch about body y = −ξ (ξ positive up), no roll.
inline geometry_msgs::Quaternion cameraAxisOrientation(double heading_rad, double pitch_rad) {
  const Eigen::Quaterniond q = Eigen::AngleAxisd(heading_rad, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(-pitch_rad, Eigen::Vector3d::UnitY());
  geometry_msgs::Quaternion m;
  m.w = q.w();
  m.x = q.x();
  m.y = q.y();
  m.z = q.z();
  return m;
}
inline void cameraHeadingPitch(const geometry_msgs::Quaternion& q, double& heading_rad, double& pitch_rad) {
  const Eigen::Vector3d x_axis = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized() * Eigen::Vector3d::UnitX();
  heading_rad = std::atan2(x_axis.y(), x_axis.x());
  pitch_rad = std::asin(std::max(-1.0, std::min(1.0, x_axis.z())));
}
inline planning::UavKinematicState toKinematicState(const nav_msgs::Odometry& odom) {
  planning::UavKinematicState s;
  s.t_s = odom.header.stamp.toSec();
  s.p_world = toEigen(odom.pose.pose.position);
  s.v_world = toEigen(odom.twist.twist.linear);  // world frame (child_frame_id = world_frame)
  cameraHeadingPitch(odom.pose.pose.orientation, s.heading_rad, s.pitch_rad);
  return s;
}

// ---- planned trajectories --------------------------------------------------------------
inline gesture_formation::PlannedTrajectory toMsg(const planning::PlannedTrajectory& plan) {
  gesture_formation::PlannedTrajectory m;
  m.header.stamp = ros::Time(plan.t0_s);
  m.uav_index = plan.uav_index;
  m.sequence = plan.sequence;
  m.dt_s = plan.dt_s;
  for (const auto& s : plan.samples) {
    m.positions.push_back(toPoint(s.p_world));
    m.velocities.push_back(toVector3(s.v_world));
    m.accelerations.push_back(toVector3(s.a_world));
    m.heading_rad.push_back(s.heading_rad);
    m.pitch_rad.push_back(s.pitch_rad);
  }
  m.status = "optimized";
  return m;
}
inline gesture_formation::PlannedTrajectory toMsg(const planning::PlanResult& r) {
  gesture_formation::PlannedTrajectory m = toMsg(r.trajectory);
  m.status = planning::toString(r.status);
  m.fallback = r.status != planning::PlanStatus::kOptimized;
  m.reason = r.reason;
  m.planning_ms = r.timings.total_ms;
  for (const auto& p : r.path_world) m.path.push_back(toPoint(p));
  for (const auto& c : r.corridors) {
    for (const auto& [a, b] : planning::polytopeEdges(c.polytope)) {
      m.corridor_edges.push_back(toPoint(a));
      m.corridor_edges.push_back(toPoint(b));
    }
  }
  return m;
}
/// PlannedTrajectory.status → PlanStatus (fails naming the value).
inline common::Result<planning::PlanStatus> planStatusFromName(const std::string& name) {
  using R = common::Result<planning::PlanStatus>;
  for (const auto s : {planning::PlanStatus::kOptimized, planning::PlanStatus::kFallbackPrevious,
                       planning::PlanStatus::kFallbackBrake}) {
    if (name == planning::toString(s)) return R::ok(s);
  }
  return R::fail("PlannedTrajectory.status '" + name + "': expected optimized | fallback_previous | fallback_brake");
}
/// Fails naming the field when the arrays disagree in length or dt is not positive and finite.
inline common::Result<planning::PlannedTrajectory> fromMsg(const gesture_formation::PlannedTrajectory& m) {
  using R = common::Result<planning::PlannedTrajectory>;
  const std::size_t n = m.positions.size();
  if (m.velocities.size() != n || m.accelerations.size() != n || m.heading_rad.size() != n || m.pitch_rad.size() != n) {
    return R::fail("PlannedTrajectory: positions, velocities, accelerations, heading_rad, pitch_rad differ in length");
  }
  if (!(m.dt_s > 0.0) || !std::isfinite(m.dt_s)) return R::fail("PlannedTrajectory.dt_s: must be finite and > 0, got " + std::to_string(m.dt_s));
  planning::PlannedTrajectory p;
  p.uav_index = m.uav_index;
  p.sequence = m.sequence;
  p.t0_s = m.header.stamp.toSec();
  p.dt_s = m.dt_s;
  p.samples.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    p.samples[k].p_world = toEigen(m.positions[k]);
    p.samples[k].v_world = toEigen(m.velocities[k]);
    p.samples[k].a_world = toEigen(m.accelerations[k]);
    p.samples[k].heading_rad = m.heading_rad[k];
    p.samples[k].pitch_rad = m.pitch_rad[k];
  }
  return R::ok(std::move(p));
}
/// The flight stack's input (design.md §6): positions, velocities, accelerations, heading as yaw.
inline trajectory_msgs::MultiDOFJointTrajectory toMultiDof(const gesture_formation::PlannedTrajectory& m,
                                                           const std::string& joint_name) {
  trajectory_msgs::MultiDOFJointTrajectory t;
  t.header = m.header;
  t.joint_names.push_back(joint_name);
  for (std::size_t k = 0; k < m.positions.size(); ++k) {
    trajectory_msgs::MultiDOFJointTrajectoryPoint pt;
    geometry_msgs::Transform tf;
    tf.translation.x = m.positions[k].x;
    tf.translation.y = m.positions[k].y;
    tf.translation.z = m.positions[k].z;
    tf.rotation = cameraAxisOrientation(m.heading_rad[k], 0.0);
    geometry_msgs::Twist v, a;
    v.linear = m.velocities[k];
    a.linear = m.accelerations[k];
    pt.transforms.push_back(tf);
    pt.velocities.push_back(v);
    pt.accelerations.push_back(a);
    pt.time_from_start = ros::Duration(m.dt_s * static_cast<double>(k));
    t.points.push_back(pt);
  }
  return t;
}

// ---- formation parameters and commands -------------------------------------------------
inline gesture_formation::FormationParams toMsg(const formation::FormationParams& p, std::uint64_t version) {
  gesture_formation::FormationParams m;
  m.version = version;
  for (int i = 0; i < p.uavCount(); ++i) {
    gesture_formation::UavObservation o;
    o.beta_deg = p.uav(i).beta_deg;
    o.gamma_deg = p.uav(i).gamma_deg;
    o.distance_m = p.uav(i).distance_m;
    m.uavs.push_back(o);
  }
  return m;
}
/// The leader's parameters with the last command it handled (onboard::FormationParamsRole).
inline gesture_formation::FormationParams toMsg(const onboard::FormationParamsRole& role, const ros::Time& now,
                                                const std::string& world_frame) {
  const onboard::CommandRecord& r = role.last();
  auto m = toMsg(role.params(), role.version());
  m.header.stamp = now;
  m.header.frame_id = world_frame;
  m.last_command = r.text;
  m.last_outcome = r.outcome;
  m.last_command_source = r.source;
  m.last_command_stamp = ros::Time(r.stamp_s);
  m.last_command_status = r.status;
  m.last_command_uavs = r.uavs;
  return m;
}
/// A command as the logs name it: "gesture leader#3: uav1.distance_m += 1.000000".
inline std::string describe(const gesture_formation::FormationCommand& m) {
  return m.source + " " + m.sender + "#" + std::to_string(m.sequence) + ": " + m.target + "." + m.parameter +
         (m.kind == "set" ? " = " : " += ") + std::to_string(m.amount);
}
/// uavs[0] the leader, uavs[i] follower i (FormationParams.uavs, PlannedTrajectory.formation).
inline common::Result<formation::FormationParams> fromMsg(const std::vector<gesture_formation::UavObservation>& uavs) {
  using R = common::Result<formation::FormationParams>;
  if (uavs.empty()) return R::fail("FormationParams.uavs: empty (needs the leader)");
  formation::FormationParams p;
  p.followers.clear();
  for (std::size_t i = 0; i < uavs.size(); ++i) {
    const formation::UavObservation o{uavs[i].beta_deg, uavs[i].gamma_deg, uavs[i].distance_m};
    if (i == 0) {
      p.leader = o;
    } else {
      p.followers.push_back(o);
    }
  }
  return R::ok(std::move(p));
}
inline common::Result<formation::FormationParams> fromMsg(const gesture_formation::FormationParams& m) {
  return fromMsg(m.uavs);
}
/// The owner's parameters as they travel: with their version (a new leader carries it on).
inline common::Result<comm::FormationParamsMessage> toWire(const gesture_formation::FormationParams& m) {
  auto p = fromMsg(m);
  if (!p) return common::Result<comm::FormationParamsMessage>::fail(p.reason());
  return common::Result<comm::FormationParamsMessage>::ok(comm::FormationParamsMessage{std::move(*p), m.version});
}
inline common::Result<formation::Parameter> parameterFromName(const std::string& name) {
  using R = common::Result<formation::Parameter>;
  for (const auto p : {formation::Parameter::kBeta, formation::Parameter::kGamma, formation::Parameter::kDistance}) {
    if (name == formation::parameterName(p)) return R::ok(p);
  }
  return R::fail("parameter '" + name + "': expected beta_deg | gamma_deg | distance_m");
}
inline gesture_formation::FormationCommand toMsg(const formation::FormationCommand& c) {
  gesture_formation::FormationCommand m;
  m.sender = c.id.sender;
  m.sequence = c.id.sequence;
  m.source = formation::toString(c.source);
  switch (c.target.group) {
    case formation::TargetGroup::kLeader: m.target = "leader"; break;
    case formation::TargetGroup::kFollowers: m.target = "followers"; break;
    case formation::TargetGroup::kAll: m.target = "all"; break;
    case formation::TargetGroup::kList:
      m.target = "list";
      m.uavs.assign(c.target.uavs.begin(), c.target.uavs.end());
      break;
  }
  m.parameter = formation::parameterName(c.parameter);
  m.kind = c.kind == formation::CommandKind::kSet ? "set" : "increment";
  m.amount = c.amount;
  return m;
}
inline common::Result<formation::FormationCommand> fromMsg(const gesture_formation::FormationCommand& m) {
  using R = common::Result<formation::FormationCommand>;
  formation::FormationCommand c;
  c.id = {m.sender, m.sequence};
  if (m.source == "operator") {
    c.source = formation::CommandSource::kOperator;
  } else if (m.source == "gesture") {
    c.source = formation::CommandSource::kGesture;
  } else {
    return R::fail("FormationCommand.source '" + m.source + "': expected operator | gesture");
  }
  if (m.target == "list") {
    c.target = formation::CommandTarget::list(std::vector<formation::UavIndex>(m.uavs.begin(), m.uavs.end()));
  } else {
    auto t = formation::parseTarget(m.target);
    if (!t) return R::fail("FormationCommand.target: " + t.reason());
    c.target = *t;
  }
  auto p = parameterFromName(m.parameter);
  if (!p) return R::fail("FormationCommand." + p.reason());
  c.parameter = *p;
  if (m.kind == "increment") {
    c.kind = formation::CommandKind::kIncrement;
  } else if (m.kind == "set") {
    c.kind = formation::CommandKind::kSet;
  } else {
    return R::fail("FormationCommand.kind '" + m.kind + "': expected increment | set");
  }
  if (!std::isfinite(m.amount)) return R::fail("FormationCommand.amount: not finite");
  c.amount = m.amount;
  return R::ok(std::move(c));
}

// ---- worker state over LCM -------------------------------------------------------------
/// One replanning's outcome as this UAV's PlannedTrajectory: the plan, its fallback flag (a holding,
/// searching or aborting UAV or a fallback plan has right of way), mode and reason, the reference
/// and the worker prediction planned around, and the formation parameters it planned with.
inline gesture_formation::PlannedTrajectory toMsg(const planning::ReplanOutcome& out, int uav_index, double t_s,
                                                  const formation::FormationParams& params, std::uint64_t version,
                                                  const std::string& world_frame) {
  auto msg = toMsg(out.result);
  msg.fallback = out.fallback;
  msg.mode = planning::toString(out.mode);
  msg.mode_reason = out.reason;
  msg.header.frame_id = world_frame;
  msg.uav_index = uav_index;
  msg.params_version = version;
  msg.planned_at = ros::Time(t_s);
  msg.formation = toMsg(params, 0).uavs;
  for (int k = 0; k < out.reference.steps(); ++k) msg.reference.push_back(toPoint(out.reference.p_world.col(k)));
  for (int k = 0; k < out.worker.steps(); ++k) msg.worker.push_back(toPoint(out.worker.p_world.col(k)));
  return msg;
}

/// An abort command from ROS as a UAV's ReplanStep takes it (sent_s = stamp); fails naming the field.
/// An abort command from ROS as it travels (its send time is the envelope's); fails naming the field.
inline common::Result<comm::AbortMessage> toWire(const gesture_formation::AbortCommand& m) {
  using R = common::Result<comm::AbortMessage>;
  if (m.source > gesture_formation::AbortCommand::SOURCE_GESTURE) {
    return R::fail("source: " + std::to_string(m.source) + " is not 0 (operator) or 1 (gesture)");
  }
  comm::AbortMessage wire{formation::CommandId{m.sender, m.sequence},
                          m.source == gesture_formation::AbortCommand::SOURCE_GESTURE ? planning::AbortSource::kGesture
                                                                                      : planning::AbortSource::kOperator};
  if (auto e = comm::encodePayload(wire); !e) return R::fail(e.reason());  // the name's rules are the wire's
  return R::ok(wire);
}
inline common::Result<planning::AbortCommand> fromMsg(const gesture_formation::AbortCommand& m) {
  using R = common::Result<planning::AbortCommand>;
  auto wire = toWire(m);
  if (!wire) return R::fail(wire.reason());
  if (m.stamp.isZero()) return R::fail("stamp: zero (when was it sent?)");
  return R::ok(wire->command(m.stamp.toSec()));
}
inline gesture_formation::AbortCommand toMsg(const planning::AbortCommand& c, int link_sender) {
  gesture_formation::AbortCommand m;
  m.source = c.source == planning::AbortSource::kGesture ? gesture_formation::AbortCommand::SOURCE_GESTURE
                                                         : gesture_formation::AbortCommand::SOURCE_OPERATOR;
  m.sender = c.id.sender;
  m.sequence = c.id.sequence;
  m.stamp = ros::Time(c.sent_s);
  m.link_sender = link_sender;
  return m;
}
/// A command acknowledgement from ROS as it travels; fails naming the field.
inline common::Result<comm::CommandAckMessage> toWire(const gesture_formation::CommandAck& m) {
  using R = common::Result<comm::CommandAckMessage>;
  comm::CommandAckMessage wire;
  wire.id = formation::CommandId{m.sender, m.sequence};
  if (m.source == "gesture") wire.source = formation::CommandSource::kGesture;
  else if (m.source != "operator") return R::fail("source: '" + m.source + "' is not operator or gesture");
  bool known = false;
  for (auto s : {formation::CommandStatus::kApplied, formation::CommandStatus::kDuplicate, formation::CommandStatus::kRejected}) {
    if (m.status == formation::toString(s)) {
      wire.status = s;
      known = true;
    }
  }
  if (!known) return R::fail("status: '" + m.status + "' is not applied, duplicate or rejected");
  wire.params_version = m.params_version;
  wire.command_stamp_s = m.command_stamp.toSec();
  wire.outcome = m.outcome.substr(0, comm::kMaxAckOutcomeBytes);
  if (auto e = comm::encodePayload(wire); !e) return R::fail(e.reason());  // the wire's rules
  return R::ok(std::move(wire));
}
/// The leader's acknowledgement of `command`: what became of it (`status`, `outcome`) and the
/// parameter version it left; stamped `now`.
inline gesture_formation::CommandAck toAck(const gesture_formation::FormationCommand& command, const std::string& status,
                                           const std::string& outcome, std::uint64_t version, const ros::Time& now) {
  gesture_formation::CommandAck m;
  m.header.stamp = now;
  m.sender = command.sender;
  m.sequence = command.sequence;
  m.source = command.source;
  m.status = status;
  m.outcome = outcome;
  m.params_version = version;
  m.command_stamp = command.header.stamp;
  return m;
}
inline gesture_formation::CommandAck fromWire(const comm::CommandAckMessage& a) {
  gesture_formation::CommandAck m;
  m.sender = a.id.sender;
  m.sequence = a.id.sequence;
  m.source = formation::toString(a.source);
  m.status = formation::toString(a.status);
  m.outcome = a.outcome;
  m.params_version = a.params_version;
  m.command_stamp = ros::Time(std::max(a.command_stamp_s, 0.0));
  return m;
}

inline gesture_formation::AssistanceState toMsg(const formation::AssistanceState& a, const ros::Time& now) {
  gesture_formation::AssistanceState m;
  m.header.stamp = now;
  m.phase = static_cast<std::uint8_t>(a.phase);
  m.requested_at = ros::Time(std::max(a.requested_s, 0.0));
  m.requested_by = a.requested_by;
  m.acknowledged_at = ros::Time(std::max(a.acknowledged_s, 0.0));
  m.acknowledged_by = a.acknowledged_by;
  return m;
}
/// An assistance state from ROS; fails naming the field.
inline common::Result<formation::AssistanceState> fromMsg(const gesture_formation::AssistanceState& m) {
  using R = common::Result<formation::AssistanceState>;
  if (m.phase > gesture_formation::AssistanceState::PHASE_ACKNOWLEDGED) {
    return R::fail("phase: " + std::to_string(m.phase) + " is not 0 (none), 1 (requested) or 2 (acknowledged)");
  }
  return R::ok(formation::AssistanceState{static_cast<formation::AssistancePhase>(m.phase), m.requested_at.toSec(),
                                          m.requested_by, m.acknowledged_at.toSec(), m.acknowledged_by});
}
/// An assistance state from ROS as it travels; fails naming the field.
inline common::Result<comm::AssistanceMessage> toWire(const gesture_formation::AssistanceState& m) {
  using R = common::Result<comm::AssistanceMessage>;
  auto state = fromMsg(m);
  if (!state) return R::fail(state.reason());
  comm::AssistanceMessage wire{std::move(*state)};
  if (auto e = comm::encodePayload(wire); !e) return R::fail(e.reason());  // the wire's rules
  return R::ok(std::move(wire));
}

inline std::uint8_t toMsgPhase(planning::AbortPhase p) {
  using S = gesture_formation::AbortState;
  switch (p) {
    case planning::AbortPhase::kRetreat: return S::PHASE_RETREAT;
    case planning::AbortPhase::kAtRetreat: return S::PHASE_AT_RETREAT;
    case planning::AbortPhase::kReturnHome: return S::PHASE_RETURN_HOME;
    case planning::AbortPhase::kAtHome: return S::PHASE_AT_HOME;
    case planning::AbortPhase::kLanding: return S::PHASE_LANDING;
    case planning::AbortPhase::kLanded: return S::PHASE_LANDED;
    case planning::AbortPhase::kNoGoal: return S::PHASE_NO_GOAL;
  }
  return S::PHASE_NONE;
}
/// One UAV's abort state (PHASE_NONE while not aborting); `reason` from its last replanning.
inline gesture_formation::AbortState toAbortState(const planning::AbortPlanner& a, int uav_index, double t_s,
                                                  const std::string& reason, int link_sender,
                                                  const std::string& world_frame) {
  gesture_formation::AbortState m;
  m.header.stamp = ros::Time(t_s);
  m.header.frame_id = world_frame;
  m.uav_index = uav_index;
  if (!a.aborting()) return m;
  m.phase = toMsgPhase(a.phase());
  m.settled = planning::settled(a.phase());
  m.goal_valid = a.currentGoal().has_value();
  if (m.goal_valid) m.goal = toPoint(*a.currentGoal());
  m.reason = reason;
  m.command = toMsg(*a.command(), link_sender);
  m.accepted_at = ros::Time(a.acceptedAt());
  return m;
}

inline comm::WorkerStateMessage toWire(const gesture_formation::WorkerState& s) {
  comm::WorkerStateMessage w;
  w.t_s = s.header.stamp.toSec();
  w.last_fused_t_s = std::min(w.t_s, s.last_fused.toSec());
  w.p_world = toEigen(s.position);
  w.v_world = toEigen(s.velocity);
  for (std::size_t i = 0; i < 6; ++i) w.covariance_diag[i] = std::max(0.0, s.covariance[7 * i]);
  w.lost = s.lost;
  return w;
}
inline gesture_formation::WorkerState fromWire(const comm::WorkerStateMessage& w) {
  estimation::Vector6d x;
  x << w.p_world, w.v_world;
  estimation::Matrix6d P = estimation::Matrix6d::Zero();
  for (int i = 0; i < 6; ++i) P(i, i) = w.covariance_diag[static_cast<std::size_t>(i)];
  gesture_formation::WorkerState s = toWorkerState(x, P);
  s.header.stamp = ros::Time(w.t_s);
  s.last_fused = ros::Time(std::max(0.0, w.last_fused_t_s));
  s.lost = w.lost;
  s.predicted = true;
  s.source = "lcm";
  return s;
}

/// WorkerState → what the replanning step knows of the worker (last_fused 0: never fused).
inline planning::WorkerKnowledge toWorkerKnowledge(const gesture_formation::WorkerState& s) {
  planning::WorkerKnowledge w;
  w.stamp_s = s.header.stamp.toSec();
  w.fused_s = s.last_fused.isZero() ? std::nan("") : s.last_fused.toSec();
  w.p_world = toEigen(s.position);
  w.v_world = toEigen(s.velocity);
  w.lost = s.lost != 0;
  return w;
}

// ---- gesture observations (the multi-view vote) ---------------------------------------------
/// CameraInfo (plumb_bob or no distortion) → the intrinsics of the image it describes: the full
/// sensor's calibration with the binning and region of interest applied (REP 104;
/// estimation::readoutIntrinsics); fails naming what is unusable.
inline common::Result<estimation::CameraIntrinsics> toIntrinsics(const sensor_msgs::CameraInfo& m) {
  using R = common::Result<estimation::CameraIntrinsics>;
  estimation::CameraIntrinsics k;
  k.fx = m.K[0];
  k.fy = m.K[4];
  k.cx = m.K[2];
  k.cy = m.K[5];
  k.width_px = static_cast<int>(m.width);
  k.height_px = static_cast<int>(m.height);
  if (!m.D.empty()) {
    if (m.distortion_model != "plumb_bob" || m.D.size() != 5) {
      return R::fail("CameraInfo: distortion model '" + m.distortion_model + "' with " + std::to_string(m.D.size()) +
                     " coefficients: expected plumb_bob with 5");
    }
    for (std::size_t i = 0; i < 5; ++i) k.distortion[i] = m.D[i];
  }
  const auto errors = k.validate();
  if (!errors.empty()) return R::fail("CameraInfo: " + errors.front());
  estimation::SensorReadout r;
  r.binning_x = static_cast<int>(std::min<std::uint32_t>(m.binning_x, 1u << 20));
  r.binning_y = static_cast<int>(std::min<std::uint32_t>(m.binning_y, 1u << 20));
  r.roi_x_offset = static_cast<int>(std::min<std::uint32_t>(m.roi.x_offset, 1u << 30));
  r.roi_y_offset = static_cast<int>(std::min<std::uint32_t>(m.roi.y_offset, 1u << 30));
  r.roi_width = static_cast<int>(std::min<std::uint32_t>(m.roi.width, 1u << 30));
  r.roi_height = static_cast<int>(std::min<std::uint32_t>(m.roi.height, 1u << 30));
  const auto image = estimation::readoutIntrinsics(k, r);
  if (!image) return R::fail("CameraInfo: " + image.reason());
  return image;
}
// ---- a skeleton with its camera (view_fusion.confirm_3d; Gesture / GestureObservation) -----
/// The 17 keypoints as (u, v, confidence) triples.
inline std::vector<double> toKeypoints(const gesture::Skeleton2D& s) {
  std::vector<double> out;
  out.reserve(3 * gesture::kNumKeypoints);
  for (std::size_t k = 0; k < static_cast<std::size_t>(gesture::kNumKeypoints); ++k) {
    out.insert(out.end(), {s.x[k], s.y[k], s.c[k]});
  }
  return out;
}
inline sensor_msgs::CameraInfo toCameraInfo(const estimation::CameraIntrinsics& k) {
  sensor_msgs::CameraInfo m;
  m.width = static_cast<std::uint32_t>(k.width_px);
  m.height = static_cast<std::uint32_t>(k.height_px);
  m.distortion_model = "plumb_bob";
  m.D.assign(k.distortion.begin(), k.distortion.end());
  m.K = {k.fx, 0.0, k.cx, 0.0, k.fy, k.cy, 0.0, 0.0, 1.0};
  m.R = {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0};
  m.P = {k.fx, 0.0, k.cx, 0.0, 0.0, k.fy, k.cy, 0.0, 0.0, 0.0, 1.0, 0.0};
  return m;
}
/// Copies x, y, z between messages that have them (Point, Vector3).
template <typename To, typename From>
void copyXyz(const From& from, To& to) {
  to.x = from.x;
  to.y = from.y;
  to.z = from.z;
}
inline geometry_msgs::Pose toPose(const Eigen::Quaterniond& q, const Eigen::Vector3d& p) {
  geometry_msgs::Pose m;
  m.position = toPoint(p);
  m.orientation.w = q.w();
  m.orientation.x = q.x();
  m.orientation.y = q.y();
  m.orientation.z = q.z();
  return m;
}
inline geometry_msgs::Pose toPose(const geometry_msgs::Transform& t) {
  geometry_msgs::Pose m;
  copyXyz(t.translation, m.position);
  m.orientation = t.rotation;
  return m;
}
inline geometry_msgs::Transform toTransform(const geometry_msgs::Pose& p) {
  geometry_msgs::Transform t;
  copyXyz(p.position, t.translation);
  t.rotation = p.orientation;
  return t;
}
/// Keypoints (17 triples), the image's camera info and the camera's pose in the world → a
/// calibrated skeleton; fails naming the field (wrong count, a quaternion of norm outside
/// 1 ± 1e-3, and everything gesture::validate refuses).
inline common::Result<gesture::CalibratedSkeleton> toCalibrated(const std::vector<double>& keypoints,
                                                                const sensor_msgs::CameraInfo& camera,
                                                                const geometry_msgs::Pose& pose) {
  using R = common::Result<gesture::CalibratedSkeleton>;
  if (keypoints.size() != 3 * static_cast<std::size_t>(gesture::kNumKeypoints)) {
    return R::fail("keypoints: " + std::to_string(keypoints.size()) + " values, expected " +
                   std::to_string(3 * gesture::kNumKeypoints));
  }
  gesture::CalibratedSkeleton c;
  for (std::size_t k = 0; k < static_cast<std::size_t>(gesture::kNumKeypoints); ++k) {
    c.skeleton.x[k] = keypoints[3 * k];
    c.skeleton.y[k] = keypoints[3 * k + 1];
    c.skeleton.c[k] = keypoints[3 * k + 2];
  }
  auto intrinsics = toIntrinsics(camera);
  if (!intrinsics) return R::fail("camera: " + intrinsics.reason());
  c.intrinsics = *intrinsics;
  const auto& o = pose.orientation;
  const Eigen::Quaterniond q(o.w, o.x, o.y, o.z);
  if (!(std::abs(q.norm() - 1.0) <= 1e-3)) {
    return R::fail("camera_pose.orientation: norm " + std::to_string(q.norm()) + ", expected 1");
  }
  c.R_world_camera = q.normalized().toRotationMatrix();
  c.p_world_camera = Eigen::Vector3d(pose.position.x, pose.position.y, pose.position.z);
  const std::vector<std::string> problems = gesture::validate(c);
  if (!problems.empty()) return R::fail(problems.front());
  return R::ok(std::move(c));
}

/// The vote's input; an unknown geometry becomes NaN (the view votes only without the envelope gate).
/// A skeleton that cannot be used (skeleton_problem set, when given) leaves the view out of the
/// 3-D confirmation only; its 2-D vote stands.
inline gesture::ViewObservation toViewObservation(const gesture_formation::GestureObservation& m,
                                                  std::string* skeleton_problem = nullptr) {
  gesture::ViewObservation o;
  o.view = m.uav_index;
  o.t_s = m.header.stamp.toSec();
  o.gesture_id = m.gesture_id;
  o.distance_m = m.geometry_known ? m.distance_m : std::nan("");
  o.elevation_deg = m.geometry_known ? m.elevation_deg : std::nan("");
  if (!m.keypoints.empty()) {
    auto c = toCalibrated(m.keypoints, m.camera, m.camera_pose);
    if (c) o.calibrated = std::move(*c);
    else if (skeleton_problem) *skeleton_problem = c.reason();
  }
  return o;
}
/// Fails naming the field on what the payload encoder or a peer's decoder would refuse.
inline common::Result<comm::GestureObservationMessage> toWire(const gesture_formation::GestureObservation& m) {
  using R = common::Result<comm::GestureObservationMessage>;
  if (m.gesture_id < 0 || m.gesture_id > comm::kMaxGestureId) {
    return R::fail("GestureObservation.gesture_id " + std::to_string(m.gesture_id) + " outside [0, " +
                   std::to_string(comm::kMaxGestureId) + "]");
  }
  comm::GestureObservationMessage w;
  w.uav_index = m.uav_index;
  w.t_s = m.header.stamp.toSec();
  w.gesture_id = static_cast<std::uint8_t>(m.gesture_id);
  w.probabilities.assign(m.probabilities.begin(), m.probabilities.end());
  w.geometry_known = m.geometry_known;
  w.distance_m = m.geometry_known ? m.distance_m : 0.0;
  w.elevation_deg = m.geometry_known ? m.elevation_deg : 0.0;
  if (!m.keypoints.empty()) {
    auto c = toCalibrated(m.keypoints, m.camera, m.camera_pose);
    if (!c) return R::fail("GestureObservation skeleton: " + c.reason());
    comm::ObservedSkeleton s;
    s.skeleton = c->skeleton;
    const auto& q = m.camera_pose.orientation;
    s.q_world_camera = Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized();
    s.p_world_camera = c->p_world_camera;
    s.intrinsics = c->intrinsics;
    w.skeleton = std::move(s);
  }
  return R::ok(std::move(w));
}
inline gesture_formation::GestureObservation fromWire(const comm::GestureObservationMessage& w) {
  gesture_formation::GestureObservation m;
  m.header.stamp = ros::Time(w.t_s);
  m.uav_index = static_cast<std::uint8_t>(w.uav_index);
  m.gesture_id = w.gesture_id;
  m.probabilities.assign(w.probabilities.begin(), w.probabilities.end());
  m.geometry_known = w.geometry_known;
  m.distance_m = w.distance_m;
  m.elevation_deg = w.elevation_deg;
  if (w.skeleton) {
    m.keypoints = toKeypoints(w.skeleton->skeleton);
    m.camera = toCameraInfo(w.skeleton->intrinsics);
    m.camera_pose = toPose(w.skeleton->q_world_camera, w.skeleton->p_world_camera);
  }
  return m;
}

// ---- images (no cv_bridge in the Debian ROS packages) ---------------------------------------
/// A colour image (bgr8, rgb8, mono8) as an owned BGR cv::Mat.
inline common::Result<cv::Mat> toBgr(const sensor_msgs::Image& m) {
  using R = common::Result<cv::Mat>;
  const int channels = m.encoding == "mono8" ? 1 : 3;
  if (m.encoding != "bgr8" && m.encoding != "rgb8" && m.encoding != "mono8") {
    return R::fail("Image.encoding '" + m.encoding + "': expected bgr8, rgb8 or mono8");
  }
  if (m.width == 0 || m.height == 0 || m.step < m.width * static_cast<std::uint32_t>(channels) ||
      m.data.size() < static_cast<std::size_t>(m.step) * m.height) {
    return R::fail("Image: " + std::to_string(m.width) + "x" + std::to_string(m.height) + ", step " +
                   std::to_string(m.step) + ", " + std::to_string(m.data.size()) + " bytes: inconsistent");
  }
  const cv::Mat view(static_cast<int>(m.height), static_cast<int>(m.width), channels == 1 ? CV_8UC1 : CV_8UC3,
                     const_cast<std::uint8_t*>(m.data.data()), m.step);
  cv::Mat bgr;
  if (m.encoding == "bgr8") bgr = view.clone();
  else if (m.encoding == "rgb8") cv::cvtColor(view, bgr, cv::COLOR_RGB2BGR);
  else cv::cvtColor(view, bgr, cv::COLOR_GRAY2BGR);
  return R::ok(std::move(bgr));
}
/// A compressed colour image (sensor_msgs/CompressedImage as image_transport's `compressed`
/// publishes it: JPEG or PNG, format e.g. "jpeg", "bgr8; jpeg compressed bgr8") as an owned BGR cv::Mat.
inline common::Result<cv::Mat> toBgr(const sensor_msgs::CompressedImage& m) {
  using R = common::Result<cv::Mat>;
  if (m.format.find("compressedDepth") != std::string::npos) {
    return R::fail("CompressedImage.format '" + m.format + "': a depth image (compressedDepth), expected a colour image");
  }
  if (m.data.empty()) return R::fail("CompressedImage.data: empty (format '" + m.format + "')");
  const cv::Mat bytes(1, static_cast<int>(m.data.size()), CV_8UC1, const_cast<std::uint8_t*>(m.data.data()));
  cv::Mat bgr = cv::imdecode(bytes, cv::IMREAD_COLOR);
  if (bgr.empty()) {
    return R::fail("CompressedImage: " + std::to_string(m.data.size()) + " bytes of format '" + m.format +
                   "' do not decode as JPEG or PNG");
  }
  return R::ok(std::move(bgr));
}
/// An aligned depth image (16UC1 / mono16: units of depth_scale_m; 32FC1: metres) as an owned cv::Mat.
inline common::Result<cv::Mat> toDepth(const sensor_msgs::Image& m) {
  using R = common::Result<cv::Mat>;
  int type = 0;
  std::uint32_t bytes = 0;
  if (m.encoding == "16UC1" || m.encoding == "mono16") {
    type = CV_16UC1;
    bytes = 2;
  } else if (m.encoding == "32FC1") {
    type = CV_32FC1;
    bytes = 4;
  } else {
    return R::fail("depth Image.encoding '" + m.encoding + "': expected 16UC1, mono16 or 32FC1");
  }
  if (m.is_bigendian) return R::fail("depth Image: big-endian data not supported");
  if (m.width == 0 || m.height == 0 || m.step < m.width * bytes ||
      m.data.size() < static_cast<std::size_t>(m.step) * m.height) {
    return R::fail("depth Image: " + std::to_string(m.width) + "x" + std::to_string(m.height) + ", step " +
                   std::to_string(m.step) + ", " + std::to_string(m.data.size()) + " bytes: inconsistent");
  }
  const cv::Mat view(static_cast<int>(m.height), static_cast<int>(m.width), type, const_cast<std::uint8_t*>(m.data.data()),
                     m.step);
  return R::ok(view.clone());
}

/// An owned, continuous or not, cv::Mat (CV_8UC3 as "rgb8"/"bgr8", CV_32FC1 as "32FC1") as an
/// Image with `encoding`; fails when the Mat's type does not match the encoding.
inline common::Result<sensor_msgs::Image> toImage(const cv::Mat& mat, const std::string& encoding) {
  using R = common::Result<sensor_msgs::Image>;
  const bool colour = encoding == "rgb8" || encoding == "bgr8";
  if (!(colour && mat.type() == CV_8UC3) && !(encoding == "32FC1" && mat.type() == CV_32FC1)) {
    return R::fail("Image: a cv::Mat of type " + std::to_string(mat.type()) + " cannot be encoded as '" + encoding + "'");
  }
  sensor_msgs::Image m;
  m.height = static_cast<std::uint32_t>(mat.rows);
  m.width = static_cast<std::uint32_t>(mat.cols);
  m.encoding = encoding;
  m.is_bigendian = 0;
  const std::size_t row_bytes = static_cast<std::size_t>(mat.cols) * mat.elemSize();
  m.step = static_cast<std::uint32_t>(row_bytes);
  m.data.resize(row_bytes * static_cast<std::size_t>(mat.rows));
  for (int r = 0; r < mat.rows; ++r) std::memcpy(m.data.data() + row_bytes * static_cast<std::size_t>(r), mat.ptr(r), row_bytes);
  return R::ok(std::move(m));
}

}  // namespace gesture_formation::nodelets

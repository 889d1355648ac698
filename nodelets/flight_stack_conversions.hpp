#pragma once
// Message <-> core conversions of the flight-stack nodelets (OdometryAdapter, SetpointRelay;
// docs/ros.md "Flight stacks"), beside conversions.hpp as sim_conversions.hpp is: no math here,
// the core (onboard::toPlannerState, onboard::SetpointRelay) computes.
#include <string>

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TwistStamped.h>
#include <geometry_msgs/Vector3Stamped.h>
#include <nav_msgs/Odometry.h>

#include "conversions.hpp"
#include "gesture_formation/onboard/odometry_adapter.hpp"
#include "gesture_formation/onboard/setpoint_relay.hpp"

namespace gesture_formation::nodelets {

inline Eigen::Quaterniond toEigen(const geometry_msgs::Quaternion& q) { return Eigen::Quaterniond(q.w, q.x, q.y, q.z); }

/// A flight stack's odometry as it came; `twist_in_body`: its child_frame_id is the body.
inline onboard::FlightStackOdometry toFlightStackOdometry(const nav_msgs::Odometry& m, bool twist_in_body) {
  onboard::FlightStackOdometry o;
  o.t_s = m.header.stamp.toSec();
  o.p_world = toEigen(m.pose.pose.position);
  o.q_world_body = toEigen(m.pose.pose.orientation);
  o.v = toEigen(m.twist.twist.linear);
  o.twist_in_body = twist_in_body;
  return o;
}

/// The planner's odometry (docs/ros.md, odometry convention): orientation = the camera axis,
/// twist in the world frame, child_frame_id = the world frame.
inline nav_msgs::Odometry toPlannerOdometry(const planning::UavKinematicState& s, const ros::Time& stamp,
                                            const std::string& world_frame) {
  nav_msgs::Odometry o;
  o.header.stamp = stamp;
  o.header.frame_id = world_frame;
  o.child_frame_id = world_frame;
  o.pose.pose.position = toPoint(s.p_world);
  o.pose.pose.orientation = cameraAxisOrientation(s.heading_rad, s.pitch_rad);
  o.twist.twist.linear = toVector3(s.v_world);
  return o;
}

/// MAVROS setpoint_position/local: the position, the body's yaw = the camera heading (level).
inline geometry_msgs::PoseStamped toPoseSetpoint(const onboard::Setpoint& s, const std::string& world_frame) {
  geometry_msgs::PoseStamped m;
  m.header.stamp = ros::Time(s.t_s);
  m.header.frame_id = world_frame;
  m.pose.position = toPoint(s.p_world);
  m.pose.orientation = cameraAxisOrientation(s.heading_rad, 0.0);
  return m;
}

/// MAVROS setpoint_velocity/cmd_vel: the velocity in the world frame (ENU), angular.z the yaw rate.
inline geometry_msgs::TwistStamped toTwistSetpoint(const onboard::Setpoint& s, const std::string& world_frame) {
  geometry_msgs::TwistStamped m;
  m.header.stamp = ros::Time(s.t_s);
  m.header.frame_id = world_frame;
  m.twist.linear = toVector3(s.v_world);
  m.twist.angular.z = s.yaw_rate_radps;
  return m;
}

/// The gimbal's target (docs/ros.md): x roll 0, y the camera pitch ξ (rad, positive up), z the
/// camera heading φ (rad, ENU: from x = east, counter-clockwise), in the world frame.
inline geometry_msgs::Vector3Stamped toGimbalSetpoint(const onboard::Setpoint& s, const std::string& world_frame) {
  geometry_msgs::Vector3Stamped m;
  m.header.stamp = ros::Time(s.t_s);
  m.header.frame_id = world_frame;
  m.vector.x = 0.0;
  m.vector.y = s.pitch_rad;
  m.vector.z = s.heading_rad;
  return m;
}

}  // namespace gesture_formation::nodelets

#pragma once
/// \file
/// \brief A flight stack's odometry → the state the planner expects (docs/ros.md, "Flight
/// stacks"; the odometry convention of docs/conventions.md): position of the body, velocity in
/// the world frame, and the *camera axis*' heading φ and pitch ξ (ξ positive up) — the body
/// attitude composed with the camera mount (fixed, or a gimbal's current angle from tf).
///
/// nav_msgs/Odometry defines the twist in `child_frame_id`: MAVROS `local_position/odom`
/// (child base_link) and the MRS system's `odom_main` (child <uav>/fcu) give it in the body
/// frame, so v_world = R_world_body · v_body; a message whose child frame is the world frame
/// carries v_world already. Both stacks' pose is ENU / FLU (REP 103).

#include <Eigen/Geometry>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/planning/planned_trajectory.hpp"

namespace gesture_formation::onboard {

/// \brief Which axis of the camera frame is the optical axis: x for an FLU camera body (REP 103,
/// e.g. a RealSense `camera_link`), z for an optical frame (REP 103 `*_optical_frame`).
enum class OpticalAxis { kX, kZ };

/// \brief The camera's orientation in the body frame, q_body_camera (Eigen order w, x, y, z).
struct CameraMount {
  Eigen::Quaterniond q_body_camera = Eigen::Quaterniond::Identity();
  OpticalAxis optical_axis = OpticalAxis::kX;

  /// \brief A fixed mount from roll, pitch, yaw about the body's x, y, z (R = Rz(yaw)·Ry(pitch)·Rx(roll),
  /// REP 103 FLU: a camera tilted 20° down is pitch +0.349 rad), optical axis x.
  static CameraMount fromRpy(double roll_rad, double pitch_rad, double yaw_rad);
};

/// \brief One odometry message of the flight stack, its fields as they came.
struct FlightStackOdometry {
  double t_s = 0.0;
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();                 ///< pose.position (world ENU)
  Eigen::Quaterniond q_world_body = Eigen::Quaterniond::Identity();  ///< pose.orientation
  Eigen::Vector3d v = Eigen::Vector3d::Zero();                       ///< twist.linear, in the child frame
  bool twist_in_body = true;  ///< child_frame_id is the body (true) or the world frame (false)
};

/// \brief The planner's state from a flight stack's odometry and the camera mount: p_world as
/// given, v_world rotated out of the body frame when `twist_in_body`, heading φ = atan2 of the
/// optical axis' world y, x and pitch ξ = asin of its world z. Fails, naming the field and
/// value, on a non-finite number, a degenerate orientation (|q| < 0.5 or > 1.5: not a rotation;
/// others are normalised) or a vertical optical axis (heading undefined).
common::Result<planning::UavKinematicState> toPlannerState(const FlightStackOdometry& odom, const CameraMount& mount);

/// \brief The odometry's state carried to `t_s` (a replanning's time) at its velocity: a plan
/// starts at t_s, and from the state of the odometry's stamp it would start where the UAV was up
/// to the planner's max_odometry_age_s earlier (1.5 m at 3 m/s and 0.5 s), the relay pulling the
/// UAV back towards it. Position only (velocity, angles as measured); a stamp at or after t_s
/// (clocks a little apart) is taken as it is; t_s.
planning::UavKinematicState carriedTo(const planning::UavKinematicState& odom, double stamp_s, double t_s);

}  // namespace gesture_formation::onboard

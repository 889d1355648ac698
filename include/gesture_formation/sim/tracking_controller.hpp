#pragma once
/// \file
/// \brief Trajectory-tracking controller of one UAV: position/velocity feedback with an
/// integral term (wind rejection, anti-windup clamp) plus the plan's feedforward
/// acceleration, gravity and estimated drag compensation (conditional integration: an axis
/// integrates only while its position error is below `integral_zone_m` or its velocity error
/// below `integral_zone_mps`, i.e. not during large transients) → specific thrust command;
/// heading and camera pitch tracked with a proportional law plus the plan's rate,
/// rate-limited.
///
///   a_des = a_ff + k_p (p_ref − p̂) + k_d (v_ref − v̂) + k_i ∫(p_ref − p̂) dt
///   a_cmd = a_des + g ẑ + drag(v_ref)/m       (the plant limits it; see multirotor.hpp)
///
/// Safety: the controller executes only a plan it was given (the planner returns only
/// verified plans). Without a plan (none yet, or cleared) it **brakes to hover**: it
/// decelerates at up to `brake_accel_mps2` and then holds the position where it stopped.
/// After a plan's end, PlannedTrajectory::sampleAt holds the last position.
/// Feedback uses the *estimated* state (odometry), not the truth. Thread safety: none.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/planning/uav_planner.hpp"
#include "gesture_formation/sim/multirotor.hpp"
#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::sim {

struct ControllerConfig {
  // Defaults place the closed-loop poles at −1.2 (xy) and −1.5 rad/s (z), triple:
  // s³ + k_d s² + k_p s + k_i = (s + ω)³.
  double kp_xy = 4.32, kp_z = 6.75;       ///< [1/s²], > 0
  double kd_xy = 3.6, kd_z = 4.5;         ///< [1/s], > 0
  double ki_xy = 1.73, ki_z = 3.375;      ///< [1/s³], ≥ 0
  double integral_limit_mps2 = 3.0;       ///< clamp of the integral term's acceleration, ≥ 0
  double integral_zone_m = 1.0;           ///< integrate an axis while |position error| < this ...
  double integral_zone_mps = 0.3;         ///< ... or |velocity error| < this (steady state; anti-windup), > 0
  double max_accel_mps2 = 8.0;            ///< clamp of |a_des| before gravity, > 0
  double k_heading = 3.0;                 ///< [1/s], > 0
  double k_pitch = 4.0;                   ///< [1/s], > 0
  double brake_accel_mps2 = 4.0;          ///< deceleration without a plan, > 0
  double hover_speed_mps = 0.2;           ///< below: brake phase ends, hold position, > 0

  std::vector<std::string> validate(const std::string& prefix = "") const;
};

/// \brief The one range of each number of ControllerConfig: the controller gains (mission.controller; brake_accel_mps2: planning::replanConfigFields()).
const common::FieldTable<ControllerConfig>& controllerConfigFields();

/// \brief The estimated state the controller feeds back on (odometry).
struct EstimatedState {
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();
  double heading_rad = 0.0;
  double pitch_rad = 0.0;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

class TrackingController {
 public:
  TrackingController(const ControllerConfig& config, const MultirotorParams& plant);

  /// \brief Sets the plan to track (a verified one; an empty plan is treated as none).
  void setPlan(const planning::PlannedTrajectory& plan);
  /// \brief Forgets the plan: the controller brakes to hover from the next update.
  void clearPlan();
  bool hasPlan() const { return has_plan_; }
  const planning::PlannedTrajectory& plan() const { return plan_; }

  /// \brief The command at `t_s` for the estimated state; `dt_s` integrates the I-term.
  MultirotorCommand update(double t_s, double dt_s, const EstimatedState& est);

  /// \brief The reference sample used by the last update (hover point when braking).
  const planning::TrajectorySample& lastReference() const { return last_ref_; }
  /// \brief True while braking / holding without a plan.
  bool braking() const { return !has_plan_; }

 private:
  ControllerConfig config_;
  MultirotorParams plant_;
  planning::PlannedTrajectory plan_;
  bool has_plan_ = false;
  Eigen::Vector3d integral_ = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> hold_p_;
  planning::TrajectorySample last_ref_;
};

}  // namespace gesture_formation::sim

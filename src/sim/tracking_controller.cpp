#include "gesture_formation/sim/tracking_controller.hpp"

#include <algorithm>
#include <cmath>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/planning/replan_step.hpp"

namespace gesture_formation::sim {

const common::FieldTable<ControllerConfig>& controllerConfigFields() {
  using common::Range;
  using C = ControllerConfig;
  static const common::FieldTable<C> t{{
      {"kp_xy", Range::positive(), [](C& c) { return &c.kp_xy; }},
      {"kp_z", Range::positive(), [](C& c) { return &c.kp_z; }},
      {"kd_xy", Range::positive(), [](C& c) { return &c.kd_xy; }},
      {"kd_z", Range::positive(), [](C& c) { return &c.kd_z; }},
      {"ki_xy", Range::nonNegative(), [](C& c) { return &c.ki_xy; }},
      {"ki_z", Range::nonNegative(), [](C& c) { return &c.ki_z; }},
      {"integral_limit_mps2", Range::nonNegative(), [](C& c) { return &c.integral_limit_mps2; }},
      {"integral_zone_m", Range::positive(), [](C& c) { return &c.integral_zone_m; }},
      {"integral_zone_mps", Range::positive(), [](C& c) { return &c.integral_zone_mps; }},
      {"max_accel_mps2", Range::positive(), [](C& c) { return &c.max_accel_mps2; }},
      {"k_heading", Range::positive(), [](C& c) { return &c.k_heading; }},
      {"k_pitch", Range::positive(), [](C& c) { return &c.k_pitch; }},
      {"hover_speed_mps", Range::positive(), [](C& c) { return &c.hover_speed_mps; }},
  }};
  return t;
}

std::vector<std::string> ControllerConfig::validate(const std::string& prefix) const {
  auto e = controllerConfigFields().rangeProblems(*this);
  // The braking deceleration is an onboard setting (the replanning step's stop point): its range.
  const common::Range& brake = *planning::replanConfigFields().rangeOf("controller.brake_accel_mps2");
  if (!brake.contains(brake_accel_mps2)) e.push_back({"brake_accel_mps2", common::rangeProblem(brake, brake_accel_mps2)});
  return common::problemLines(e, prefix);
}

TrackingController::TrackingController(const ControllerConfig& config, const MultirotorParams& plant)
    : config_(config), plant_(plant) {}

void TrackingController::setPlan(const planning::PlannedTrajectory& plan) {
  if (plan.empty()) {
    clearPlan();
    return;
  }
  plan_ = plan;
  has_plan_ = true;
  hold_p_.reset();
}

void TrackingController::clearPlan() {
  has_plan_ = false;
  plan_ = planning::PlannedTrajectory{};
}

MultirotorCommand TrackingController::update(double t_s, double dt_s, const EstimatedState& est) {
  planning::TrajectorySample ref;
  Eigen::Vector3d a_des = Eigen::Vector3d::Zero();
  double heading_rate_ff = 0.0, pitch_rate_ff = 0.0;
  if (has_plan_) {
    ref = plan_.sampleAt(t_s);
    const double h = 0.05;
    const planning::TrajectorySample next = plan_.sampleAt(t_s + h);
    heading_rate_ff = common::wrapAngle(next.heading_rad - ref.heading_rad) / h;
    pitch_rate_ff = (next.pitch_rad - ref.pitch_rad) / h;
  } else {
    // Brake to hover: decelerate, then hold where the UAV stopped.
    ref.heading_rad = est.heading_rad;
    ref.pitch_rad = est.pitch_rad;
    if (!hold_p_ && est.v_world.norm() <= config_.hover_speed_mps) hold_p_ = est.p_world;
    if (!hold_p_) {
      ref.p_world = est.p_world;
      Eigen::Vector3d brake = -config_.kd_xy * est.v_world;
      if (brake.norm() > config_.brake_accel_mps2) brake *= config_.brake_accel_mps2 / brake.norm();
      last_ref_ = ref;
      integral_.setZero();
      const Eigen::Vector3d drag_comp =
          (plant_.drag_linear_ns_per_m + plant_.drag_quadratic_ns2_per_m2 * est.v_world.norm()) * est.v_world /
          plant_.mass_kg;
      MultirotorCommand cmd;
      cmd.thrust_accel_world = brake + Eigen::Vector3d(0.0, 0.0, kGravityMps2) + drag_comp;
      return cmd;
    }
    ref.p_world = *hold_p_;
  }
  last_ref_ = ref;

  const Eigen::Vector3d e_p = ref.p_world - est.p_world;
  const Eigen::Vector3d e_v = ref.v_world - est.v_world;
  const Eigen::Vector3d kp(config_.kp_xy, config_.kp_xy, config_.kp_z);
  const Eigen::Vector3d kd(config_.kd_xy, config_.kd_xy, config_.kd_z);
  const Eigen::Vector3d ki(config_.ki_xy, config_.ki_xy, config_.ki_z);
  if (dt_s > 0.0) {
    for (int i = 0; i < 3; ++i) {
      if (std::abs(e_p(i)) < config_.integral_zone_m || std::abs(e_v(i)) < config_.integral_zone_mps) integral_(i) += dt_s * ki(i) * e_p(i);
    }
    const double lim = config_.integral_limit_mps2;
    integral_ = integral_.cwiseMax(Eigen::Vector3d::Constant(-lim)).cwiseMin(Eigen::Vector3d::Constant(lim));
  }
  a_des = ref.a_world + kp.cwiseProduct(e_p) + kd.cwiseProduct(e_v) + integral_;
  if (a_des.norm() > config_.max_accel_mps2) a_des *= config_.max_accel_mps2 / a_des.norm();
  // Drag compensation at the reference velocity (the wind is unknown: the I-term takes it).
  const Eigen::Vector3d drag_comp =
      (plant_.drag_linear_ns_per_m + plant_.drag_quadratic_ns2_per_m2 * ref.v_world.norm()) * ref.v_world /
      plant_.mass_kg;

  MultirotorCommand cmd;
  cmd.thrust_accel_world = a_des + Eigen::Vector3d(0.0, 0.0, kGravityMps2) + drag_comp;
  cmd.heading_rate_rps = heading_rate_ff + config_.k_heading * common::wrapAngle(ref.heading_rad - est.heading_rad);
  cmd.pitch_rate_rps = pitch_rate_ff + config_.k_pitch * (ref.pitch_rad - est.pitch_rad);
  return cmd;
}

}  // namespace gesture_formation::sim

#include "gesture_formation/sim/multirotor.hpp"

#include <algorithm>
#include <cmath>

#include "gesture_formation/common/angles.hpp"

namespace gesture_formation::sim {

const common::FieldTable<MultirotorParams>& multirotorParamsFields() {
  using common::Range;
  using C = MultirotorParams;
  static const common::FieldTable<C> t{{
      {"mass_kg", Range::positive(), [](C& c) { return &c.mass_kg; }},
      {"max_thrust_to_weight", Range{1.0, 10.0, false, true}, [](C& c) { return &c.max_thrust_to_weight; }},
      {"min_thrust_to_weight", Range{0.0, 1.0, true, false}, [](C& c) { return &c.min_thrust_to_weight; }},
      {"max_tilt_deg", Range::openClosed(0.0, 80.0), [](C& c) { return &c.max_tilt_deg; }},
      {"attitude_time_constant_s", Range::positive(), [](C& c) { return &c.attitude_time_constant_s; }},
      {"drag_linear_ns_per_m", Range::nonNegative(), [](C& c) { return &c.drag_linear_ns_per_m; }},
      {"drag_quadratic_ns2_per_m2", Range::nonNegative(), [](C& c) { return &c.drag_quadratic_ns2_per_m2; }},
      {"max_yaw_rate_dps", Range::positive(), [](C& c) { return &c.max_yaw_rate_dps; }},
      {"max_pitch_rate_dps", Range::positive(), [](C& c) { return &c.max_pitch_rate_dps; }},
      {"min_pitch_deg", Range::closed(-90.0, 90.0), [](C& c) { return &c.min_pitch_deg; }},
      {"max_pitch_deg", Range::closed(-90.0, 90.0), [](C& c) { return &c.max_pitch_deg; }},
      {"body_radius_m", Range::positive(), [](C& c) { return &c.body_radius_m; }},
  }};
  return t;
}

std::vector<std::string> MultirotorParams::validate(const std::string& prefix) const {
  auto e = multirotorParamsFields().rangeProblems(*this);
  common::checkRule(e, min_pitch_deg < max_pitch_deg, "min_pitch_deg", min_pitch_deg, "must be < max_pitch_deg");
  return common::problemLines(e, prefix);
}

Multirotor::Multirotor(const MultirotorParams& params, const MultirotorState& initial)
    : params_(params), state_(initial) {}

Eigen::Vector3d Multirotor::limitThrust(const Eigen::Vector3d& a_cmd) const {
  const double g = kGravityMps2;
  const double t_max = params_.max_thrust_to_weight * g;
  const double t_min = params_.min_thrust_to_weight * g;
  const double tan_tilt = std::tan(common::degToRad(params_.max_tilt_deg));
  Eigen::Vector3d a = a_cmd.allFinite() ? a_cmd : Eigen::Vector3d(0.0, 0.0, g);
  // Vertical part first: within [t_min, t_max] (never pointing down).
  a.z() = std::clamp(a.z(), std::max(t_min, 1e-3), t_max);
  // Tilt: |horizontal| ≤ z tan(tilt).
  Eigen::Vector2d h = a.head<2>();
  const double h_max_tilt = a.z() * tan_tilt;
  const double h_max_thrust = std::sqrt(std::max(0.0, t_max * t_max - a.z() * a.z()));
  const double h_max = std::min(h_max_tilt, h_max_thrust);
  if (h.norm() > h_max) h *= h_max / h.norm();
  a.head<2>() = h;
  return a;
}

void Multirotor::step(double dt_s, const MultirotorCommand& cmd, const Eigen::Vector3d& wind_world_mps,
                      double ground_height_m) {
  if (!(dt_s > 0.0)) return;
  const Eigen::Vector3d target = limitThrust(cmd.thrust_accel_world);
  const double alpha = 1.0 - std::exp(-dt_s / params_.attitude_time_constant_s);
  state_.thrust_accel_world += alpha * (target - state_.thrust_accel_world);
  // The lag interpolates between two admissible vectors; re-limit against rounding.
  state_.thrust_accel_world = limitThrust(state_.thrust_accel_world);

  const Eigen::Vector3d v_rel = state_.v_world - wind_world_mps;
  const Eigen::Vector3d drag =
      -(params_.drag_linear_ns_per_m + params_.drag_quadratic_ns2_per_m2 * v_rel.norm()) * v_rel / params_.mass_kg;
  Eigen::Vector3d a = state_.thrust_accel_world - Eigen::Vector3d(0.0, 0.0, kGravityMps2) + drag;
  state_.v_world += dt_s * a;
  state_.p_world += dt_s * state_.v_world;
  if (state_.p_world.z() < ground_height_m) {  // the ground is a floor
    state_.p_world.z() = ground_height_m;
    if (state_.v_world.z() < 0.0) {
      a.z() -= state_.v_world.z() / dt_s;
      state_.v_world.z() = 0.0;
    }
  }
  state_.a_world = a;

  const double max_yaw = common::degToRad(params_.max_yaw_rate_dps);
  const double max_pitch_rate = common::degToRad(params_.max_pitch_rate_dps);
  const double yaw_rate = std::clamp(std::isfinite(cmd.heading_rate_rps) ? cmd.heading_rate_rps : 0.0, -max_yaw, max_yaw);
  const double pitch_rate =
      std::clamp(std::isfinite(cmd.pitch_rate_rps) ? cmd.pitch_rate_rps : 0.0, -max_pitch_rate, max_pitch_rate);
  state_.heading_rad = common::wrapAngle(state_.heading_rad + dt_s * yaw_rate);
  state_.pitch_rad = std::clamp(state_.pitch_rad + dt_s * pitch_rate, common::degToRad(params_.min_pitch_deg),
                                common::degToRad(params_.max_pitch_deg));
}

double Multirotor::tiltRad() const {
  const Eigen::Vector3d& a = state_.thrust_accel_world;
  return std::atan2(a.head<2>().norm(), a.z());
}

}  // namespace gesture_formation::sim

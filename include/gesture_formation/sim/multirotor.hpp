#pragma once
/// \file
/// \brief Point-mass multirotor plant (docs/design.md §5): total thrust along the body z axis with
/// thrust and tilt limits, a first-order attitude (thrust-vector) response, linear and
/// quadratic drag relative to the wind, and a camera whose heading (the UAV's yaw) and pitch
/// (a gimbal) follow rate commands within rate and pitch limits.
///
///   a_thrust' = (a_cmd,limited − a_thrust) / τ_att          (first-order attitude response)
///   v'        = a_thrust − g ẑ − (c_lin v_rel + c_quad |v_rel| v_rel) / m,  v_rel = v − w
///   p'        = v
///
/// `a_cmd` is the commanded specific thrust (thrust / mass, world frame, includes gravity
/// compensation): its tilt from ẑ is limited to `max_tilt_deg` and its magnitude to
/// [min_thrust_to_weight, max_thrust_to_weight]·g, keeping the vertical part first.
/// Integration: semi-implicit Euler with the caller's step (the runner uses 10 ms).
/// World frame ENU (docs/conventions.md); the ground z = `ground_height_m` is a floor.
/// Thread safety: value type.

#include <string>
#include <vector>

#include <Eigen/Core>
#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::sim {

constexpr double kGravityMps2 = 9.80665;

/// \brief Physical parameters of one UAV. Physical limits have no silent defaults in the
/// mission file (every key is required there); the defaults below document an F450-class UAV.
struct MultirotorParams {
  double mass_kg = 1.6;                  ///< > 0
  double max_thrust_to_weight = 2.2;     ///< > 1
  double min_thrust_to_weight = 0.15;    ///< [0, 1)
  double max_tilt_deg = 35.0;            ///< (0, 80]
  double attitude_time_constant_s = 0.12;  ///< τ_att, > 0
  double drag_linear_ns_per_m = 0.25;    ///< c_lin [N s/m], ≥ 0
  double drag_quadratic_ns2_per_m2 = 0.04;  ///< c_quad [N s²/m²], ≥ 0
  double max_yaw_rate_dps = 90.0;        ///< camera heading rate limit [deg/s], > 0
  double max_pitch_rate_dps = 60.0;      ///< gimbal pitch rate limit [deg/s], > 0
  double min_pitch_deg = -90.0;          ///< gimbal range [deg]
  double max_pitch_deg = 30.0;
  double body_radius_m = 0.35;           ///< sphere enclosing the frame and props (collisions), > 0

  /// \brief Every problem, each naming the field (prefixed by `prefix`) and value.
  std::vector<std::string> validate(const std::string& prefix = "") const;
};

/// \brief The one range of each number of MultirotorParams: the plant (mission.uavs[i].plant; every key required).
const common::FieldTable<MultirotorParams>& multirotorParamsFields();

/// \brief True state of one UAV.
struct MultirotorState {
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();
  /// Actual specific thrust (world frame, m/s²); its direction is the body z axis.
  Eigen::Vector3d thrust_accel_world = Eigen::Vector3d(0.0, 0.0, kGravityMps2);
  Eigen::Vector3d a_world = Eigen::Vector3d::Zero();  ///< acceleration of the last step
  double heading_rad = 0.0;  ///< camera heading φ (−π, π]
  double pitch_rad = 0.0;    ///< camera pitch ξ
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief What the controller commands.
struct MultirotorCommand {
  Eigen::Vector3d thrust_accel_world = Eigen::Vector3d(0.0, 0.0, kGravityMps2);  ///< specific thrust [m/s²]
  double heading_rate_rps = 0.0;
  double pitch_rate_rps = 0.0;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The plant. Construct with valid params (MultirotorParams::validate() empty).
class Multirotor {
 public:
  Multirotor(const MultirotorParams& params, const MultirotorState& initial);

  /// \brief The specific thrust the plant can produce closest to `a_cmd` (tilt, then
  /// magnitude limits; the vertical part is kept first).
  Eigen::Vector3d limitThrust(const Eigen::Vector3d& a_cmd) const;

  /// \brief Advances by `dt_s` (> 0) with `cmd` in the wind `wind_world_mps`.
  void step(double dt_s, const MultirotorCommand& cmd, const Eigen::Vector3d& wind_world_mps,
            double ground_height_m = 0.0);

  const MultirotorState& state() const { return state_; }
  const MultirotorParams& params() const { return params_; }
  /// \brief Tilt of the body z axis from the world z axis [rad].
  double tiltRad() const;

 private:
  MultirotorParams params_;
  MultirotorState state_;
};

}  // namespace gesture_formation::sim

#pragma once
/// \file
/// \brief Noisy odometry of one UAV: the true state plus white Gaussian noise and a slowly
/// drifting position bias (first-order Gauss–Markov). What the controller, the planner
/// and the leader's camera pose (for the estimator) use. Thread safety: none.

#include <random>
#include <string>
#include <vector>

#include "gesture_formation/sim/multirotor.hpp"
#include "gesture_formation/sim/tracking_controller.hpp"
#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::sim {

struct OdometryConfig {
  double position_noise_m = 0.03;     ///< white σ per axis [m], ≥ 0
  double velocity_noise_mps = 0.05;   ///< white σ per axis [m/s], ≥ 0
  double heading_noise_deg = 0.5;     ///< ≥ 0
  double pitch_noise_deg = 0.2;       ///< ≥ 0
  double bias_std_m = 0.05;           ///< stationary σ of the position bias per axis [m], ≥ 0
  double bias_time_constant_s = 30.0;  ///< > 0

  std::vector<std::string> validate(const std::string& prefix = "") const;
};

/// \brief The one range of each number of OdometryConfig: mission.odometry.
const common::FieldTable<OdometryConfig>& odometryConfigFields();

class Odometry {
 public:
  Odometry(const OdometryConfig& config, std::mt19937_64 rng);
  /// \brief Advances the bias by `dt_s` and returns the measured state.
  EstimatedState measure(const MultirotorState& truth, double dt_s);

 private:
  OdometryConfig config_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> n01_{0.0, 1.0};
  Eigen::Vector3d bias_ = Eigen::Vector3d::Zero();
};

}  // namespace gesture_formation::sim

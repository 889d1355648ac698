#pragma once
/// \file
/// \brief Wind: a mean vector, turbulence as a first-order Gauss–Markov (Ornstein–Uhlenbeck)
/// process per axis, and discrete "1 − cos" gusts arriving as a Poisson process.
/// One field shared by all UAVs (the site is small against the wind's correlation length).
/// Deterministic for its RNG. Thread safety: none.

#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>
#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::sim {

struct WindConfig {
  Eigen::Vector3d mean_mps = Eigen::Vector3d::Zero();  ///< steady wind (world) [m/s]
  double turbulence_std_mps = 0.0;       ///< stationary σ of each horizontal axis [m/s], ≥ 0 (vertical: half)
  double turbulence_time_constant_s = 3.0;  ///< correlation time [s], > 0
  double gusts_per_minute = 0.0;         ///< Poisson rate of discrete gusts, ≥ 0
  double gust_peak_mps = 0.0;            ///< peak speed of a gust [m/s], ≥ 0 (horizontal, random direction)
  double gust_duration_s = 4.0;          ///< > 0

  std::vector<std::string> validate(const std::string& prefix = "") const;
};

/// \brief The one range of each number of WindConfig: mission.wind and mission.faults.wind (mean_mps: any finite vector).
const common::FieldTable<WindConfig>& windConfigFields();

class WindModel {
 public:
  WindModel(const WindConfig& config, std::mt19937_64 rng);
  /// \brief Advances to `t_s` by `dt_s` and returns the wind (world, m/s).
  Eigen::Vector3d step(double t_s, double dt_s);
  const Eigen::Vector3d& current() const { return current_; }

 private:
  WindConfig config_;
  std::mt19937_64 rng_;
  Eigen::Vector3d turbulence_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d current_ = Eigen::Vector3d::Zero();
  double next_gust_s_ = 0.0;
  double gust_start_s_ = -1e9;
  Eigen::Vector3d gust_dir_ = Eigen::Vector3d::UnitX();
};

/// \brief Stands in for the flight stack's wind estimate (PX4's EKF2 wind states, published
/// by mavros as `wind_estimation`; they converge over seconds): the wind at the UAV low-passed
/// with `time_constant_s`, starting at the first sample; NaN before it.
class WindEstimate {
 public:
  static constexpr double kDefaultTimeConstantS = 2.0;
  explicit WindEstimate(double time_constant_s = kDefaultTimeConstantS) : tau_s_(time_constant_s) {}
  /// \brief Advances by `dt_s` (≥ 0) towards the wind `wind_mps` and returns the estimate.
  const Eigen::Vector3d& update(const Eigen::Vector3d& wind_mps, double dt_s) {
    if (!value_.allFinite()) {
      value_ = wind_mps;
    } else {
      value_ += (wind_mps - value_) * (1.0 - std::exp(-dt_s / tau_s_));
    }
    return value_;
  }
  const Eigen::Vector3d& value() const { return value_; }

 private:
  double tau_s_;
  Eigen::Vector3d value_ = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

}  // namespace gesture_formation::sim

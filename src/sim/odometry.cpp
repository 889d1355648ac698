#include "gesture_formation/sim/odometry.hpp"

#include <cmath>

#include "gesture_formation/common/angles.hpp"

namespace gesture_formation::sim {

const common::FieldTable<OdometryConfig>& odometryConfigFields() {
  using common::Range;
  using C = OdometryConfig;
  static const common::FieldTable<C> t{{
      {"position_noise_m", Range::nonNegative(), [](C& c) { return &c.position_noise_m; }},
      {"velocity_noise_mps", Range::nonNegative(), [](C& c) { return &c.velocity_noise_mps; }},
      {"heading_noise_deg", Range::nonNegative(), [](C& c) { return &c.heading_noise_deg; }},
      {"pitch_noise_deg", Range::nonNegative(), [](C& c) { return &c.pitch_noise_deg; }},
      {"bias_std_m", Range::nonNegative(), [](C& c) { return &c.bias_std_m; }},
      {"bias_time_constant_s", Range::positive(), [](C& c) { return &c.bias_time_constant_s; }},
  }};
  return t;
}

std::vector<std::string> OdometryConfig::validate(const std::string& prefix) const {
  return common::problemLines(odometryConfigFields().rangeProblems(*this), prefix);
}

Odometry::Odometry(const OdometryConfig& config, std::mt19937_64 rng) : config_(config), rng_(std::move(rng)) {
  const double s = config_.bias_std_m;
  bias_ = Eigen::Vector3d(s * n01_(rng_), s * n01_(rng_), s * n01_(rng_));
}

EstimatedState Odometry::measure(const MultirotorState& truth, double dt_s) {
  if (dt_s > 0.0) {
    const double phi = std::exp(-dt_s / config_.bias_time_constant_s);
    const double k = config_.bias_std_m * std::sqrt(std::max(0.0, 1.0 - phi * phi));
    for (int i = 0; i < 3; ++i) bias_(i) = phi * bias_(i) + k * n01_(rng_);
  }
  EstimatedState e;
  const double sp = config_.position_noise_m, sv = config_.velocity_noise_mps;
  e.p_world = truth.p_world + bias_ + sp * Eigen::Vector3d(n01_(rng_), n01_(rng_), n01_(rng_));
  e.v_world = truth.v_world + sv * Eigen::Vector3d(n01_(rng_), n01_(rng_), n01_(rng_));
  e.heading_rad = common::wrapAngle(truth.heading_rad + common::degToRad(config_.heading_noise_deg) * n01_(rng_));
  e.pitch_rad = truth.pitch_rad + common::degToRad(config_.pitch_noise_deg) * n01_(rng_);
  return e;
}

}  // namespace gesture_formation::sim

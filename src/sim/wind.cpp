#include "gesture_formation/sim/wind.hpp"

#include <cmath>
#include <limits>

#include "gesture_formation/common/angles.hpp"

namespace gesture_formation::sim {

const common::FieldTable<WindConfig>& windConfigFields() {
  using common::Range;
  using C = WindConfig;
  static const common::FieldTable<C> t{{
      {"turbulence_std_mps", Range::nonNegative(), [](C& c) { return &c.turbulence_std_mps; }},
      {"turbulence_time_constant_s", Range::positive(), [](C& c) { return &c.turbulence_time_constant_s; }},
      {"gusts_per_minute", Range::nonNegative(), [](C& c) { return &c.gusts_per_minute; }},
      {"gust_peak_mps", Range::nonNegative(), [](C& c) { return &c.gust_peak_mps; }},
      {"gust_duration_s", Range::positive(), [](C& c) { return &c.gust_duration_s; }},
  }};
  return t;
}

std::vector<std::string> WindConfig::validate(const std::string& prefix) const {
  std::vector<std::string> e;
  if (!mean_mps.allFinite()) e.push_back(prefix + "mean_mps must be finite");
  for (auto& line : common::problemLines(windConfigFields().rangeProblems(*this), prefix)) e.push_back(std::move(line));
  return e;
}

WindModel::WindModel(const WindConfig& config, std::mt19937_64 rng) : config_(config), rng_(std::move(rng)) {
  std::normal_distribution<double> n01(0.0, 1.0);
  const double s = config_.turbulence_std_mps;
  turbulence_ = Eigen::Vector3d(s * n01(rng_), s * n01(rng_), 0.5 * s * n01(rng_));
  if (config_.gusts_per_minute > 0.0) {
    std::exponential_distribution<double> wait(config_.gusts_per_minute / 60.0);
    next_gust_s_ = wait(rng_);
  } else {
    next_gust_s_ = std::numeric_limits<double>::infinity();
  }
  current_ = config_.mean_mps + turbulence_;
}

Eigen::Vector3d WindModel::step(double t_s, double dt_s) {
  std::normal_distribution<double> n01(0.0, 1.0);
  // Exact discretisation of the OU process: x ← φ x + σ sqrt(1 − φ²) n.
  const double phi = std::exp(-dt_s / config_.turbulence_time_constant_s);
  const double k = std::sqrt(std::max(0.0, 1.0 - phi * phi));
  const double s = config_.turbulence_std_mps;
  turbulence_.x() = phi * turbulence_.x() + s * k * n01(rng_);
  turbulence_.y() = phi * turbulence_.y() + s * k * n01(rng_);
  turbulence_.z() = phi * turbulence_.z() + 0.5 * s * k * n01(rng_);
  if (t_s >= next_gust_s_) {
    gust_start_s_ = next_gust_s_;
    std::uniform_real_distribution<double> dir(-common::kPi, common::kPi);
    const double a = dir(rng_);
    gust_dir_ = Eigen::Vector3d(std::cos(a), std::sin(a), 0.0);
    std::exponential_distribution<double> wait(config_.gusts_per_minute / 60.0);
    next_gust_s_ = gust_start_s_ + config_.gust_duration_s + wait(rng_);
  }
  Eigen::Vector3d gust = Eigen::Vector3d::Zero();
  const double tau = t_s - gust_start_s_;
  if (tau >= 0.0 && tau <= config_.gust_duration_s) {
    gust = config_.gust_peak_mps * 0.5 * (1.0 - std::cos(2.0 * common::kPi * tau / config_.gust_duration_s)) * gust_dir_;
  }
  current_ = config_.mean_mps + turbulence_ + gust;
  return current_;
}

}  // namespace gesture_formation::sim

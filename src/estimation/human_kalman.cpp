#include "gesture_formation/estimation/human_kalman.hpp"

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::estimation {

using common::Range;

const common::FieldTable<HumanKalmanConfig>& humanKalmanFields() {
  using C = HumanKalmanConfig;
  static const common::FieldTable<HumanKalmanConfig> t{{
      {"process_noise.sigma_p_m", Range::positive(), [](C& c) { return &c.sigma_p_m; }},
      {"process_noise.sigma_v_mps", Range::positive(), [](C& c) { return &c.sigma_v_mps; }},
      {"process_noise.reference_period_s", Range::closed(0.0, 10.0), [](C& c) { return &c.reference_period_s; }},
      {"initial_velocity_std_mps", Range::positive(), [](C& c) { return &c.initial_velocity_std_mps; }},
      {"gate_chi2", Range::positive(), [](C& c) { return &c.gate_chi2; }},
      {"max_consecutive_rejections", Range::atLeast(1), [](C& c) { return &c.max_consecutive_rejections; }},
      {"lost_timeout_s", Range::positive(), [](C& c) { return &c.lost_timeout_s; }},
      {"confirm_measurements", Range::atLeast(1), [](C& c) { return &c.confirm_measurements; }},
  }};
  return t;
}

std::vector<std::string> HumanKalmanConfig::validate() const {
  return common::problemLines(humanKalmanFields().rangeProblems(*this));
}

}  // namespace gesture_formation::estimation

#include "gesture_formation/formation/formation_params.hpp"

#include <cmath>
#include <sstream>

#include "gesture_formation/common/format_number.hpp"

namespace gesture_formation::formation {

std::string uavLabel(UavIndex uav) { return uav == kLeader ? std::string("L") : std::to_string(uav); }

double wrapDeg(double angle_deg) {
  if (!std::isfinite(angle_deg)) return angle_deg;
  double w = std::remainder(angle_deg, 360.0);  // exact, in [−180, 180]
  if (w <= -180.0) w += 360.0;
  return w;
}

double elevationDeg(const FormationParams& params, UavIndex uav) {
  return uav == kLeader ? params.leader.gamma_deg : params.leader.gamma_deg + params.uav(uav).gamma_deg;
}

const common::FieldTable<FormationLimits>& formationLimitsFields() {
  using C = FormationLimits;
  using common::Range;
  static const common::FieldTable<FormationLimits> t{{
      {"limits.gamma_min_deg", Range{-90.0, 90.0, false, false}, [](C& c) { return &c.gamma_min_deg; }},
      {"limits.gamma_max_deg", Range{-90.0, 90.0, false, false}, [](C& c) { return &c.gamma_max_deg; }},
      {"limits.distance_min_m", Range::positive(), [](C& c) { return &c.distance_min_m; }},
      {"limits.distance_max_m", Range::positive(), [](C& c) { return &c.distance_max_m; }},
      {"limits.safety_distance_m", Range::positive(), [](C& c) { return &c.safety_distance_m; }},
  }};
  return t;
}

const common::FieldTable<UavObservation>& uavObservationFields() {
  using C = UavObservation;
  using common::Range;
  static const common::FieldTable<UavObservation> t{{
      {"beta_deg", Range::openClosed(-180.0, 180.0), [](C& c) { return &c.beta_deg; }},
      {"gamma_deg", Range::openClosed(-90.0, 90.0), [](C& c) { return &c.gamma_deg; }},
      {"distance_m", Range::positive(), [](C& c) { return &c.distance_m; }},
  }};
  return t;
}

std::vector<common::ConfigError> FormationLimits::problems() const {
  std::vector<common::ConfigError> e = formationLimitsFields().rangeProblems(*this);
  const auto n = [](double v) { return common::formatNumber(v); };
  common::checkRule(e, gamma_max_deg >= gamma_min_deg, "limits.gamma_max_deg", gamma_max_deg,
                    "must be >= limits.gamma_min_deg (" + n(gamma_min_deg) + ")");
  common::checkRule(e, distance_min_m >= safety_distance_m, "limits.distance_min_m", distance_min_m,
                    "must be >= limits.safety_distance_m (" + n(safety_distance_m) + ")");
  common::checkRule(e, distance_max_m > distance_min_m, "limits.distance_max_m", distance_max_m,
                    "must be > limits.distance_min_m (" + n(distance_min_m) + ")");
  formationLimitsFields().sortByTableOrder(e);
  return e;
}

std::vector<std::string> FormationLimits::validate() const { return common::problemLines(problems()); }

namespace {

/// The elevation and distance of UAV `u` within `limits` (its own ranges were checked before).
void uavLimitProblems(const FormationParams& params, const FormationLimits& limits, UavIndex u, const std::string& key,
                      std::vector<common::ConfigError>& e) {
  const UavObservation& o = params.uav(u);
  const auto n = [](double v) { return common::formatNumber(v); };
  if (std::isfinite(o.gamma_deg) && std::isfinite(params.leader.gamma_deg)) {
    const double el = elevationDeg(params, u);
    // Tolerance: a clamped leader γ_L = gamma_min_deg − γ_i may miss the bound by an ulp.
    constexpr double kTolDeg = 1e-9;
    if (el < limits.gamma_min_deg - kTolDeg || el > limits.gamma_max_deg + kTolDeg) {
      const std::string range = "[" + n(limits.gamma_min_deg) + ", " + n(limits.gamma_max_deg) + "]";
      if (u == kLeader) {
        e.push_back({key + ".gamma_deg", n(o.gamma_deg) + " is out of range " + range + " (limits.gamma_min_deg/gamma_max_deg)"});
      } else {
        e.push_back({key + ".gamma_deg", n(o.gamma_deg) + ": the follower's elevation leader.gamma_deg + gamma_deg = " +
                                             n(el) + " is out of range " + range + " (limits.gamma_min_deg/gamma_max_deg)"});
      }
    }
  }
  if (std::isfinite(o.distance_m) && (o.distance_m < limits.distanceFloorM() || o.distance_m > limits.distance_max_m)) {
    e.push_back({key + ".distance_m", n(o.distance_m) + " is out of range [" + n(limits.distanceFloorM()) + ", " +
                                          n(limits.distance_max_m) + "] (limits.distance_min_m, safety_distance_m, distance_max_m)"});
  }
}

}  // namespace

std::vector<common::ConfigError> paramsProblems(const FormationParams& params, const FormationLimits& limits) {
  std::vector<common::ConfigError> e;
  for (UavIndex u = 0; u < params.uavCount(); ++u) {
    const std::string key = u == kLeader ? std::string("leader") : "followers[" + std::to_string(u - 1) + "]";
    for (auto& p : uavObservationFields().rangeProblems(params.uav(u))) e.push_back({key + "." + p.key, p.message});
    uavLimitProblems(params, limits, u, key, e);
  }
  return e;
}

std::vector<std::string> validateParams(const FormationParams& params, const FormationLimits& limits) {
  return common::problemLines(paramsProblems(params, limits));
}

}  // namespace gesture_formation::formation

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

std::vector<std::string> FormationLimits::validate() const {
  std::vector<std::string> e;
  auto finite = [&](double v, const char* name) {
    if (!std::isfinite(v)) e.push_back(std::string("limits.") + name + " must be finite, got " + common::formatNumber(v));
    return std::isfinite(v);
  };
  const bool g_ok = finite(gamma_min_deg, "gamma_min_deg") & finite(gamma_max_deg, "gamma_max_deg");
  const bool d_ok = finite(distance_min_m, "distance_min_m") & finite(distance_max_m, "distance_max_m") &
                    finite(safety_distance_m, "safety_distance_m");
  if (g_ok) {
    if (!(gamma_min_deg > -90.0)) e.push_back("limits.gamma_min_deg must be > -90, got " + common::formatNumber(gamma_min_deg));
    if (!(gamma_max_deg < 90.0)) e.push_back("limits.gamma_max_deg must be < 90, got " + common::formatNumber(gamma_max_deg));
    if (!(gamma_min_deg <= gamma_max_deg)) {
      e.push_back("limits.gamma_max_deg must be >= limits.gamma_min_deg (" + common::formatNumber(gamma_min_deg) + "), got " +
                  common::formatNumber(gamma_max_deg));
    }
  }
  if (d_ok) {
    if (!(safety_distance_m > 0.0)) e.push_back("limits.safety_distance_m must be > 0, got " + common::formatNumber(safety_distance_m));
    if (!(distance_min_m >= safety_distance_m)) {
      e.push_back("limits.distance_min_m must be >= limits.safety_distance_m (" + common::formatNumber(safety_distance_m) + "), got " +
                  common::formatNumber(distance_min_m));
    }
    if (!(distance_max_m > distance_min_m)) {
      e.push_back("limits.distance_max_m must be > limits.distance_min_m (" + common::formatNumber(distance_min_m) + "), got " +
                  common::formatNumber(distance_max_m));
    }
  }
  return e;
}

std::vector<std::string> validateParams(const FormationParams& params, const FormationLimits& limits) {
  std::vector<std::string> e;
  for (UavIndex u = 0; u < params.uavCount(); ++u) {
    const UavObservation& o = params.uav(u);
    const std::string key = u == kLeader ? std::string("leader") : "followers[" + std::to_string(u - 1) + "]";
    if (!std::isfinite(o.beta_deg)) e.push_back(key + ".beta_deg must be finite, got " + common::formatNumber(o.beta_deg));
    if (!std::isfinite(o.gamma_deg)) {
      e.push_back(key + ".gamma_deg must be finite, got " + common::formatNumber(o.gamma_deg));
    } else if (std::isfinite(params.leader.gamma_deg)) {
      const double el = elevationDeg(params, u);
      // Tolerance: a clamped leader γ_L = gamma_min_deg − γ_i may miss the bound by an ulp.
      constexpr double kTolDeg = 1e-9;
      if (el < limits.gamma_min_deg - kTolDeg || el > limits.gamma_max_deg + kTolDeg) {
        const std::string range = "[" + common::formatNumber(limits.gamma_min_deg) + ", " + common::formatNumber(limits.gamma_max_deg) + "]";
        if (u == kLeader) {
          e.push_back(key + ".gamma_deg " + common::formatNumber(o.gamma_deg) + " is out of range " + range +
                      " (limits.gamma_min_deg/gamma_max_deg)");
        } else {
          e.push_back(key + ".gamma_deg " + common::formatNumber(o.gamma_deg) + ": the follower's elevation leader.gamma_deg + gamma_deg = " +
                      common::formatNumber(el) + " is out of range " + range + " (limits.gamma_min_deg/gamma_max_deg)");
        }
      }
    }
    if (!std::isfinite(o.distance_m)) {
      e.push_back(key + ".distance_m must be finite, got " + common::formatNumber(o.distance_m));
    } else if (o.distance_m < limits.distanceFloorM() || o.distance_m > limits.distance_max_m) {
      e.push_back(key + ".distance_m " + common::formatNumber(o.distance_m) + " is out of range [" + common::formatNumber(limits.distanceFloorM()) + ", " +
                  common::formatNumber(limits.distance_max_m) + "] (limits.distance_min_m, safety_distance_m, distance_max_m)");
    }
  }
  return e;
}

}  // namespace gesture_formation::formation

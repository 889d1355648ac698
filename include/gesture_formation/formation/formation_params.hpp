#pragma once
/// \file
/// \brief Adaptive parameters of the formation (paper: "Formation control", Table II;
/// docs/design.md §4) and the limits every command is clamped to (docs/formation.md §3).
///
/// Every UAV has an observation heading β, an observation pitch γ and a distance d. The
/// leader's β and γ are relative to the worker's heading ^Hφ and the horizontal plane; a
/// follower's are relative to the leader's camera heading ^Lφ and pitch ^Lξ. Angles are
/// stored in degrees (the unit of configuration and commands, so that increments such as
/// +30° are exact); the geometry converts to radians.
///
/// UAV indices: 0 = leader (CSV label "L"), i ≥ 1 = follower i (CSV label "i"; YAML list
/// entry `followers[i-1]`).

#include <cstddef>
#include <string>
#include <vector>

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::formation {

/// \brief Index of a UAV in the formation: 0 = leader, i ≥ 1 = follower i.
using UavIndex = int;
constexpr UavIndex kLeader = 0;

/// \brief "L" for the leader, "1", "2", … for the followers (the CSV labels of design.md §8.2).
std::string uavLabel(UavIndex uav);

/// \brief Wraps an angle in degrees to (−180, 180]. Non-finite input is returned unchanged.
/// Exact for integer-degree arithmetic (uses std::remainder).
double wrapDeg(double angle_deg);

/// \brief Observation parameters of one UAV (docs/design.md §4).
struct UavObservation {
  double beta_deg = 0.0;    ///< observation heading β [deg], wrapped to (−180, 180]
  double gamma_deg = 0.0;   ///< observation pitch γ [deg]; positive = UAV above its reference
  double distance_m = 8.0;  ///< distance d to the worker [m]
};

/// \brief Parameters of the leader and any number of followers. Defaults: paper Table II.
struct FormationParams {
  UavObservation leader{90.0, 11.0, 10.0};                            ///< ^Lβ 90°, ^Lγ 11°, ^Ld 10 m
  std::vector<UavObservation> followers{{60.0, 0.0, 8.0}, {-60.0, 0.0, 8.0}};  ///< followers 1, 2

  /// \brief 1 + number of followers.
  int uavCount() const { return 1 + static_cast<int>(followers.size()); }
  bool hasUav(UavIndex uav) const { return uav >= 0 && uav < uavCount(); }
  /// \brief The parameters of UAV `uav` (precondition: hasUav(uav)).
  const UavObservation& uav(UavIndex uav) const {
    return uav == kLeader ? leader : followers[static_cast<std::size_t>(uav - 1)];
  }
  UavObservation& uav(UavIndex uav) {
    return uav == kLeader ? leader : followers[static_cast<std::size_t>(uav - 1)];
  }
};

/// \brief The physical elevation of UAV `uav` above the worker [deg]: the leader's γ_L, and
/// for follower i γ_L + γ_i (the follower's pitch is relative to the leader's, eq.
/// follower_ref: its unit vector to the worker has elevation ξ_L − γ_i = −(γ_L + γ_i)).
double elevationDeg(const FormationParams& params, UavIndex uav);

/// \brief Limits of the adaptive parameters (docs/formation.md §3). Defaults documented per
/// field; `validate()` names the offending field (YAML key under `limits.`).
///
/// Rules enforced on every UAV (config values outside → error; commands → clamped):
/// - distance d ∈ [distance_min_m, distance_max_m], and distance_min_m ≥ safety_distance_m.
///   Each reference lies at exactly d from the worker (leader and followers alike: a
///   follower's position is relative to the worker, not to the leader), so d ≥ Γ is the
///   whole "no reference closer to the worker than Γ" rule.
/// - elevation (leader γ_L; follower γ_L + γ_i) ∈ [gamma_min_deg, gamma_max_deg] ⊂ (−90, 90):
///   a follower's γ is relative to the leader's pitch, so a leader γ command moves every
///   follower up or down too; without this rule a follower could be carried over the
///   worker's head (elevation ≥ 90°), where its horizontal offset flips sign.
/// - β is wrapped to (−180, 180], never clamped.
struct FormationLimits {
  double gamma_min_deg = -30.0;    ///< lowest elevation of any UAV above the worker [deg], > −90
  double gamma_max_deg = 60.0;     ///< highest elevation of any UAV above the worker [deg], < 90
  double distance_min_m = 4.0;     ///< smallest d of any UAV [m], ≥ safety_distance_m
  double distance_max_m = 25.0;    ///< largest d of any UAV [m], > distance_min_m
  double safety_distance_m = 2.5;  ///< Γ_dis (Table II): no reference closer to the worker [m], > 0

  /// \brief Every problem, each naming the key (`limits.<field>`); empty when valid.
  std::vector<std::string> validate() const;
  /// \brief The same problems, typed {key, message}.
  std::vector<common::ConfigError> problems() const;
  /// \brief Effective lower bound of d: max(distance_min_m, safety_distance_m).
  double distanceFloorM() const { return distance_min_m > safety_distance_m ? distance_min_m : safety_distance_m; }
};

/// \brief Every way `params` violates `limits`, each naming the YAML key
/// (`leader.gamma_deg`, `followers[1].distance_m`, …) with the value and the allowed range;
/// empty when valid. Non-finite values are errors. Elevations are checked to 1e-9 deg (a
/// leader γ clamped to gamma_min_deg − γ_i can miss the bound by one rounding).
std::vector<std::string> validateParams(const FormationParams& params, const FormationLimits& limits);
/// \brief The same problems, typed {key, message}.
std::vector<common::ConfigError> paramsProblems(const FormationParams& params, const FormationLimits& limits);

/// \brief FormationLimits' numbers (keys `limits.*`) with their ranges: the only place they are
/// written, used by validate() and by the YAML reader.
const common::FieldTable<FormationLimits>& formationLimitsFields();
/// \brief One UAV's numbers (keys `beta_deg` (−180, 180], `gamma_deg` (−90, 90], `distance_m` > 0,
/// relative to `leader.` / `followers[i].`); the limits above narrow γ and d further.
const common::FieldTable<UavObservation>& uavObservationFields();

}  // namespace gesture_formation::formation

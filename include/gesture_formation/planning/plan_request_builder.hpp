#pragma once
/// \file
/// \brief One UAV's planning request from what it knows (DESIGN §4; docs/safety.md §1): the
/// stage-1 reference (eq. leader_ref on the worker's predicted trajectory for the leader;
/// eq. follower_ref relative to the leader's received plan — ^Lφ, ^Lξ per step — for a
/// follower; or a given hold reference) and the other UAVs' plans it plans around. Shared by
/// the simulated UAVs of `gfctl simulate` (sim::runMission) and the FormationPlanner nodelet,
/// so that both apply one avoidance rule:
/// - a follower always avoids the leader's received plan;
/// - with AvoidanceRule::avoid_all_plans (mission `faults.avoid_all_plans`, default) every
///   UAV avoids every other UAV's last received plan;
/// - otherwise (the paper's priority rule) UAV i avoids the plans of followers j < i, and
///   those flagged fallback or silent for longer than max_plan_age_s (right of way);
/// - in hold, every received plan.
/// Plans are added in the order: the leader's, then followers 1, 2, … (the planner's input).
/// Thread safety: pure function.

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/formation/formation_params.hpp"
#include "gesture_formation/planning/uav_planner.hpp"

namespace gesture_formation::planning {

/// \brief A plan received from another UAV with its sender's fallback flag (the sender's
/// planner returned its previous plan / braking, or it holds).
struct ReceivedPlan {
  PlannedTrajectory plan;
  bool fallback = false;
};

/// \brief Which received follower plans a UAV plans around (see the file comment).
struct AvoidanceRule {
  bool avoid_all_plans = true;  ///< every other UAV's plan (mission faults.avoid_all_plans)
  double max_plan_age_s = 1.0;  ///< the priority rule: a UAV not heard from for this long has right of way, > 0
};

/// \brief What one replanning of UAV `uav_index` starts from.
struct PlanRequestInputs {
  int uav_index = 0;                 ///< 0 = leader, i = follower i (priority order)
  double t_s = 0.0;                  ///< now; sample 0 of the reference
  double dt_s = 0.2;                 ///< horizon step [s]
  UavKinematicState state;  ///< the UAV's current (estimated) state
  /// The flight stack's wind estimate (world, m/s; non-finite: none) — PlanRequest::wind_estimate_mps.
  Eigen::Vector3d wind_estimate_mps = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  formation::WorkerHorizon worker;    ///< the worker's predicted trajectory (its steps = the horizon's)
  const formation::FormationParams* params = nullptr;  ///< required: the formation's parameters
  /// Followers: the leader's last received plan (null or empty: none; the reference then
  /// uses the leader's desired heading and pitch).
  const PlannedTrajectory* leader_plan = nullptr;
  /// The plans received from the followers, indexed by sender (entries 0 and uav_index are
  /// ignored); may be null.
  const std::vector<std::optional<ReceivedPlan>>* received = nullptr;
  /// Non-null: the UAV holds — this is its reference, and it avoids every received plan.
  const formation::ReferenceTrajectory* hold_reference = nullptr;
  AvoidanceRule rule;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The request (see the file comment). Preconditions: params non-null with a
/// follower entry for uav_index; worker.steps() ≥ 1.
PlanRequest buildPlanRequest(const PlanRequestInputs& in);

// ---- hold (docs/safety.md §1 rules 2–4), shared by gfctl simulate and the FormationPlanner ----

/// \brief Age limits of the data a UAV plans from (mission `faults.*`; FormationPlanner params).
struct FreshnessLimits {
  double max_share_age_s = 2.0;   ///< a follower's leader share (worker state) since the leader sent it
  double max_worker_age_s = 3.0;  ///< the worker estimate since its last fused measurement
};

/// \brief Why UAV `uav_index` must hold at t_s (empty: it may track). The leader checks the age of
/// its estimate (worker_stamp_s = the last fused measurement); a follower first the age of the
/// leader's share (share_stamp_s = when the leader sent it), then of the estimate it carries.
/// Non-finite stamps count as infinitely old.
std::string holdReason(int uav_index, double t_s, double share_stamp_s, double worker_stamp_s,
                       const FreshnessLimits& limits);

/// \brief Where braking from velocity v at `brake_accel_mps2` ends: p + v|v|/(2a). A UAV entering
/// hold latches this point and holds it until it tracks again (docs/safety.md §1 rule 3).
Eigen::Vector3d brakingPoint(const Eigen::Vector3d& p_world, const Eigen::Vector3d& v_world, double brake_accel_mps2);

/// \brief The hold reference: every step at `hold_world`, camera heading and pitch towards
/// `worker_world` (the last known worker position; `heading_rad` when straight above/below).
formation::ReferenceTrajectory holdReference(const Eigen::Vector3d& hold_world, const Eigen::Vector3d& worker_world,
                                             double heading_rad, int steps);

}  // namespace gesture_formation::planning

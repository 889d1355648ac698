#pragma once
/// \file
/// \brief Verification of a planned trajectory before it may be executed (docs/planning.md
/// §7). The continuous trajectory is the cubic Hermite spline through the samples' p and v
/// (for the QP's constant-jerk output it is exactly the planned curve); it is evaluated at
/// `substeps` points per interval, sample times included, and every point must have:
///   - finite p, v, a, heading, pitch;
///   - no occupied voxel cube within clearance_m (distance field first — its value minus the
///     voxel half-diagonal is a lower bound of the distance to the cubes — and FCL's exact
///     ball/cube test where the field cannot decide);
///   - ‖v‖ ≤ max_speed, |v_z| ≤ max_vertical_speed, ‖a‖ ≤ max_acceleration, |a_z| ≤ max
///     vertical acceleration (relative tolerance), heading/pitch steps within their rate limits;
///   - distance ≥ uavKeepOutDistance(age) = Γ_dis + min(age_margin_speed·age, age_margin_max) to
///     every other plan at the same time, and ≥ Γ_dis
///     to the braking envelope (keptBrakeEnvelope()) of every other plan older than
///     brake_envelope_age_s and of every lower-priority UAV's plan (brake_envelope_lead_s);
///   - distance ≥ worker_safety_distance_m to the worker's predicted position;
///   - given a SeenSpace (online mapping): the seen-space rule (seen_space.hpp) — from every point
///     within SeenRule::horizon_s of the start, the braking path runs through observed space.
/// On the first interval [t0, t0+dt], which starts from the measured state, a limit the state
/// itself already violates only has to not get worse (min(limit, value at t0)); a separation
/// from another plan, its braking envelope or the worker that the start violates must recover at
/// the pace of recoveringDistance().
/// Thread safety: not thread-safe (FCL).

#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/planner_config.hpp"
#include "gesture_formation/planning/seen_space.hpp"
#include "gesture_formation/planning/shapes.hpp"  // closestPointOnSegment, distanceToPolyline
#include "gesture_formation/planning/uav_planner.hpp"

namespace gesture_formation::planning {

/// \brief Position, velocity, acceleration of the Hermite spline at time t (clamped to the
/// trajectory; after the end: the last position, hovering).
struct TrajectoryPoint {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
};
TrajectoryPoint evaluateTrajectory(const PlannedTrajectory& trajectory, double t_s);

/// \brief The worker's predicted position at time t: linear interpolation of the horizon whose
/// step k is at t0_s + k·dt_s (clamped at both ends).
Eigen::Vector3d workerPositionAt(const formation::WorkerHorizon& worker, double t0_s, double dt_s, double t_s);

/// \brief Braking to hover from velocity v_world the way UavPlanner's brake plan does: constant
/// deceleration along −v, as large as ‖a‖ ≤ max_acceleration_mps2 and |a_z| ≤
/// max_vertical_acceleration_mps2 allow, lowered so that the stop falls on a sample of spacing
/// dt_s. At rest (or non-finite v, dt ≤ 0): zero.
struct BrakeProfile {
  Eigen::Vector3d dir = Eigen::Vector3d::Zero();  ///< unit direction of v (zero at rest)
  double decel_mps2 = 0.0;
  double t_stop_s = 0.0;
  double speed_mps = 0.0;
};
BrakeProfile brakeProfile(const Eigen::Vector3d& v_world, const DynamicLimits& limits, double dt_s);

/// \brief Where a UAV at p_world with velocity v_world stops braking by brakeProfile().
Eigen::Vector3d brakeStop(const Eigen::Vector3d& p_world, const Eigen::Vector3d& v_world, const DynamicLimits& limits,
                          double dt_s);

/// \brief `plan` re-timed to n samples t0_s + k·dt_s: the exact Hermite evaluation while within it
/// (camera angles from PlannedTrajectory::sampleAt); after its end, braking to hover from its end
/// velocity by brakeProfile() — not a jump to rest, which a plan that ends moving would otherwise
/// make (a velocity step of several m/s within one interval: tens of m/s² that no verifier passes).
/// A plan that ends at rest re-times exactly as evaluateTrajectory (hover at its end).
PlannedTrajectory retimeThenBrake(const PlannedTrajectory& plan, double t0_s, double dt_s, int n,
                                  const DynamicLimits& limits);

/// \brief The braking envelope of another UAV's plan at t_until_s (PlannerConfig::brake_envelope_age_s,
/// brake_envelope_lead_s): brakeStop() of the plan's state at each of its sample times in
/// [t0, min(t_until, tEnd)] and at that end time, in time order — a polyline of ≥ 1 point (empty
/// only for an empty plan). A UAV that followed the plan and braked at any of those times stopped
/// on it (between the sample times: within the chord error, a few cm at the limits).
std::vector<Eigen::Vector3d> brakeEnvelope(const PlannedTrajectory& plan, double t_until_s, const DynamicLimits& limits);

/// \brief The braking envelope UAV own_index, planning at t_now_s, keeps Γ_dis from, for another
/// UAV's plan: for a lower-priority UAV's (other.uav_index > own_index) with
/// config.brake_envelope_lead_s > 0, its envelope up to t_now + lead; else, for a plan older than
/// brake_envelope_age_s, up to t_now; else none (empty). The planner's QP and the verifier both
/// take it from here.
std::vector<Eigen::Vector3d> keptBrakeEnvelope(const PlannedTrajectory& other, int own_index, double t_now_s,
                                               const PlannerConfig& config);

struct VerificationReport {
  bool ok = false;
  std::string reason;  ///< first failure, with time and values; empty when ok
  double min_obstacle_clearance_m = 0.0;  ///< lower bound of the distance to the voxel cubes
  double min_uav_margin_m = 0.0;          ///< min over other plans of (distance − required)
  double min_worker_distance_m = 0.0;
  double max_speed_mps = 0.0;
  double max_acceleration_mps2 = 0.0;
};

class TrajectoryVerifier {
 public:
  /// \brief `seen` (may be null: no seen-space rule) must outlive the verifier.
  TrajectoryVerifier(const OccupancyMap& map, const DistanceField& field, const PlannerConfig& config,
                     const SeenSpace* seen = nullptr);
  ~TrajectoryVerifier();
  TrajectoryVerifier(const TrajectoryVerifier&) = delete;
  TrajectoryVerifier& operator=(const TrajectoryVerifier&) = delete;

  /// \brief Checks `trajectory` from its t0 to its end. `t_now_s` dates the other plans (age
  /// = t_now − their t0). `worker` may have 0 steps (no worker).
  VerificationReport verify(const PlannedTrajectory& trajectory, double t_now_s, const std::vector<PlannedTrajectory>& others,
                            const formation::WorkerHorizon& worker, double worker_t0_s, double worker_dt_s) const;

 private:
  /// The seen-space rule: empty when it holds, else the first violation (time, point, voxel).
  std::string seenViolation(const PlannedTrajectory& trajectory) const;

  const OccupancyMap& map_;
  const DistanceField& field_;
  PlannerConfig config_;
  FclClearance fcl_;
  const SeenSpace* seen_ = nullptr;
};

}  // namespace gesture_formation::planning

#pragma once
/// \file
/// \brief One replanning of one UAV: the three stages of DESIGN §4 behind one call.
///
///   stage 1  reference trajectory (formation core, given in the request)
///   stage 2  collision-free path near the reference on the map (references inside an
///            obstacle projected to the nearest free point)
///   stage 3  convex corridors along the path (CorridorBuilder) → trajectory QP (ProxQP,
///            warm-started) with hard speed/acceleration limits, time-indexed half-spaces
///            keeping Γ_dis from the higher-priority UAVs' plans and a safety distance from
///            the worker → camera heading/pitch (line of sight, rate limits) → verification.
///
/// Safety contract: `plan()` returns a trajectory only if it passed verification; otherwise
/// it returns the last verified plan (re-timed to t_now) when that is still valid, else a
/// braking-to-hover plan, with `status` and `reason` saying which and why. The planner is
/// stateful (last verified plan, QP warm start) and deterministic for the same sequence of
/// requests. Not thread-safe; one instance per UAV.
///
/// This header is the API the simulator (`sim/`), `gfctl plan` and the FormationPlanner
/// nodelet code against. Fields may be added; do not rename.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/formation/formation_geometry.hpp"

namespace gesture_formation::planning {

class OccupancyMap;
class DistanceField;

/// \brief Kinematic state of one UAV at time t (world ENU, SI units).
struct UavKinematicState {
  double t_s = 0.0;
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_world = Eigen::Vector3d::Zero();
  double heading_rad = 0.0;  ///< camera heading φ (−π, π]
  double pitch_rad = 0.0;    ///< camera pitch ξ
};

/// \brief One sample of a planned trajectory.
struct TrajectorySample {
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d a_world = Eigen::Vector3d::Zero();
  double heading_rad = 0.0;
  double pitch_rad = 0.0;
};

/// \brief A time-stamped planned trajectory: sample k at t0_s + k·dt_s. This is what UAVs
/// exchange (over LCM) and what the plant's controller tracks.
struct PlannedTrajectory {
  int uav_index = 0;      ///< 0 = leader, i = follower i (priority order)
  std::uint32_t sequence = 0;  ///< per-UAV plan counter
  double t0_s = 0.0;      ///< time of sample 0 (plan stamp)
  double dt_s = 0.2;
  std::vector<TrajectorySample> samples;

  bool empty() const { return samples.empty(); }
  double tEnd() const { return t0_s + dt_s * static_cast<double>(samples.empty() ? 0 : samples.size() - 1); }
  /// Linear interpolation in time; before t0 the first sample; after the end the last
  /// position with zero velocity and acceleration (hover).
  TrajectorySample sampleAt(double t_s) const;
};

/// \brief Everything one replanning needs besides the map.
struct PlanRequest {
  int uav_index = 0;
  double t_now_s = 0.0;
  UavKinematicState state;  ///< current (estimated) state; sample 0 of the plan starts here
  double dt_s = 0.2;        ///< sample spacing of reference, worker horizon and output
  /// Stage-1 reference, step k at t_now_s + k·dt_s (formation::formationHorizon output).
  formation::ReferenceTrajectory reference;
  /// The worker's predicted trajectory, same steps (a moving obstacle; camera target).
  formation::WorkerHorizon worker;
  /// Plans of the higher-priority UAVs as last received (any stamps; older plans get a
  /// margin growing with their age).
  std::vector<PlannedTrajectory> higher_priority_plans;
};

enum class PlanStatus {
  kOptimized,          ///< new verified plan from this request
  kFallbackPrevious,   ///< this request failed; last verified plan returned
  kFallbackBrake,      ///< this request failed and no usable previous plan: brake to hover
};
const char* toString(PlanStatus status);

/// \brief Wall-clock milliseconds per stage of one replanning.
struct StageTimings {
  double path_ms = 0.0;
  double corridor_ms = 0.0;
  double qp_ms = 0.0;
  double heading_ms = 0.0;
  double verify_ms = 0.0;
  double total_ms = 0.0;
};

struct PlanResult {
  PlannedTrajectory trajectory;  ///< always verified-safe (see file comment)
  PlanStatus status = PlanStatus::kFallbackBrake;
  std::string reason;            ///< why a fallback was taken (empty when kOptimized)
  StageTimings timings;
  int qp_variables = 0;
  int qp_constraints = 0;
  int qp_iterations = 0;
  double min_obstacle_clearance_m = 0.0;  ///< verified clearance of the returned plan
};

}  // namespace gesture_formation::planning

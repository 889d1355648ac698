#pragma once
/// \file
/// \brief Reference geometry of the formation: the paper's eqs. leader_ref and follower_ref
/// (docs/design.md §4), for one instant and along a planning horizon.
///
/// Frames and units: positions in the world frame [m] (z up); headings φ are camera headings
/// about world z [rad], wrapped to (−π, π] (common/angles.hpp); pitches ξ are camera pitch
/// [rad], positive = looking up (the leader's ξ_L = −γ_L looks down at the worker when it
/// is above it).
///
///   leader:     ^L p = ^H p − ^L d [cos(^Hφ − ^Lβ) cos ^Lγ,  sin(^Hφ − ^Lβ) cos ^Lγ,  −sin ^Lγ]
///               ^L φ = ^Hφ − ^Lβ,    ^L ξ = −^Lγ
///   follower i: ^i p = ^H p − ^i d [cos(^Lφ − ^iβ) cos(^iγ − ^Lξ),
///                                   sin(^Lφ − ^iβ) cos(^iγ − ^Lξ),  sin(^Lξ − ^iγ)]
///               ^i φ = ^Lφ − ^iβ,    ^i ξ = ^Lξ − ^iγ
///
/// Properties (tested): |p − ^H p| = d for every UAV; the unit vector from a UAV to the
/// worker has azimuth φ and elevation ξ (the camera points at the worker).
/// Thread safety: pure functions.

#include <vector>

#include <Eigen/Core>

#include "gesture_formation/formation/formation_params.hpp"

namespace gesture_formation::formation {

/// \brief Largest horizon the fixed-size trajectory types hold (steps).
constexpr int kMaxHorizonSteps = 128;

/// \brief Positions along a horizon, one column per step, world frame [m]. Fixed maximum
/// size: no heap allocation.
using HorizonPoints = Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::ColMajor, 3, kMaxHorizonSteps>;
/// \brief One scalar per horizon step (angles [rad]). Fixed maximum size.
using HorizonScalars = Eigen::Matrix<double, 1, Eigen::Dynamic, Eigen::RowMajor, 1, kMaxHorizonSteps>;

/// \brief Where a camera sees the worker from: its distance and its elevation above him
/// (positive: the camera is above the worker). The geometry the gesture vote gates on
/// (gesture::ViewFusionConfig's envelope), the metrics report and the worker model renders.
struct ViewGeometry {
  double distance_m = 0.0;     ///< |camera − worker| [m]
  double elevation_deg = 0.0;  ///< asin((camera − worker)_z / distance) [deg], 0 when they coincide
};
/// \brief The view of `worker_world` from `camera_world` (world frame, [m]); non-finite inputs
/// give non-finite fields.
ViewGeometry viewGeometry(const Eigen::Vector3d& camera_world, const Eigen::Vector3d& worker_world);

/// \brief Desired state of one UAV at one instant.
struct UavReference {
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();  ///< position [m], world frame
  double heading_rad = 0.0;                            ///< camera heading φ [rad], (−π, π]
  double pitch_rad = 0.0;                              ///< camera pitch ξ [rad]
};

/// \brief Desired states of one UAV along a horizon (column k = step k).
struct ReferenceTrajectory {
  HorizonPoints p_world;      ///< positions [m], world frame
  HorizonScalars heading_rad;  ///< camera headings φ [rad], (−π, π]
  HorizonScalars pitch_rad;    ///< camera pitches ξ [rad]

  int steps() const { return static_cast<int>(p_world.cols()); }
  void resize(int steps) {
    p_world.resize(3, steps);
    heading_rad.resize(1, steps);
    pitch_rad.resize(1, steps);
  }
  UavReference at(int k) const { return UavReference{p_world.col(k), heading_rad(k), pitch_rad(k)}; }
};

/// \brief Eq. leader_ref at one instant. `p_human_world` [m], `human_heading_rad` ^Hφ [rad].
UavReference leaderReference(const Eigen::Vector3d& p_human_world, double human_heading_rad,
                             const UavObservation& leader);

/// \brief Eq. follower_ref at one instant, relative to the leader's camera heading ^Lφ and
/// pitch ^Lξ [rad] (its desired values, or its planned ones).
UavReference followerReference(const Eigen::Vector3d& p_human_world, double leader_heading_rad,
                               double leader_pitch_rad, const UavObservation& follower);

/// \brief The worker's predicted trajectory over the horizon (e.g. from HumanKalman).
struct WorkerHorizon {
  HorizonPoints p_world;      ///< predicted positions [m], world frame, one column per step
  HorizonScalars heading_rad;  ///< ^Hφ per step [rad] (WorkerHeading; constant 0 in the paper)
  int steps() const { return static_cast<int>(p_world.cols()); }
};

/// \brief The constant-velocity prediction p0 + k·dt·v0, k = 0..steps−1, with a constant
/// heading (what the planners use from the estimator's state).
WorkerHorizon constantVelocityHorizon(const Eigen::Vector3d& p0_world, const Eigen::Vector3d& v_world,
                                      double heading_rad, int steps, double dt_s);

/// \brief The leader's planned camera heading and pitch along the horizon (received over
/// LCM by the followers). Same number of steps as the WorkerHorizon.
struct LeaderPlan {
  HorizonScalars heading_rad;  ///< ^Lφ per step [rad]
  HorizonScalars pitch_rad;    ///< ^Lξ per step [rad]
};

/// \brief Eq. leader_ref at every step. `out` is resized to the horizon (no heap).
void leaderHorizon(const WorkerHorizon& worker, const UavObservation& leader, ReferenceTrajectory& out);

/// \brief Eq. follower_ref at every step, relative to the leader's `plan` when given, else
/// to the leader's desired heading and pitch (from `leader`, eq. leader_ref) at each step.
/// Precondition: plan (if any) has worker.steps() steps.
void followerHorizon(const WorkerHorizon& worker, const UavObservation& leader, const LeaderPlan* plan,
                     const UavObservation& follower, ReferenceTrajectory& out);

/// \brief References of every UAV of the formation along the horizon: out[0] the leader,
/// out[i] follower i. `out` is resized to params.uavCount() (allocates only when it grows;
/// reuse it across calls for an allocation-free hot path).
/// Precondition: 1 ≤ worker.steps() ≤ kMaxHorizonSteps; plan (if any) matches.
void formationHorizon(const WorkerHorizon& worker, const FormationParams& params, const LeaderPlan* plan,
                      std::vector<ReferenceTrajectory>& out);

}  // namespace gesture_formation::formation

#pragma once
/// \file
/// \brief A UAV's planned trajectory as UAVs exchange it (over LCM) and its controller tracks
/// it, with the kinematic state and sample types it is made of. Kept apart from the planner so
/// that message code (comm/payloads.hpp) and controllers need not include the planner.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace gesture_formation::planning {

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
  /// The plan at t_s: position, velocity and acceleration on the cubic Hermite curve through the
  /// samples (evaluateTrajectory(), the curve the verifier checks), heading and pitch linear
  /// between samples; before t0 the first sample; after the end the last position with zero
  /// velocity and acceleration (hover).
  TrajectorySample sampleAt(double t_s) const;
  /// The state the plan commands at t_s (sampleAt as a UavKinematicState with t_s set).
  UavKinematicState stateAt(double t_s) const;
};

}  // namespace gesture_formation::planning

#pragma once
/// \file
/// \brief Camera heading φ and pitch ξ along planned positions: line of sight to the
/// predicted worker under hard rate limits (docs/design.md §4; conventions.md: heading from +x
/// towards +y, pitch positive up, headings wrapped to (−π, π]).
///
/// Ceres formulation (solveCameraCeres): per angle, the variables are the increments
/// Δ_k = φ_{k+1} − φ_k, k = 0..N−1, bounded |Δ_k| ≤ rate·dt (hard rate limit as Ceres
/// parameter bounds); φ_0 is the current angle. Residuals: w·(φ_k − φ*_k) for k = 1..N with
/// φ*_k the line-of-sight angle unwrapped along the horizon (so the wrap is continuous), and
/// w_s·(Δ_k − Δ_{k−1}) (angular acceleration, soft). Pitch targets are clamped to the gimbal
/// range; the result is clamped too (clamping never increases a step).
/// cameraFilter is the closed-form alternative (target angle, step clamped to the rate limit),
/// compared in bench/bench_planner.cpp (docs/planning.md §6.5).
/// Thread safety: pure functions.

#include <string>
#include <vector>

#include <Eigen/Core>

namespace gesture_formation::planning {

struct CameraTrackingProblem {
  double dt_s = 0.2;
  double heading0_rad = 0.0;  ///< current heading (sample 0)
  double pitch0_rad = 0.0;    ///< current pitch (sample 0)
  std::vector<Eigen::Vector3d> p_world;       ///< UAV positions, k = 0..N
  std::vector<Eigen::Vector3d> target_world;  ///< worker positions, k = 0..N
  double max_heading_rate_radps = 1.0;
  double max_pitch_rate_radps = 0.5;
  double min_pitch_rad = -1.4;
  double max_pitch_rad = 0.5;
  double weight = 1.0;
  double smoothness_weight = 2.0;
};

struct CameraTrack {
  bool ok = false;
  std::string reason;
  std::vector<double> heading_rad;  ///< k = 0..N, wrapped
  std::vector<double> pitch_rad;    ///< k = 0..N
  int iterations = 0;
  /// RMS line-of-sight error (rad) over k = 1..N, heading and pitch together.
  double rms_error_rad = 0.0;
};

/// \brief Line-of-sight azimuth and elevation (rad) from p to target; `fallback` when they
/// (nearly) coincide horizontally.
Eigen::Vector2d lineOfSight(const Eigen::Vector3d& p_world, const Eigen::Vector3d& target_world, const Eigen::Vector2d& fallback);

CameraTrack solveCameraCeres(const CameraTrackingProblem& problem);
CameraTrack cameraFilter(const CameraTrackingProblem& problem);

}  // namespace gesture_formation::planning

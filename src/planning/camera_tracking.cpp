#include "gesture_formation/planning/camera_tracking.hpp"

#include <algorithm>
#include <cmath>

#include <ceres/ceres.h>

#include "gesture_formation/common/angles.hpp"

namespace gesture_formation::planning {

using common::wrapAngle;

Eigen::Vector2d lineOfSight(const Eigen::Vector3d& p, const Eigen::Vector3d& target, const Eigen::Vector2d& fallback) {
  const Eigen::Vector3d d = target - p;
  const double horizontal = d.head<2>().norm();
  if (horizontal < 1e-6) return Eigen::Vector2d(fallback(0), d.z() >= 0.0 ? M_PI / 2 : -M_PI / 2);
  return Eigen::Vector2d(std::atan2(d.y(), d.x()), std::atan2(d.z(), horizontal));
}

namespace {

/// Unwrapped heading targets (k = 1..N, index 0 = current heading) and clamped pitch targets.
bool targets(const CameraTrackingProblem& pr, std::vector<double>& heading, std::vector<double>& pitch, std::string& reason) {
  const std::size_t n = pr.p_world.size();
  if (n < 2 || pr.target_world.size() != n) {
    reason = "camera: need >= 2 positions and as many targets";
    return false;
  }
  if (!(pr.dt_s > 0.0) || !std::isfinite(pr.heading0_rad) || !std::isfinite(pr.pitch0_rad)) {
    reason = "camera: dt or initial angles not finite/positive";
    return false;
  }
  heading.assign(n, pr.heading0_rad);
  pitch.assign(n, std::clamp(pr.pitch0_rad, pr.min_pitch_rad, pr.max_pitch_rad));
  Eigen::Vector2d last(pr.heading0_rad, pr.pitch0_rad);
  for (std::size_t k = 1; k < n; ++k) {
    if (!pr.p_world[k].allFinite() || !pr.target_world[k].allFinite()) {
      reason = "camera: position or target " + std::to_string(k) + " not finite";
      return false;
    }
    const Eigen::Vector2d los = lineOfSight(pr.p_world[k], pr.target_world[k], last);
    heading[k] = heading[k - 1] + wrapAngle(los(0) - heading[k - 1]);
    pitch[k] = std::clamp(los(1), pr.min_pitch_rad, pr.max_pitch_rad);
    last = Eigen::Vector2d(los(0), los(1));
  }
  return true;
}

/// Residuals of one angle sequence: w(φ0 + Σ_{i<k} Δ_i − φ*_k), k = 1..N, then
/// w_s(Δ_k − Δ_{k−1}), k = 1..N−1. Linear in Δ (analytic Jacobian).
class AngleTrackingCost final : public ceres::CostFunction {
 public:
  AngleTrackingCost(double angle0, std::vector<double> targets, double w, double ws)
      : angle0_(angle0), targets_(std::move(targets)), w_(w), ws_(ws) {
    n_ = static_cast<int>(targets_.size()) - 1;
    set_num_residuals(n_ + std::max(0, n_ - 1));
    mutable_parameter_block_sizes()->push_back(n_);
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double* d = parameters[0];
    const int m = num_residuals();
    double angle = angle0_;
    for (int k = 1; k <= n_; ++k) {
      angle += d[k - 1];
      residuals[k - 1] = w_ * (angle - targets_[static_cast<std::size_t>(k)]);
    }
    for (int k = 1; k < n_; ++k) residuals[n_ + k - 1] = ws_ * (d[k] - d[k - 1]);
    if (jacobians != nullptr && jacobians[0] != nullptr) {
      double* J = jacobians[0];  // row-major m × n
      std::fill(J, J + static_cast<std::ptrdiff_t>(m) * n_, 0.0);
      for (int k = 1; k <= n_; ++k) {
        for (int i = 0; i < k; ++i) J[(k - 1) * n_ + i] = w_;
      }
      for (int k = 1; k < n_; ++k) {
        J[(n_ + k - 1) * n_ + k] = ws_;
        J[(n_ + k - 1) * n_ + k - 1] = -ws_;
      }
    }
    return true;
  }

 private:
  double angle0_;
  std::vector<double> targets_;
  double w_, ws_;
  int n_ = 0;
};

void finish(const CameraTrackingProblem& pr, const std::vector<double>& th, const std::vector<double>& tp, CameraTrack& out) {
  double se = 0.0;
  const std::size_t n = th.size();
  for (std::size_t k = 1; k < n; ++k) {
    out.pitch_rad[k] = std::clamp(out.pitch_rad[k], pr.min_pitch_rad, pr.max_pitch_rad);
    se += std::pow(out.heading_rad[k] - th[k], 2) + std::pow(out.pitch_rad[k] - tp[k], 2);
  }
  for (auto& h : out.heading_rad) h = wrapAngle(h);
  out.rms_error_rad = std::sqrt(se / static_cast<double>(2 * (n - 1)));
  out.ok = true;
  for (std::size_t k = 0; k < n; ++k) {
    if (!std::isfinite(out.heading_rad[k]) || !std::isfinite(out.pitch_rad[k])) {
      out.ok = false;
      out.reason = "camera: non-finite angle at sample " + std::to_string(k);
    }
  }
}

}  // namespace

CameraTrack cameraFilter(const CameraTrackingProblem& pr) {
  CameraTrack out;
  std::vector<double> th, tp;
  if (!targets(pr, th, tp, out.reason)) return out;
  const std::size_t n = th.size();
  out.heading_rad.assign(n, pr.heading0_rad);
  out.pitch_rad.assign(n, pr.pitch0_rad);
  const double sh = pr.max_heading_rate_radps * pr.dt_s;
  const double sp = pr.max_pitch_rate_radps * pr.dt_s;
  for (std::size_t k = 1; k < n; ++k) {
    out.heading_rad[k] = out.heading_rad[k - 1] + std::clamp(th[k] - out.heading_rad[k - 1], -sh, sh);
    out.pitch_rad[k] = out.pitch_rad[k - 1] + std::clamp(tp[k] - out.pitch_rad[k - 1], -sp, sp);
  }
  finish(pr, th, tp, out);
  return out;
}

CameraTrack solveCameraCeres(const CameraTrackingProblem& pr) {
  CameraTrack out;
  std::vector<double> th, tp;
  if (!targets(pr, th, tp, out.reason)) return out;
  const int n = static_cast<int>(th.size()) - 1;
  // Initial guess: the closed-form filter (feasible, usually close).
  const CameraTrack guess = cameraFilter(pr);
  std::vector<double> dh(static_cast<std::size_t>(n)), dp(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    // Unwrapped increments of the filter (it moves by at most rate·dt < π per step).
    dh[static_cast<std::size_t>(k)] = wrapAngle(guess.heading_rad[static_cast<std::size_t>(k) + 1] - guess.heading_rad[static_cast<std::size_t>(k)]);
    dp[static_cast<std::size_t>(k)] = guess.pitch_rad[static_cast<std::size_t>(k) + 1] - guess.pitch_rad[static_cast<std::size_t>(k)];
  }
  const double ws = pr.smoothness_weight;
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  const double pitch0 = std::clamp(pr.pitch0_rad, pr.min_pitch_rad, pr.max_pitch_rad);
  problem.AddResidualBlock(new AngleTrackingCost(pr.heading0_rad, th, pr.weight, ws), nullptr, dh.data());
  problem.AddResidualBlock(new AngleTrackingCost(pitch0, tp, pr.weight, ws), nullptr, dp.data());
  const double sh = pr.max_heading_rate_radps * pr.dt_s;
  const double sp = pr.max_pitch_rate_radps * pr.dt_s;
  for (int k = 0; k < n; ++k) {
    problem.SetParameterLowerBound(dh.data(), k, -sh);
    problem.SetParameterUpperBound(dh.data(), k, sh);
    problem.SetParameterLowerBound(dp.data(), k, -sp);
    problem.SetParameterUpperBound(dp.data(), k, sp);
  }
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = 50;
  so.num_threads = 1;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  so.function_tolerance = 1e-10;
  so.gradient_tolerance = 1e-12;
  so.parameter_tolerance = 1e-10;
  ceres::Solver::Summary summary;
  ceres::Solve(so, &problem, &summary);
  out.iterations = static_cast<int>(summary.iterations.size());
  if (!summary.IsSolutionUsable()) {
    out.reason = "camera: Ceres failed: " + summary.message;
    return out;
  }
  out.heading_rad.assign(static_cast<std::size_t>(n) + 1, pr.heading0_rad);
  out.pitch_rad.assign(static_cast<std::size_t>(n) + 1, pitch0);
  for (int k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    // Bounds are respected by Ceres' projected trust region; clamp against round-off.
    out.heading_rad[i + 1] = out.heading_rad[i] + std::clamp(dh[i], -sh, sh);
    out.pitch_rad[i + 1] = out.pitch_rad[i] + std::clamp(dp[i], -sp, sp);
  }
  finish(pr, th, tp, out);
  return out;
}

}  // namespace gesture_formation::planning

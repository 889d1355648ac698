#pragma once
/// \file
/// \brief Constant-velocity Kalman filter of the worker's position and velocity
/// (paper: "Human 3D position estimation"; docs/design.md §3 and §8.1).
///
///   x = [p; v] ∈ R⁶ (world),  x⁺ = F x,  F = [[I, Δt I], [0, I]],
///   P⁺ = F P Fᵀ + Q,  Q = diag(σ_p² I₃, σ_v² I₃)  (added once per prediction step),
///   z = p + ζ, ζ ~ N(0, Σ).
///
/// Beyond the paper: Mahalanobis gating (χ²₃) with re-initialisation after more than
/// `max_consecutive_rejections` rejections in a row, measurements older than the filter's
/// time dropped and counted, non-finite input rejected, a "lost" flag after a timeout, after
/// which the velocity is no longer extrapolated (see predict()), and track confirmation: a track
/// (re-)initialised from one measurement is *tentative* until `confirm_measurements` of its
/// measurements (the initialising one included) were accepted — consumers act only on a
/// confirmed track, so that a gross range error at the start does not steer the formation
/// (docs/estimation.md, docs/safety.md §4.12).
/// A rejected input never changes the state.
/// Thread safety: none; one filter per thread (the nodelet guards it with a mutex).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>

#include "gesture_formation/estimation/measurement_model.hpp"

namespace gesture_formation::common {
template <class Config>
struct FieldTable;
}  // namespace gesture_formation::common

namespace gesture_formation::estimation {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// \brief Filter parameters (paper Table II for the noise values).
struct HumanKalmanConfig {
  double sigma_p_m = 0.1;                 ///< process noise on position per step [m], > 0
  double sigma_v_mps = 0.1;               ///< process noise on velocity per step [m/s], > 0
  /// Q's time base [s], ≥ 0. 0: Q is added once per prediction step, whatever its length (the
  /// paper's filter, tuned for a 15 Hz camera). > 0: Q is scaled by dt / reference_period_s, so the
  /// noise per second is the same at any measurement rate (a camera at 5 Hz, sensors arriving
  /// together or apart); set it to the period the sigmas were tuned at (1/15 s for the paper's).
  double reference_period_s = 0.0;
  double initial_velocity_std_mps = 1.0;  ///< σ_v0 of the velocity at (re-)initialisation [m/s], > 0
  double gate_chi2 = 16.27;               ///< Mahalanobis gate, χ²₃ at 0.999, > 0
  int max_consecutive_rejections = 10;    ///< at most this many gated-out measurements in a row, ≥ 1
  double lost_timeout_s = 5.0;            ///< no fused measurement for this long → lost, and no more extrapolation [s], > 0
  int confirm_measurements = 3;           ///< accepted measurements (the initialising one included) that confirm a track, ≥ 1

  /// \brief Every problem, each naming the YAML key (humanKalmanFields()); empty when valid.
  std::vector<std::string> validate() const;
};

/// \brief HumanKalmanConfig's numbers (estimator YAML keys `process_noise.*`,
/// `initial_velocity_std_mps`, `gate_chi2`, `max_consecutive_rejections`, `lost_timeout_s`,
/// `confirm_measurements`) with their ranges: the only place they are written, used by validate()
/// and by the estimator's YAML reader (common/config_fields.hpp).
const common::FieldTable<HumanKalmanConfig>& humanKalmanFields();

/// \brief What happened to one measurement.
enum class UpdateOutcome {
  kInitialized,    ///< first measurement (or after reset): state set from it
  kFused,          ///< passed the gate and was fused
  kReinitialized,  ///< failed the gate after too many rejections: state re-set from it
  kGated,          ///< failed the Mahalanobis gate; state unchanged
  kOutOfOrder,     ///< older than the filter's time; state unchanged
  kInvalid,        ///< non-finite measurement, time or covariance; state unchanged
};

inline bool accepted(UpdateOutcome o) {
  return o == UpdateOutcome::kInitialized || o == UpdateOutcome::kFused || o == UpdateOutcome::kReinitialized;
}

inline const char* toString(UpdateOutcome o) {
  switch (o) {
    case UpdateOutcome::kInitialized: return "initialized";
    case UpdateOutcome::kFused: return "fused";
    case UpdateOutcome::kReinitialized: return "reinitialized";
    case UpdateOutcome::kGated: return "gated";
    case UpdateOutcome::kOutOfOrder: return "out_of_order";
    case UpdateOutcome::kInvalid: return "invalid";
  }
  return "?";
}

/// \brief Counters for diagnostics.
struct HumanKalmanCounters {
  std::uint64_t fused = 0;
  std::uint64_t initializations = 0;
  std::uint64_t reinitializations = 0;
  std::uint64_t gated = 0;
  std::uint64_t out_of_order = 0;
  std::uint64_t invalid = 0;
};

/// \brief One predicted sample of the worker's trajectory.
struct PredictedSample {
  double t_s = 0.0;
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov_p = Eigen::Matrix3d::Zero();
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

class HumanKalman {
 public:
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
  explicit HumanKalman(const HumanKalmanConfig& config = HumanKalmanConfig()) : config_(config) {}

  const HumanKalmanConfig& config() const { return config_; }
  bool initialized() const { return initialized_; }
  /// Time of the state [s]; meaningful only when initialized.
  double time() const { return t_; }
  const Vector6d& state() const { return x_; }
  const Matrix6d& covariance() const { return P_; }
  const HumanKalmanCounters& counters() const { return counters_; }
  /// Mahalanobis distance² of the last gated measurement (NaN before any).
  double lastMahalanobis2() const { return last_d2_; }
  int consecutiveRejections() const { return consecutive_rejections_; }
  /// \brief True when initialised and at least `confirm_measurements` measurements were accepted
  /// since the last (re-)initialisation (the initialising one included). A tentative track's
  /// state is not for acting on: the WorkerEstimator does not publish it, the simulated leader
  /// does not plan on it.
  bool confirmed() const { return initialized_ && accepted_since_init_ >= config_.confirm_measurements; }

  /// \brief True when initialised and no measurement was fused for more than lost_timeout_s
  /// before `t_s`.
  bool lost(double t_s) const { return initialized_ && (t_s - t_last_fused_) > config_.lost_timeout_s; }

  /// \brief Forgets the state (next measurement initialises).
  void reset() {
    initialized_ = false;
    consecutive_rejections_ = 0;
  }

  /// \brief Takes over another filter's published estimate (a new leader starts from the last
  /// shared state, docs/safety.md §1.2): position `p_world` and velocity `v_world` at `t_s`,
  /// position covariance `cov_p_world` (velocity: σ_v0² I, no correlation), last fused at
  /// `fused_s` (≤ t_s; lost() counts from it). The track counts as confirmed — only a confirmed
  /// track is published. Returns false and changes nothing for non-finite or inconsistent input.
  bool adopt(double t_s, const Eigen::Vector3d& p_world, const Eigen::Vector3d& v_world,
             const Eigen::Matrix3d& cov_p_world, double fused_s) {
    if (!std::isfinite(t_s) || !std::isfinite(fused_s) || fused_s > t_s || !p_world.allFinite() ||
        !v_world.allFinite() || !cov_p_world.allFinite() || cov_p_world.llt().info() != Eigen::Success) {
      ++counters_.invalid;
      return false;
    }
    x_.head<3>() = p_world;
    x_.tail<3>() = v_world;
    P_.setZero();
    P_.topLeftCorner<3, 3>() = 0.5 * (cov_p_world + cov_p_world.transpose());
    const double s0 = config_.initial_velocity_std_mps;
    P_.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * (s0 * s0);
    t_ = t_s;
    t_last_fused_ = fused_s;
    initialized_ = true;
    consecutive_rejections_ = 0;
    accepted_since_init_ = std::max(1, config_.confirm_measurements);
    ++counters_.initializations;
    return true;
  }

  /// \brief Predicts the state to `t_s` (≥ time()), adding Q once (scaled by
  /// dt / reference_period_s when that is > 0, dt = t_s − time()). Returns false and changes
  /// nothing when not initialised, `t_s` is not finite, or `t_s` < time().
  ///
  /// The constant-velocity model holds for at most lost_timeout_s after the last fused
  /// measurement. Beyond it (lost) the filter no longer extrapolates: the position is held where
  /// the model left it, the velocity is forgotten (mean 0, covariance σ_v0² I, no correlation)
  /// and the position covariance grows by σ_v0²·(1 s) per second — a random walk at σ_v0 — so a
  /// worker who climbed out of view is not estimated tens of metres above the tower
  /// (docs/safety.md §4.6), and the growing covariance lets him be re-acquired where he reappears.
  bool predict(double t_s) {
    if (!initialized_ || !std::isfinite(t_s) || t_s < t_) return false;
    const double t_model_end = t_last_fused_ + config_.lost_timeout_s;
    const double dt = std::max(0.0, std::min(t_s, t_model_end) - t_);       // constant velocity
    const double dt_held = std::max(0.0, t_s - std::max(t_, t_model_end));  // lost: position held
    Vector6d x = x_;
    x.head<3>() += dt * x_.tail<3>();
    // F P Fᵀ written out by blocks (F = [[I, dt I], [0, I]]).
    Matrix6d P = P_;
    const Eigen::Matrix3d Ppp = P_.topLeftCorner<3, 3>();
    const Eigen::Matrix3d Ppv = P_.topRightCorner<3, 3>();
    const Eigen::Matrix3d Pvv = P_.bottomRightCorner<3, 3>();
    P.topLeftCorner<3, 3>() = Ppp + dt * (Ppv + Ppv.transpose()) + dt * dt * Pvv;
    P.topRightCorner<3, 3>() = Ppv + dt * Pvv;
    P.bottomLeftCorner<3, 3>() = P.topRightCorner<3, 3>().transpose();
    if (t_s > t_model_end) {
      const double s0 = config_.initial_velocity_std_mps;
      x.tail<3>().setZero();
      P.topRightCorner<3, 3>().setZero();
      P.bottomLeftCorner<3, 3>().setZero();
      P.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * (s0 * s0);
      P.topLeftCorner<3, 3>().diagonal().array() += s0 * s0 * dt_held * 1.0 /* s */;
    }
    const double q_scale = config_.reference_period_s > 0.0 ? (t_s - t_) / config_.reference_period_s : 1.0;
    const double qp = q_scale * config_.sigma_p_m * config_.sigma_p_m;
    const double qv = q_scale * config_.sigma_v_mps * config_.sigma_v_mps;
    P.diagonal() += (Vector6d() << qp, qp, qp, qv, qv, qv).finished();
    if (!x.allFinite() || !P.allFinite()) return false;
    x_ = x;
    P_ = P;
    t_ = t_s;
    return true;
  }

  /// \brief Fuses a measurement taken at `t_s`: predicts to `t_s` (Q once) and updates,
  /// or initialises from it. A measurement older than time() is dropped (kOutOfOrder).
  UpdateOutcome step(double t_s, const PositionMeasurement& m) {
    if (!std::isfinite(t_s) || !m.z_world.allFinite() || !m.sigma_world.allFinite()) {
      ++counters_.invalid;
      return UpdateOutcome::kInvalid;
    }
    if (!initialized_) {
      initializeFrom(t_s, m);
      ++counters_.initializations;
      return UpdateOutcome::kInitialized;
    }
    if (t_s < t_) {
      ++counters_.out_of_order;
      return UpdateOutcome::kOutOfOrder;
    }
    if (!predict(t_s)) {
      ++counters_.invalid;
      return UpdateOutcome::kInvalid;
    }
    return update(m);
  }

  /// \brief Updates the state at its current time with `m` (no prediction).
  UpdateOutcome update(const PositionMeasurement& m) {
    if (!initialized_ || !m.z_world.allFinite() || !m.sigma_world.allFinite()) {
      ++counters_.invalid;
      return UpdateOutcome::kInvalid;
    }
    const Eigen::Vector3d y = m.z_world - x_.head<3>();
    const Eigen::Matrix3d S = P_.topLeftCorner<3, 3>() + m.sigma_world;
    const Eigen::LLT<Eigen::Matrix3d> llt(S);
    if (llt.info() != Eigen::Success) {
      ++counters_.invalid;
      return UpdateOutcome::kInvalid;
    }
    const double d2 = y.dot(llt.solve(y));
    last_d2_ = d2;
    if (!(d2 <= config_.gate_chi2)) {
      if (consecutive_rejections_ >= config_.max_consecutive_rejections) {
        initializeFrom(t_, m);
        ++counters_.reinitializations;
        return UpdateOutcome::kReinitialized;
      }
      ++consecutive_rejections_;
      ++counters_.gated;
      return UpdateOutcome::kGated;
    }
    // K = P Hᵀ S⁻¹ with H = [I 0]; Joseph form keeps P symmetric positive definite.
    const Eigen::Matrix<double, 6, 3> PHt = P_.leftCols<3>();
    const Eigen::Matrix<double, 6, 3> K = llt.solve(PHt.transpose()).transpose();
    Vector6d x = x_ + K * y;
    Matrix6d IKH = Matrix6d::Identity();
    IKH.leftCols<3>() -= K;
    Matrix6d P = IKH * P_ * IKH.transpose() + K * m.sigma_world * K.transpose();
    P = 0.5 * (P + P.transpose());
    if (!x.allFinite() || !P.allFinite()) {
      ++counters_.invalid;
      return UpdateOutcome::kInvalid;
    }
    x_ = x;
    P_ = P;
    consecutive_rejections_ = 0;
    t_last_fused_ = t_;
    ++accepted_since_init_;
    ++counters_.fused;
    return UpdateOutcome::kFused;
  }

  /// \brief The state predicted to `t_s` without changing the filter (Q added once when
  /// t_s > time(), as a prediction step would). Requires initialized().
  PredictedSample predicted(double t_s) const {
    HumanKalman copy = *this;
    if (t_s > t_) copy.predict(t_s);
    PredictedSample s;
    s.t_s = t_s;
    const double dt = t_s - copy.t_;  // zero unless t_s < time(): extrapolate backwards without noise
    s.p_world = copy.x_.head<3>() + dt * copy.x_.tail<3>();
    s.v_world = copy.x_.tail<3>();
    s.cov_p = copy.P_.topLeftCorner<3, 3>();
    return s;
  }

  /// \brief The whole state and its 6×6 covariance predicted to `t_s` as one prediction step would
  /// (Q once), without changing the filter; before time() the position extrapolated back without
  /// noise (as predicted()) and the filter's covariance. Position, velocity and their correlation
  /// come from one step, so the covariance stays symmetric positive semi-definite (a position
  /// block predicted alone beside the old velocity blocks need not be). Requires initialized().
  std::pair<Vector6d, Matrix6d> predictedState(double t_s) const {
    HumanKalman copy = *this;
    if (t_s > t_) copy.predict(t_s);
    Vector6d x = copy.x_;
    x.head<3>() += (t_s - copy.t_) * copy.x_.tail<3>();  // zero unless t_s < time()
    return {x, copy.P_};
  }

  /// \brief The predicted trajectory over a horizon for the planner: `steps` samples at
  /// t0 + k·dt (k = 0…steps−1). Position follows the constant-velocity model; the
  /// covariance grows as a chain of prediction steps from time(). Requires initialized().
  std::vector<PredictedSample, Eigen::aligned_allocator<PredictedSample>> predictTrajectory(double t0_s, double dt_s,
                                                                                             int steps) const {
    std::vector<PredictedSample, Eigen::aligned_allocator<PredictedSample>> out;
    if (!initialized_ || steps <= 0 || !(dt_s > 0.0) || !std::isfinite(t0_s)) return out;
    out.reserve(static_cast<std::size_t>(steps));
    HumanKalman copy = *this;
    for (int k = 0; k < steps; ++k) {
      const double t = t0_s + k * dt_s;
      if (t > copy.t_) copy.predict(t);
      PredictedSample s;
      s.t_s = t;
      const double dt = t - copy.t_;
      s.p_world = copy.x_.head<3>() + dt * copy.x_.tail<3>();
      s.v_world = copy.x_.tail<3>();
      s.cov_p = copy.P_.topLeftCorner<3, 3>();
      out.push_back(s);
    }
    return out;
  }

 private:
  void initializeFrom(double t_s, const PositionMeasurement& m) {
    x_.head<3>() = m.z_world;
    x_.tail<3>().setZero();
    P_.setZero();
    P_.topLeftCorner<3, 3>() = m.sigma_world;
    const double s0 = config_.initial_velocity_std_mps;
    P_.bottomRightCorner<3, 3>() = Eigen::Matrix3d::Identity() * (s0 * s0);
    t_ = t_s;
    t_last_fused_ = t_s;
    initialized_ = true;
    consecutive_rejections_ = 0;
    accepted_since_init_ = 1;
  }

  HumanKalmanConfig config_;
  bool initialized_ = false;
  double t_ = 0.0;
  double t_last_fused_ = 0.0;
  Vector6d x_ = Vector6d::Zero();
  Matrix6d P_ = Matrix6d::Identity();
  int consecutive_rejections_ = 0;
  int accepted_since_init_ = 0;
  double last_d2_ = std::nan("");
  HumanKalmanCounters counters_;
};

}  // namespace gesture_formation::estimation

// UavPlanner: stage 2 (projection, path), stage 3 (corridors, QP, camera), verification and
// fallback. docs/planning.md §5–§8.
#include "gesture_formation/planning/uav_planner.hpp"

#include <algorithm>
#include <functional>
#include <chrono>
#include <cmath>
#include <sstream>

#include <Eigen/Geometry>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/planning/camera_tracking.hpp"
#include "gesture_formation/planning/corridor_builder.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/path_search.hpp"
#include "gesture_formation/planning/qp_diagnosis.hpp"
#include "gesture_formation/planning/trajectory_qp.hpp"
#include "gesture_formation/planning/trajectory_verifier.hpp"

namespace gesture_formation::planning {

namespace {

/// A QP whose sparse solve was stopped: its deadline passed or ProxQP broke an invariant.
bool stoppedSparse(const TrajectoryQpSolution& s) {
  return s.sparse_invariant_broken || s.status == TrajectoryQpSolution::Status::kTimeLimit;
}

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

/// The replanning's time budget (PlannerConfig::time_budget_ms, 0: none) is spent.
bool budgetSpent(const PlannerConfig& config, Clock::time_point t_start) {
  return config.time_budget_ms > 0.0 && msSince(t_start) > config.time_budget_ms;
}

std::string joinErrors(const std::vector<std::string>& e) {
  std::string s;
  for (const auto& x : e) s += (s.empty() ? "" : "; ") + x;
  return s;
}

/// Largest speed along unit direction d inside the polygon (support of the inner set).
double supportAlong(const NormPolygon& poly, const Eigen::Vector3d& d) {
  const auto D = poly.directions();
  const auto h = poly.halfWidths();
  double s = std::numeric_limits<double>::infinity();
  for (int r = 0; r < NormPolygon::kRows; ++r) {
    const double c = std::abs(D.row(r).dot(d));
    if (c > 1e-12) s = std::min(s, h(r) / c);
  }
  return s;
}

/// Least value of d·p_k (k = 1..N, index 0 unused) that the QP's model can reach from (p0, v0, a0):
/// acceleration along −d at `accel_share` of the acceleration set's support (the first interval
/// ramps from a0, as in the QP), speed along −d within the velocity set's support. A position row
/// d·p_k ≤ b with b below it cannot be met — the UAV's momentum carries it over the plane (a state
/// that deviates from the plan it flew, a corridor rebuilt around a new path).
std::vector<double> leastReach(const Eigen::Vector3d& d, const Eigen::Vector3d& p0, const Eigen::Vector3d& v0,
                               const Eigen::Vector3d& a0, const NormPolygon& velocity, const NormPolygon& acceleration,
                               double accel_share, double dt, int N) {
  std::vector<double> out(static_cast<std::size_t>(N) + 1, d.dot(p0));
  const double A = accel_share * supportAlong(acceleration, d), V = supportAlong(velocity, d);
  double s = d.dot(p0), v = d.dot(v0), acc = d.dot(a0);
  for (int k = 1; k <= N; ++k) {
    double next = -A;
    next = std::min(std::max(next, 2.0 * (-V - v) / dt - acc), A);  // not faster than V along −d
    s += v * dt + acc * dt * dt / 3.0 + next * dt * dt / 6.0;
    v += (acc + next) * dt / 2.0;
    acc = next;
    out[static_cast<std::size_t>(k)] = s;
  }
  return out;
}

/// The rate and pitch limits of `limits` into a camera problem.
void setCameraLimits(const DynamicLimits& limits, CameraTrackingProblem& cam) {
  cam.max_heading_rate_radps = limits.max_heading_rate_radps;
  cam.max_pitch_rate_radps = limits.max_pitch_rate_radps;
  cam.min_pitch_rad = limits.min_pitch_rad;
  cam.max_pitch_rad = limits.max_pitch_rad;
}

std::string checkRequest(const PlanRequest& r) {
  std::ostringstream e;
  const auto& s = r.state;
  if (!std::isfinite(r.t_now_s)) e << "t_now_s is not finite; ";
  if (!(r.dt_s > 0.0) || !std::isfinite(r.dt_s)) e << "dt_s must be > 0, got " << r.dt_s << "; ";
  if (!s.v_world.allFinite()) e << "state.v_world is not finite; ";
  if (!s.a_world.allFinite()) e << "state.a_world is not finite; ";
  if (!std::isfinite(s.heading_rad) || !std::isfinite(s.pitch_rad)) e << "state heading/pitch not finite; ";
  const int n = r.reference.steps();
  if (n < 2) e << "reference has " << n << " steps, need >= 2; ";
  if (r.reference.heading_rad.cols() != n || r.reference.pitch_rad.cols() != n) e << "reference angle rows mismatch; ";
  if (r.worker.steps() != 0 && r.worker.steps() != n) {
    e << "worker horizon has " << r.worker.steps() << " steps, reference " << n << "; ";
  }
  for (int k = 0; k < n; ++k) {
    if (!r.reference.p_world.col(k).allFinite()) {
      e << "reference step " << k << " is not finite; ";
      break;
    }
  }
  for (int k = 0; k < r.worker.steps(); ++k) {
    if (!r.worker.p_world.col(k).allFinite()) {
      e << "worker step " << k << " is not finite; ";
      break;
    }
  }
  for (std::size_t j = 0; j < r.higher_priority_plans.size(); ++j) {
    const auto& p = r.higher_priority_plans[j];
    bool ok = !p.samples.empty() && p.dt_s > 0.0 && std::isfinite(p.t0_s);
    for (const auto& smp : p.samples) ok = ok && smp.p_world.allFinite() && smp.v_world.allFinite();
    if (!ok) e << "higher_priority_plans[" << j << "] (uav " << p.uav_index << ") is empty or not finite; ";
  }
  const std::string out = e.str();
  return out.empty() ? out : "bad request: " + out.substr(0, out.size() - 2);
}

}  // namespace

// ---- construction -------------------------------------------------------------------------

UavPlanner::UavPlanner(const PlannerConfig& config, std::shared_ptr<const OccupancyMap> map,
                       std::shared_ptr<const DistanceField> field, std::shared_ptr<const SeenSpace> seen)
    : config_(config), map_(std::move(map)), field_(std::move(field)), seen_(std::move(seen)) {
  auto errors = config_.validate();
  if (!map_ || !field_) errors.push_back("map and distance field must be given");
  config_error_ = joinErrors(errors);
  if (!config_error_.empty()) config_ = PlannerConfig{};  // keep the object usable (brake only)
  CorridorConfig cc;
  cc.clearance_m = config_.obstacle_clearance_m;
  cc.local_box_margin_m = Eigen::Vector3d::Constant(config_.corridor_box_margin_m);
  // The QP shrinks every corridor by corridor_margin_m: the seed segment (which starts at the
  // current position) must stay inside the shrunk corridor, or a UAV closer to an obstacle
  // than the clearance has no feasible first sample (found in the power-tower mission).
  cc.seed_margin_m = config_.corridor_margin_m + 0.02;
  corridors_ = std::make_unique<CorridorBuilder>(cc);
  qp_ = std::make_unique<TrajectoryQp>();
  if (map_ && field_) {
    verifier_ = std::make_unique<TrajectoryVerifier>(*map_, *field_, config_, seen_.get());
    search_ = std::make_unique<GridPathSearch>(*map_, *field_);
  }
}

UavPlanner::~UavPlanner() = default;
UavPlanner::UavPlanner(UavPlanner&&) noexcept = default;
UavPlanner& UavPlanner::operator=(UavPlanner&&) noexcept = default;

void UavPlanner::reset() {
  last_verified_ = PlannedTrajectory{};
  brake_ = PlannedTrajectory{};
  flown_ = PlannedTrajectory{};
  tracking_deviation_m_ = 0.0;
  last_deviation_m_ = 0.0;
  wind_speeds_.clear();
  mean_wind_.setZero();
  sequence_ = 0;
}

void UavPlanner::updateTrackingAllowance(const PlanRequest& req) {
  if (!std::isfinite(req.t_now_s)) return;
  // The held deviation decays with the time since the last measurement ...
  const double elapsed = std::max(0.0, req.t_now_s - allowance_t_s_);
  tracking_deviation_m_ = std::max(0.0, tracking_deviation_m_ - config_.tracking_allowance_decay_mps * elapsed);
  allowance_t_s_ = req.t_now_s;
  // ... and grows to the deviation of the state from the plan being flown.
  last_deviation_m_ = 0.0;
  if (!flown_.empty() && req.state.p_world.allFinite()) {
    const double d = (evaluateTrajectory(flown_, req.t_now_s).p - req.state.p_world).norm();
    if (std::isfinite(d)) {
      tracking_deviation_m_ = std::max(tracking_deviation_m_, d);
      last_deviation_m_ = d;
    }
  }
}

double UavPlanner::updateWindAllowance(const PlanRequest& req) {
  if (!std::isfinite(req.t_now_s)) return 0.0;
  // A clock that jumps back (a restarted simulation, a replayed bag) starts a new window.
  if (!wind_speeds_.empty() && req.t_now_s < wind_speeds_.back().t_s) wind_speeds_.clear();
  const Eigen::Vector3d& w = req.wind_estimate_mps;
  if (w.head<2>().allFinite()) wind_speeds_.push_back({req.t_now_s, w.head<2>()});
  while (!wind_speeds_.empty() && wind_speeds_.front().t_s < req.t_now_s - config_.wind_window_s) {
    wind_speeds_.pop_front();
  }
  mean_wind_.setZero();
  if (wind_speeds_.empty()) return 0.0;
  double peak = 0.0;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const auto& e : wind_speeds_) {
    peak = std::max(peak, e.horizontal_mps.norm());
    sum += e.horizontal_mps;
  }
  mean_wind_.head<2>() = sum / static_cast<double>(wind_speeds_.size());
  return std::clamp(config_.wind_allowance_m_per_mps * (peak - config_.wind_allowance_from_mps), 0.0,
                    config_.wind_allowance_max_m);
}

// ---- fallbacks -------------------------------------------------------------------------------

PlannedTrajectory UavPlanner::brakePlan(const PlanRequest& req) const {
  PlannedTrajectory tr;
  tr.uav_index = req.uav_index;
  tr.t0_s = req.t_now_s;
  tr.dt_s = req.dt_s > 0.0 && std::isfinite(req.dt_s) ? req.dt_s : 0.2;
  const int n = std::max(2, req.reference.steps());
  const Eigen::Vector3d p0 = req.state.p_world;
  const Eigen::Vector3d v0 = req.state.v_world.allFinite() ? req.state.v_world : Eigen::Vector3d::Zero();
  const BrakeProfile brake = brakeProfile(v0, config_.limits, tr.dt_s);
  const Eigen::Vector3d dir = brake.dir;
  const double decel = brake.decel_mps2, t_stop = brake.t_stop_s;
  const Eigen::Vector3d p_stop = p0 + v0 * t_stop - 0.5 * decel * dir * t_stop * t_stop;
  for (int k = 0; k < n; ++k) {
    const double t = k * tr.dt_s;
    TrajectorySample s;
    if (t < t_stop - 1e-9) {
      s.p_world = p0 + v0 * t - 0.5 * decel * dir * t * t;
      s.v_world = v0 - decel * dir * t;
      s.a_world = -decel * dir;
    } else {
      s.p_world = p_stop;
    }
    tr.samples.push_back(s);
  }
  aimCamera(req, tr);
  return tr;
}

std::optional<PlannedTrajectory> UavPlanner::separateHoldPoint(const PlanRequest& req, const PlannedTrajectory& hold,
                                                               std::string& why) const {
  const int n = static_cast<int>(hold.samples.size());
  if (n < 2 || !verifier_) return std::nullopt;
  // What the stop point keeps away from: the other UAVs' plans (Γ_dis) and the worker's
  // predicted positions (worker_safety_distance_m), each plus the QP's buffer.
  struct Keep {
    std::function<Eigen::Vector3d(double)> at;
    double distance;  ///< the stop point's target distance
    double floor;     ///< a move must not enter it where the unmoved plan is outside (the verifier's requirement + buffer)
    std::string name;
  };
  std::vector<Keep> keep;
  for (const auto& other : req.higher_priority_plans) {
    if (other.empty()) continue;
    const double age = std::isfinite(req.t_now_s) ? std::max(0.0, req.t_now_s - other.t0_s) : 0.0;
    keep.push_back({[&other](double t) { return evaluateTrajectory(other, t).p; },
                    config_.mutual_distance_m + config_.qp_distance_buffer_m,
                    uavKeepOutDistance(config_, age) + config_.qp_distance_buffer_m,
                    "UAV " + std::to_string(other.uav_index)});
  }
  if (req.worker.steps() > 0 && req.worker.p_world.allFinite()) {
    const double d = config_.worker_safety_distance_m + config_.qp_distance_buffer_m;
    keep.push_back({[&req](double t) { return workerPositionAt(req.worker, req.t_now_s, req.dt_s, t); }, d, d, "the worker"});
  }
  if (keep.empty()) return std::nullopt;
  // First sample from which the plan stands still (the stop point).
  int k_stop = n - 1;
  while (k_stop > 0 && hold.samples[static_cast<std::size_t>(k_stop) - 1].v_world.norm() < 1e-9 &&
         (hold.samples[static_cast<std::size_t>(k_stop) - 1].p_world - hold.samples.back().p_world).norm() < 1e-9) {
    --k_stop;
  }
  const Eigen::Vector3d p_hold = hold.samples.back().p_world;
  Eigen::Vector3d away = Eigen::Vector3d::Zero();
  double deficit = 0.0;
  std::string closest;
  for (const auto& kp : keep) {
    double d_min = std::numeric_limits<double>::infinity();
    Eigen::Vector3d q_min = Eigen::Vector3d::Zero();
    for (int k = k_stop; k < n; ++k) {
      const Eigen::Vector3d q = kp.at(hold.t0_s + k * hold.dt_s);
      const double d = (p_hold - q).norm();
      if (d < d_min) d_min = d, q_min = q;
    }
    if (!(d_min < kp.distance) || !(d_min > 1e-6)) continue;
    away += (p_hold - q_min) / d_min * (kp.distance - d_min);
    if (kp.distance - d_min > deficit) deficit = kp.distance - d_min, closest = kp.name;
  }
  if (!(away.norm() > 1e-6) || !(deficit > 1e-3)) return std::nullopt;
  const double D = std::min(deficit, config_.fallback_max_deviation_m);
  // s(τ) = D (1 − cos(πτ/T)) / 2: peak speed Dπ/2T and acceleration Dπ²/2T² within the recovery
  // pace; T a whole number of samples, so that the move ends on a sample (no overshoot in between).
  const double T = hold.dt_s * std::ceil(std::max(D * M_PI / (2.0 * config_.recovery_speed_mps),
                                                  M_PI * std::sqrt(D / (2.0 * config_.recovery_acceleration_mps2))) /
                                         hold.dt_s - 1e-9);
  if (static_cast<double>(n - 1 - k_stop) * hold.dt_s < T) return std::nullopt;  // the move must end inside the plan
  const auto moveAlong = [&](const Eigen::Vector3d& dir) -> std::optional<PlannedTrajectory> {
    PlannedTrajectory moved = hold;
    for (int k = k_stop; k < n; ++k) {
      const double tau = (k - k_stop) * hold.dt_s;
      const double ph = tau < T ? M_PI * tau / T : M_PI;
      TrajectorySample& s = moved.samples[static_cast<std::size_t>(k)];
      s.p_world = p_hold + dir * (D * 0.5 * (1.0 - std::cos(ph)));
      s.v_world = tau < T ? Eigen::Vector3d(dir * (D * M_PI / (2.0 * T) * std::sin(ph))) : Eigen::Vector3d::Zero();
      s.a_world = tau < T ? Eigen::Vector3d(dir * (D * M_PI * M_PI / (2.0 * T * T) * std::cos(ph))) : Eigen::Vector3d::Zero();
    }
    aimCamera(req, moved);
    // Obstacles and limits: the verifier alone; the UAVs and the worker: never closer than the hold
    // where that is within their floor, never inside the floor where the hold is not.
    const VerificationReport rep = verifier_->verify(moved, req.t_now_s, {}, formation::WorkerHorizon{}, req.t_now_s, hold.dt_s);
    if (!rep.ok) return std::nullopt;
    for (const auto& kp : keep) {
      for (double t = hold.t0_s; t <= hold.tEnd() + 1e-9; t += hold.dt_s / 4.0) {
        const Eigen::Vector3d q = kp.at(t);
        // Closer only where it stays beyond the floor (a UAV 5 m off must not block a move by a
        // millimetre: dense pillars seed 3).
        const double d_hold = (evaluateTrajectory(hold, t).p - q).norm();
        if ((evaluateTrajectory(moved, t).p - q).norm() < std::min(d_hold, kp.floor) - 1e-6) return std::nullopt;
      }
    }
    return moved;
  };
  // Away from what it is too close to; when that is blocked (a pillar behind the UAV, another UAV
  // on the far side), straight up: among pillars and towers the way up is usually free, and it
  // leaves a worker on the ground below (dense pillars seed 3: a follower braked between a pillar
  // and the worker walking up to it, 1.89 m).
  const char* how = "away from ";
  std::optional<PlannedTrajectory> moved = moveAlong(away.normalized());
  if (!moved && away.normalized().z() < 1.0 - 1e-9) {
    moved = moveAlong(Eigen::Vector3d::UnitZ());
    how = "up, away from ";
  }
  if (!moved) return std::nullopt;
  std::ostringstream os;
  os.precision(3);
  os << "; moving the brake point " << D << " m " << how << closest;
  why = os.str();
  return moved;
}

void UavPlanner::aimCamera(const PlanRequest& req, PlannedTrajectory& tr) const {
  // Keep looking at the worker (or the search's targets) within the rate limits (closed-form
  // filter: no failure modes), else hold the current angles.
  const int n = static_cast<int>(tr.samples.size());
  CameraTrackingProblem cam;
  cam.dt_s = tr.dt_s;
  cam.heading0_rad = std::isfinite(req.state.heading_rad) ? req.state.heading_rad : 0.0;
  cam.pitch0_rad = std::isfinite(req.state.pitch_rad) ? req.state.pitch_rad : 0.0;
  const bool search = req.camera_target.cols() == n && req.camera_target.allFinite();
  const formation::HorizonPoints& target = search ? req.camera_target : req.worker.p_world;
  const bool worker_ok = search || (req.worker.steps() == n && req.worker.p_world.allFinite());
  if (worker_ok) {
    for (const auto& s : tr.samples) cam.p_world.push_back(s.p_world);
    for (int k = 0; k < n; ++k) cam.target_world.push_back(target.col(k));
    setCameraLimits(config_.limits, cam);
  }
  const CameraTrack track = worker_ok ? cameraFilter(cam) : CameraTrack{};
  for (int k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    tr.samples[i].heading_rad = track.ok ? track.heading_rad[i] : cam.heading0_rad;
    tr.samples[i].pitch_rad = track.ok ? track.pitch_rad[i] : cam.pitch0_rad;
  }
}

bool UavPlanner::reusePrevious(const PlanRequest& req, PlanResult& result, std::string& why_not) {
  const bool state_finite = req.state.p_world.allFinite();
  const int n = std::max(2, req.reference.steps());
  const double dt = req.dt_s > 0.0 && std::isfinite(req.dt_s) ? req.dt_s : 0.2;
  if (last_verified_.empty()) {
    why_not = "no previous plan";
    return false;
  }
  if (!std::isfinite(req.t_now_s) || last_verified_.tEnd() < req.t_now_s + config_.fallback_min_horizon_s) {
    std::ostringstream os;
    os << "previous plan ends at " << last_verified_.tEnd() << " s, before t_now + " << config_.fallback_min_horizon_s << " s";
    why_not = os.str();
    return false;
  }
  const TrajectoryPoint at_now = evaluateTrajectory(last_verified_, req.t_now_s);
  const double deviation = (at_now.p - req.state.p_world).norm();
  if (state_finite && !(deviation <= config_.fallback_max_deviation_m)) {
    std::ostringstream os;
    os << "previous plan is " << deviation << " m from the state";
    why_not = os.str();
    return false;
  }
  PlannedTrajectory prev = retimeThenBrake(last_verified_, req.t_now_s, dt, n, config_.limits);
  prev.uav_index = req.uav_index;
  const VerificationReport rep =
      verifier_ ? verifier_->verify(prev, req.t_now_s, req.higher_priority_plans, req.worker, req.t_now_s, dt)
                : VerificationReport{};
  if (!rep.ok) {
    why_not = "previous plan fails now: " + rep.reason;
    return false;
  }
  result.trajectory = prev;
  result.status = PlanStatus::kFallbackPrevious;
  result.verified = true;
  result.min_obstacle_clearance_m = rep.min_obstacle_clearance_m;
  result.min_uav_margin_m = rep.min_uav_margin_m;
  result.min_worker_distance_m = rep.min_worker_distance_m;
  result.reason += "; reusing verified plan #" + std::to_string(last_verified_.sequence);
  if (brake_.sequence != last_verified_.sequence) brake_ = PlannedTrajectory{};  // another plan is flown now
  result.trajectory.sequence = ++sequence_;
  return true;
}

PlanResult UavPlanner::fallback(const PlanRequest& req, PlanResult result, const std::string& reason) {
  const auto t_fb = Clock::now();
  result.reason = reason;
  const bool state_finite = req.state.p_world.allFinite();
  const int n = std::max(2, req.reference.steps());
  const double dt = req.dt_s > 0.0 && std::isfinite(req.dt_s) ? req.dt_s : 0.2;
  // 1. The last verified plan, re-timed to t_now, if it still covers enough and verifies now
  // (unless the request prefers not to: then only when the brake plan does not verify, below).
  std::string why_not;
  if (last_verified_.empty()) {
    why_not = "no previous plan";
  } else if (!req.reuse_previous) {
    why_not = req.no_reuse_reason;
  } else if (reusePrevious(req, result, why_not)) {
    result.timings.verify_ms += msSince(t_fb);
    return result;
  }
  // 2. Last resort: brake to hover along the current velocity.
  result.status = PlanStatus::kFallbackBrake;
  result.reason += "; " + why_not + "; braking to hover";
  if (!state_finite) {
    result.trajectory = PlannedTrajectory{};
    result.trajectory.uav_index = req.uav_index;
    result.verified = false;
    result.reason += " impossible (state position not finite): empty trajectory";
    result.timings.verify_ms += msSince(t_fb);
    return result;
  }
  // Keep the brake point while the failures go on (docs/planning.md §8): re-anchoring the brake
  // plan at the state every replanning lets the UAV drift with its tracking error (wind).
  std::string held;
  if (!brake_.empty() && std::isfinite(req.t_now_s)) {
    const double deviation = (evaluateTrajectory(brake_, req.t_now_s).p - req.state.p_world).norm();
    if (deviation <= config_.fallback_max_deviation_m) {
      PlannedTrajectory again;
      again.uav_index = req.uav_index;
      again.t0_s = req.t_now_s;
      again.dt_s = dt;
      for (int k = 0; k < n; ++k) {
        const TrajectoryPoint x = evaluateTrajectory(brake_, req.t_now_s + k * dt);  // after its end: the stop point
        TrajectorySample s;
        s.p_world = x.p;
        s.v_world = x.v;
        s.a_world = x.a;
        again.samples.push_back(s);
      }
      aimCamera(req, again);
      result.trajectory = again;
      held = "; holding the brake point of plan #" + std::to_string(brake_.sequence);
    } else {
      std::ostringstream os;
      os << "; the state is " << deviation << " m from the brake plan #" << brake_.sequence << ": braking anew";
      held = os.str();
      brake_ = PlannedTrajectory{};
    }
  }
  if (brake_.empty()) result.trajectory = brakePlan(req);
  result.reason += held;
  // Brake points are not chosen against each other, and a hovering UAV drifts: a stop point
  // closer than Γ_dis + buffer to another UAV's plan is moved away (docs/safety.md §4.4).
  std::string separated;
  PlannedTrajectory unmoved;
  if (auto moved = separateHoldPoint(req, result.trajectory, separated)) {
    unmoved = std::move(result.trajectory);
    result.trajectory = std::move(*moved);
  }
  result.trajectory.sequence = ++sequence_;
  if (verifier_) {
    const auto verify = [&](const PlannedTrajectory& tr) {
      return verifier_->verify(tr, req.t_now_s, req.higher_priority_plans, req.worker, req.t_now_s, dt);
    };
    VerificationReport rep = verify(result.trajectory);
    if (!rep.ok && !unmoved.empty()) {
      // The move is checked against the others and the worker only pointwise (never closer than
      // the hold where that is near): where the full check (braking envelopes, recovery pace)
      // refuses it and the unmoved brake plan verifies, the unmoved one is flown.
      unmoved.sequence = result.trajectory.sequence;
      const VerificationReport rep_unmoved = verify(unmoved);
      if (rep_unmoved.ok) {
        separated = "; not moving the brake point (the move fails: " + rep.reason + ")";
        result.trajectory = std::move(unmoved);
        rep = rep_unmoved;
      }
    }
    result.reason += separated;
    result.verified = rep.ok;
    result.min_obstacle_clearance_m = rep.min_obstacle_clearance_m;
    result.min_uav_margin_m = rep.min_uav_margin_m;
    result.min_worker_distance_m = rep.min_worker_distance_m;
    if (rep.ok) {
      last_verified_ = result.trajectory;  // the UAV now executes it; reusable next time
    } else {
      result.reason += " (brake plan NOT verified: " + rep.reason + ")";
      // Verified first: the previous plan the request preferred not to re-fly, if it verifies now.
      std::string why_not_previous;
      if (!req.reuse_previous) {
        if (reusePrevious(req, result, why_not_previous)) {
          result.reason += "; " + req.no_reuse_reason + ", but it verifies where the brake plan does not";
          result.timings.verify_ms += msSince(t_fb);
          return result;
        }
        result.reason += "; nor the previous plan: " + why_not_previous;
      }
    }
  } else {
    result.reason += separated;
  }
  brake_ = result.trajectory;  // held: the same curve (re-timed), now under this sequence number
  result.timings.verify_ms += msSince(t_fb);
  return result;
}

// ---- the three stages ------------------------------------------------------------------------

/// What one replanning's stages hand each other (docs/planning.md §5–§8): the request's
/// constants, then the path, the corridors, the QP and its solution, the camera angles.
struct UavPlanner::PlanContext {
  PlanContext(const PlanRequest& request, Clock::time_point start) : req(request), t_start(start) {}

  const PlanRequest& req;
  Clock::time_point t_start;
  double allowance = 0.0;  ///< tracking + wind allowance added to the planning clearances
  double wind_allowance = 0.0;  ///< the wind's part of it (PlanResult::wind_allowance_m)
  Eigen::Vector3d downwind = Eigen::Vector3d::Zero();  ///< horizontal unit vector of the window's mean wind estimate
  double res = 0.0;        ///< map resolution
  double dt = 0.0;
  int N = 0;  ///< intervals of the horizon
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero();
  bool has_worker = false;
  double worker_keep = 0.0;  ///< worker safety distance + QP buffer
  double path_clear = 0.0;   ///< path clearance (planning, not verification) + allowance
  double seg_clear = 0.0;    ///< corridor clearance + allowance
  double start_clear = 0.0;  ///< the start's distance to the nearest obstacle
  // Stage 2
  std::vector<Eigen::Vector3d> ref;  ///< projected references, index 0 = p0
  KeepOutTube worker_tube;
  std::vector<Eigen::Vector3d> path;
  bool path_around_worker = false;
  // Stage 3
  std::vector<SegmentCorridor> corridors;
  std::vector<int> seg;                 ///< corridor of sample k (guide's segment)
  std::vector<Eigen::Vector3d> guide;   ///< guide point of sample k on the path
  TrajectoryQpProblem qp;
  bool have_prev = false;  ///< the last verified plan covers t_now (linearisation, warm start)
  TrajectoryQpSolution sol;
  std::vector<double> heading, pitch;

  /// The worker's keep-out tube for the segment a→b, shrunk so that neither end lies inside it.
  KeepOutTube keepOutFor(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
    KeepOutTube tube = worker_tube;
    if (tube.polyline_world.empty()) return tube;
    tube.radius_m = std::min({worker_keep, tube.distance(a) - res, tube.distance(b) - res});
    return tube;
  }
  /// Clearance a segment from waypoint `i` must keep (less for the first, from a start that is closer).
  double segmentClearance(bool from_start) const {
    return from_start ? std::min(seg_clear, start_clear - res) : seg_clear;
  }
};

namespace {

/// Greedy merge: extend a segment over the following waypoints while it stays clear and
/// every skipped waypoint lies within the merge tolerance of it.
template <typename SegmentOk>
std::vector<Eigen::Vector3d> mergeWaypoints(const std::vector<Eigen::Vector3d>& raw, double tolerance_m,
                                            const SegmentOk& segment_ok) {
  std::vector<Eigen::Vector3d> path{raw.front()};
  std::size_t i = 0;
  while (i + 1 < raw.size()) {
    std::size_t j = i + 1;
    while (j + 1 < raw.size()) {
      const std::size_t c = j + 1;
      const Eigen::Vector3d a = raw[i], b = raw[c];
      const Eigen::Vector3d ab = b - a;
      const double L2 = ab.squaredNorm();
      bool close = true;
      for (std::size_t m = i + 1; m < c && close; ++m) {
        const double s = L2 > 0 ? std::clamp((raw[m] - a).dot(ab) / L2, 0.0, 1.0) : 0.0;
        close = (raw[m] - (a + s * ab)).norm() <= tolerance_m;
      }
      if (!close || !segment_ok(i, a, b)) break;
      j = c;
    }
    path.push_back(raw[j]);
    i = j;
  }
  return path;
}

}  // namespace

PlanResult UavPlanner::plan(const PlanRequest& req) {
  PlanContext ctx(req, Clock::now());
  PlanResult result;
  result.trajectory.uav_index = req.uav_index;
  updateTrackingAllowance(req);
  const double wind_allowance = updateWindAllowance(req);
  ctx.allowance = std::clamp(tracking_deviation_m_, config_.tracking_allowance_min_m + wind_allowance,
                             config_.tracking_allowance_max_m + wind_allowance);
  result.tracking_allowance_m = ctx.allowance;
  result.tracking_deviation_m = last_deviation_m_;
  result.wind_allowance_m = wind_allowance;
  ctx.wind_allowance = wind_allowance;
  if (wind_allowance > 0.0 && mean_wind_.norm() > 1e-6) ctx.downwind = mean_wind_.normalized();
  const auto finish = [&](PlanResult r) {
    flown_ = r.trajectory;
    r.timings.total_ms = msSince(ctx.t_start);
    return r;
  };
  std::string failure;
  if (!config_error_.empty()) {
    failure = "invalid planner config: " + config_error_;
  } else if (!req.state.p_world.allFinite()) {
    failure = "bad request: state.p_world is not finite";
  } else {
    failure = checkRequest(req);
  }
  if (failure.empty()) failure = runStages(ctx, result);
  if (!failure.empty()) return finish(fallback(req, result, failure));
  return finish(result);
}

std::string UavPlanner::runStages(PlanContext& ctx, PlanResult& result) {
  const PlanRequest& req = ctx.req;
  ctx.res = map_->resolution();
  ctx.dt = req.dt_s;
  ctx.N = req.reference.steps() - 1;
  ctx.p0 = req.state.p_world;
  ctx.has_worker = req.worker.steps() > 0;
  ctx.worker_keep = config_.worker_safety_distance_m + config_.qp_distance_buffer_m;
  // Obstacle clearances of planning (not of verification) grown by the tracking allowance.
  ctx.path_clear = config_.path_clearance_m + ctx.allowance;
  ctx.seg_clear = config_.obstacle_clearance_m + ctx.allowance;
  ctx.start_clear = field_->clearance(ctx.p0);

  auto t_stage = Clock::now();
  projectReferences(ctx, result);
  planPath(ctx, result);
  result.timings.path_ms = msSince(t_stage);

  t_stage = Clock::now();
  std::string failure = buildCorridors(ctx);
  result.timings.corridor_ms = msSince(t_stage);
  if (!failure.empty()) return failure;
  result.corridor_count = static_cast<int>(ctx.corridors.size());

  t_stage = Clock::now();
  setUpQp(ctx);
  guideAlongPath(ctx);
  addCorridorRows(ctx, result);
  result.corridors = std::move(ctx.corridors);  // for display; not used below
  addRecoveryRows(ctx, result);
  addSeparationRows(ctx);
  failure = solveQp(ctx, result);
  result.timings.qp_ms = msSince(t_stage);
  if (!failure.empty()) return failure;

  t_stage = Clock::now();
  failure = planCamera(ctx);
  result.timings.heading_ms = msSince(t_stage);
  if (!failure.empty()) return failure;

  return verifyAndAccept(ctx, result);
}

// ---- stage 2: project the references, connect them, merge -----------------------------------

void UavPlanner::projectReferences(PlanContext& c, PlanResult& result) const {
  const PlanRequest& req = c.req;
  c.ref.assign(static_cast<std::size_t>(c.N) + 1, c.p0);
  // The UAVs silent for as long as their keep-out's bound (aroundSilentUavs).
  std::vector<const PlannedTrajectory*> silent;
  const double bound = uavKeepOutDistance(config_, std::numeric_limits<double>::infinity());
  for (const auto& other : req.higher_priority_plans) {
    if (!other.empty() && uavKeepOutDistance(config_, req.t_now_s - other.t0_s) >= bound - 1e-9) silent.push_back(&other);
  }
  for (auto it = silent_turn_side_.begin(); it != silent_turn_side_.end();) {  // forget UAVs heard again
    const bool still = std::any_of(silent.begin(), silent.end(), [&](const PlannedTrajectory* p) { return p->uav_index == it->first; });
    it = still ? std::next(it) : silent_turn_side_.erase(it);
  }
  for (int k = 1; k <= c.N; ++k) {
    Eigen::Vector3d r = req.reference.p_world.col(k);
    bool moved = false;
    if (c.has_worker) {  // out of the worker's safety sphere, horizontally away from it
      const Eigen::Vector3d w = req.worker.p_world.col(k);
      Eigen::Vector3d d = r - w;
      if (d.norm() < c.worker_keep) {
        Eigen::Vector3d h(d.x(), d.y(), 0.0);
        if (h.norm() < 1e-6) h = Eigen::Vector3d(c.p0.x() - w.x(), c.p0.y() - w.y(), 0.0);
        if (h.norm() < 1e-6) h = Eigen::Vector3d::UnitX();
        d = d + h.normalized() * (c.worker_keep - d.norm() + 1e-3);
        if (d.norm() < c.worker_keep) d = d.normalized() * (c.worker_keep + 1e-3);
        r = w + d;
        moved = true;
      }
    }
    if (c.has_worker && aroundSilentUavs(c, silent, k, r)) moved = true;
    const auto proj = projectToClearance(*field_, *map_, r, c.path_clear, config_.max_projection_m);
    if (proj) {
      moved = moved || (*proj - r).norm() > 1e-9;
      r = *proj;
    } else {
      r = c.ref[static_cast<std::size_t>(k) - 1];  // nothing clear nearby: hold the previous target
      moved = true;
    }
    if (moved) ++result.projected_references;
    c.ref[static_cast<std::size_t>(k)] = r;
  }
}

bool UavPlanner::aroundSilentUavs(const PlanContext& c, const std::vector<const PlannedTrajectory*>& silent, int k,
                                  Eigen::Vector3d& r) const {
  // A UAV silent for as long as its keep-out's bound (docs/safety.md §1.3) hovers where its last
  // plan ended, and a reference there can never be reached: the UAV would press against the
  // keep-out wherever the QP leaves it (a new leader whose slot the silent old leader still holds:
  // 16 m from the worker at his feet's height, outside the cameras' envelope; §1.2). Such a
  // reference turns about the vertical through the worker — distance and elevation kept, so the
  // view stays in the envelope — on the side of the silent UAV the UAV is on (latched per silent
  // UAV) by the least angle in 5° steps that takes it out of every silent UAV's keep-out + buffer.
  if (silent.empty()) return false;
  const double t = c.req.t_now_s + k * c.dt;
  const double keep = uavKeepOutDistance(config_, std::numeric_limits<double>::infinity()) + config_.qp_distance_buffer_m;
  std::vector<Eigen::Vector3d> at_t;
  for (const PlannedTrajectory* other : silent) at_t.push_back(evaluateTrajectory(*other, t).p);
  const auto clear = [&](const Eigen::Vector3d& q) {
    return std::all_of(at_t.begin(), at_t.end(), [&](const Eigen::Vector3d& o) { return (q - o).norm() >= keep; });
  };
  const auto inside = std::find_if(at_t.begin(), at_t.end(), [&](const Eigen::Vector3d& o) { return (r - o).norm() < keep; });
  if (inside == at_t.end()) return false;
  const int blocker = silent[static_cast<std::size_t>(inside - at_t.begin())]->uav_index;
  const Eigen::Vector3d w = c.req.worker.p_world.col(k);
  const Eigen::Vector3d d = r - w;
  // Latched so that the reference neither crosses over the worker nor swaps sides later; taken from
  // the silent UAV's azimuth, not the reference's: the first reference turned may be the UAV's own
  // slot on its own azimuth, where that side is a coin toss, and the latch then sent the slot the
  // silent UAV holds round the far side, over the tower (leader_dropout_for_good seed 157).
  const Eigen::Vector2d from_w(c.p0.x() - w.x(), c.p0.y() - w.y());
  const Eigen::Vector3d b = *inside - w;
  auto latched = silent_turn_side_.find(blocker);
  if (latched == silent_turn_side_.end()) {
    latched = silent_turn_side_.emplace(blocker, b.x() * from_w.y() - b.y() * from_w.x() >= 0.0 ? 1.0 : -1.0).first;
  }
  const double side = latched->second;
  constexpr double kStep = 5.0 * M_PI / 180.0;
  for (double sgn : {side, -side}) {
    for (int i = 1; i * kStep <= M_PI + 1e-9; ++i) {
      const Eigen::Vector3d q = w + Eigen::AngleAxisd(sgn * i * kStep, Eigen::Vector3d::UnitZ()) * d;
      if (clear(q)) {
        r = q;
        return true;
      }
    }
  }
  return false;  // nowhere around the worker: the QP's rows keep it out
}

void UavPlanner::planPath(PlanContext& c, PlanResult& result) const {
  const PlanRequest& req = c.req;
  // The worker's keep-out for the path: a tube around his predicted positions over the horizon
  // (a ball for a standing worker). A straight segment to a reference far away may pass right by
  // him, and where obstacles make the corridor around that segment a sliver the QP cannot bend
  // around him (harsh seed 65: the leader stuck for 180 s beside the tower he climbed, every
  // replanning infeasible; docs/planning.md §5). Shrunk per segment so that neither end lies
  // inside it (a worker who walked up to the UAV; a reference on his track that he will have
  // passed when the UAV gets there): the QP's half-spaces keep the full distance in time.
  if (c.has_worker) {
    std::vector<Eigen::Vector3d> track;
    for (int k = 0; k < req.worker.steps(); ++k) track.push_back(req.worker.p_world.col(k));
    c.worker_tube.polyline_world = simplifyPolyline(track, 0.05);  // within 5 cm of every step
  }
  // Waypoints: the current position, then the projected references (duplicates dropped),
  // with A* detours where the straight segment is not clear.
  std::vector<Eigen::Vector3d> raw{c.p0};
  for (int k = 1; k <= c.N; ++k) {
    const Eigen::Vector3d& target = c.ref[static_cast<std::size_t>(k)];
    if ((target - raw.back()).norm() < 1e-3) continue;
    const KeepOutTube tube = c.keepOutFor(raw.back(), target);
    const bool outside = tube.segmentOutside(raw.back(), target);
    if (segmentClear(*field_, c.res, raw.back(), target, c.segmentClearance(raw.size() == 1)) && outside) {
      raw.push_back(target);
      continue;
    }
    c.path_around_worker = c.path_around_worker || !outside;
    ++result.path_searches;
    GridPathSearch::Stats stats;
    const auto detour = search_->search(raw.back(), target, c.path_clear, c.seg_clear, config_.search_margin_m,
                                        config_.search_max_expansions, &stats, tube);
    result.path_search_expansions += stats.expansions;
    if (!detour) {
      // The rest of the reference is unreachable for now: the path ends here, and so do the QP's
      // references — pulled towards points it cannot reach, every sample pressed against the
      // walls of the corridor left (a formation point inside a tower's lattice: 25–80 ProxQP
      // iterations a replanning instead of 3, docs/planning.md §10).
      ++result.path_searches_failed;
      for (int j = k; j <= c.N; ++j) c.ref[static_cast<std::size_t>(j)] = raw.back();
      break;
    }
    for (std::size_t i = 1; i < detour->size(); ++i) raw.push_back((*detour)[i]);
  }
  c.path = mergeWaypoints(raw, config_.path_merge_tolerance_m,
                          [&](std::size_t i, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
                            return segmentClear(*field_, c.res, a, b, c.segmentClearance(i == 0)) &&
                                   c.keepOutFor(a, b).segmentOutside(a, b);
                          });
  if (c.path.size() == 1) {  // already at the (static) reference: a short segment to hold a corridor
    Eigen::Vector3d d = req.state.v_world.norm() > 1e-3 ? Eigen::Vector3d(req.state.v_world.normalized()) : Eigen::Vector3d::UnitZ();
    c.path.push_back(c.p0 + 0.05 * d);
  }
  result.path_world = c.path;
}

// ---- stage 3a: corridors --------------------------------------------------------------------

std::string UavPlanner::buildCorridors(PlanContext& c) const {
  c.corridors.reserve(c.path.size() - 1);
  std::unique_ptr<CorridorBuilder> inflated;
  if (c.allowance > 0.0) {
    CorridorConfig cc = corridors_->config();
    cc.clearance_m += c.allowance;
    inflated = std::make_unique<CorridorBuilder>(cc);
  }
  const CorridorBuilder& builder = inflated ? *inflated : *corridors_;
  const std::unique_ptr<CorridorBuilder> first_builder = firstCorridorBuilder(c);
  for (std::size_t i = 0; i + 1 < c.path.size(); ++i) {
    auto corridor = (i == 0 && first_builder ? *first_builder : builder).buildSegment(c.path[i], c.path[i + 1], *map_);
    if (!corridor) return "corridor " + std::to_string(i) + ": " + corridor.reason();
    c.corridors.push_back(std::move(corridor.value()));
  }
  return {};
}

std::unique_ptr<CorridorBuilder> UavPlanner::firstCorridorBuilder(const PlanContext& c) const {
  // A start closer to an obstacle than the corridor clearance (flying low over the ground, a
  // gust): the first corridor is asked for a little less than the start has — its exact distance
  // to the nearest voxel centre − the builder's seed margin (the ends lie that far inside every
  // plane) − kFirstCorridorGap — not less than the verifier's clearance. Asked for more, the builder
  // shrinks its planes point by point around the start — a fan of ~100 planes for a start near
  // flat ground, whose QP rows (× 40 samples) made single replannings take seconds; within ~1 cm of
  // that distance the fan appears too (tangent planes through points just beyond the start). Not
  // less: the corridor must not let the UAV much closer than it is (the move-away rows below ask
  // it to recover).
  if (!(c.start_clear < c.seg_clear)) return nullptr;
  constexpr double kFirstCorridorGap = 0.03;
  std::vector<Eigen::Vector3d> near;
  map_->pointsInBox(Aabb{c.p0 - Eigen::Vector3d::Constant(c.seg_clear), c.p0 + Eigen::Vector3d::Constant(c.seg_clear)}, near);
  double d_exact = std::numeric_limits<double>::infinity();
  for (const auto& q : near) d_exact = std::min(d_exact, (q - c.p0).norm());
  CorridorConfig cc = corridors_->config();
  const double first_clear = std::clamp(d_exact - cc.seed_margin_m - kFirstCorridorGap,
                                        config_.verify_clearance_m + OccupancyMap::rasterInflation(c.res), c.seg_clear);  // to centres
  if (!(first_clear < c.seg_clear - 1e-9)) return nullptr;
  cc.clearance_m = first_clear;
  return std::make_unique<CorridorBuilder>(cc);
}

// ---- stage 3b: QP rows ----------------------------------------------------------------------

void UavPlanner::setUpQp(PlanContext& c) const {
  TrajectoryQpProblem& qp = c.qp;
  qp.dt_s = c.dt;
  qp.intervals = c.N;
  qp.p0 = c.p0;
  qp.v0 = c.req.state.v_world;
  qp.a0 = c.req.state.a_world;
  qp.reference = c.ref;
  qp.velocity = NormPolygon{config_.limits.max_speed_mps, config_.limits.max_vertical_speed_mps};
  qp.acceleration = NormPolygon{config_.limits.max_acceleration_mps2, config_.limits.max_vertical_acceleration_mps2};
  qp.w_reference = config_.weights.reference;
  qp.w_acceleration = config_.weights.acceleration;
  qp.w_jerk = config_.weights.jerk;
  qp.w_terminal_velocity = config_.weights.terminal_velocity;
  qp.eps_abs = config_.qp_eps_abs;
  qp.max_iterations = config_.qp_max_iterations;
  qp.solve_timeout_s = config_.qp_solve_timeout_s;
  c.have_prev = !last_verified_.empty() && last_verified_.tEnd() > c.req.t_now_s;
}

void UavPlanner::guideAlongPath(PlanContext& c) {
  // Assignment of samples to corridors: a guide point moves along the path no faster than the
  // inner speed/acceleration sets allow (70 %), towards the projection of r_k, stopping on
  // every waypoint it passes; sample k must lie in the corridors of the guide's segments at
  // k−1 and k (so every chord x_{k−1}x_k lies in one convex corridor).
  const std::vector<Eigen::Vector3d>& path = c.path;
  const int M = static_cast<int>(path.size()) - 1;
  const double dt = c.dt;
  std::vector<double> S(static_cast<std::size_t>(M) + 1, 0.0);
  for (int i = 0; i < M; ++i) S[static_cast<std::size_t>(i) + 1] = S[static_cast<std::size_t>(i)] + (path[static_cast<std::size_t>(i) + 1] - path[static_cast<std::size_t>(i)]).norm();
  const auto segOf = [&](double sigma) {
    int s = static_cast<int>(std::upper_bound(S.begin(), S.end(), sigma + 1e-12) - S.begin()) - 1;
    return std::clamp(s, 0, M - 1);
  };
  const auto tangent = [&](int s) {
    const Eigen::Vector3d d = path[static_cast<std::size_t>(s) + 1] - path[static_cast<std::size_t>(s)];
    return Eigen::Vector3d(d / std::max(d.norm(), 1e-12));
  };
  c.seg.assign(static_cast<std::size_t>(c.N) + 1, 0);
  c.guide.assign(static_cast<std::size_t>(c.N) + 1, c.p0);
  double sigma = 0.0, target_sigma = 0.0;
  double u = std::max(0.0, c.req.state.v_world.dot(tangent(0)));
  int search_from = 0;
  for (int k = 1; k <= c.N; ++k) {
    // Projection of r_k onto the path (monotone, a window of segments ahead).
    double best = std::numeric_limits<double>::infinity(), best_sigma = target_sigma;
    for (int s = search_from; s < std::min(M, search_from + 12); ++s) {
      const Eigen::Vector3d a = path[static_cast<std::size_t>(s)], b = path[static_cast<std::size_t>(s) + 1];
      const Eigen::Vector3d ab = b - a;
      const double t = std::clamp((c.ref[static_cast<std::size_t>(k)] - a).dot(ab) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
      const double d = (c.ref[static_cast<std::size_t>(k)] - (a + t * ab)).norm();
      if (d < best - 1e-9) best = d, best_sigma = S[static_cast<std::size_t>(s)] + t * ab.norm();
    }
    target_sigma = std::max(target_sigma, best_sigma);
    const int s_prev = segOf(sigma);
    search_from = s_prev;
    const Eigen::Vector3d t_dir = tangent(s_prev);
    const double v_cap = 0.7 * supportAlong(c.qp.velocity, t_dir);
    const double a_cap = 0.5 * supportAlong(c.qp.acceleration, t_dir);
    u = std::min(u + a_cap * dt, v_cap);
    double next = std::min(target_sigma, sigma + u * dt);
    const double boundary = S[static_cast<std::size_t>(s_prev) + 1];
    if (s_prev < M - 1 && next > boundary) next = boundary;  // stop on the waypoint
    if (next < sigma + u * dt) u = (next - sigma) / dt;       // waiting slows the guide down
    sigma = std::min(next, S.back());
    const int s = segOf(sigma);
    c.seg[static_cast<std::size_t>(k)] = s;
    const double local = std::clamp(sigma - S[static_cast<std::size_t>(s)], 0.0, S[static_cast<std::size_t>(s) + 1] - S[static_cast<std::size_t>(s)]);
    c.guide[static_cast<std::size_t>(k)] = path[static_cast<std::size_t>(s)] + local * tangent(s);
  }
}

namespace {
constexpr double kMomentumAccelShare = 0.7, kMomentumCushion = 0.02;
}  // namespace

void UavPlanner::addCorridorRows(PlanContext& c, PlanResult& result) const {
  // Corridor rows, pruned when the sample cannot reach them (‖x_k − p0‖ ≤ v_max t_k). A row the
  // UAV cannot meet (with a 2 cm cushion) even braking with all its acceleration — its momentum
  // carries it over the plane (leastReach) — is moved out to where it can braking at 70 %, by at
  // most the tracking allowance: the part of the corridor clearance that is there to absorb
  // deviations from the plan, and never closer to the obstacle points behind it than the
  // verifier's clearance (catch-up 18–34 m low over the
  // ground: the plan flown descended towards its floor, the new corridor's floor was 2 cm too high
  // for the state; docs/planning.md §12). Rows it can meet are not touched (plans unchanged); a row
  // still out of reach after the allowance leaves the QP infeasible: the planner falls back.
  TrajectoryQpProblem& qp = c.qp;
  const double vmax = config_.limits.max_speed_mps;
  const double verify_clear = config_.verify_clearance_m + OccupancyMap::rasterInflation(c.res);  // to voxel centres
  struct Reach {
    std::vector<double> full, soft;  // leastReach braking fully / at kMomentumAccelShare, per k
  };
  std::vector<std::vector<Reach>> least(c.corridors.size());  // [corridor][row], computed lazily
  for (int k = 1; k <= c.N; ++k) {
    const double reach = vmax * k * c.dt;
    const int s_prev = c.seg[static_cast<std::size_t>(k) - 1], s_cur = c.seg[static_cast<std::size_t>(k)];
    for (int s : {s_prev, s_cur}) {
      const Polytope& P = c.corridors[static_cast<std::size_t>(s)].polytope;
      // Not the wind's part: that is kept for the gust still to come (docs/safety.md §4.13).
      const double cap = std::min(c.allowance - c.wind_allowance, c.corridors[static_cast<std::size_t>(s)].clearance_m - verify_clear);
      auto& rows_least = least[static_cast<std::size_t>(s)];
      if (rows_least.empty()) rows_least.resize(static_cast<std::size_t>(P.rows()));
      for (int r = 0; r < P.rows(); ++r) {
        const Eigen::Vector3d a = P.A.row(r).transpose();
        double b = P.b(r) - config_.corridor_margin_m;
        // A plane downwind keeps the wind allowance once more: gusts push along the mean wind
        // (docs/safety.md §4.13). A start already inside that band must only not get closer.
        const double downwind = c.wind_allowance * std::max(0.0, a.dot(c.downwind));
        if (downwind > 0.0) b = std::min(b, std::max(b - downwind, a.dot(c.p0)));
        if (a.dot(c.p0) + reach < b) continue;  // unreachable plane
        Reach& lr = rows_least[static_cast<std::size_t>(r)];
        if (lr.full.empty()) lr.full = leastReach(a, c.p0, qp.v0, qp.a0, qp.velocity, qp.acceleration, 1.0, c.dt, c.N);
        if (lr.full[static_cast<std::size_t>(k)] + kMomentumCushion > b && cap > 0.0) {
          if (lr.soft.empty()) lr.soft = leastReach(a, c.p0, qp.v0, qp.a0, qp.velocity, qp.acceleration, kMomentumAccelShare, c.dt, c.N);
          b = std::min(lr.soft[static_cast<std::size_t>(k)] + kMomentumCushion, b + cap);
          ++result.momentum_relaxed_rows;
        }
        qp.constraints.push_back(PositionConstraint{k, a, b, PositionConstraint::Kind::kCorridor});
      }
      if (s_prev == s_cur) break;
    }
  }
}

void UavPlanner::addRecoveryRows(PlanContext& c, PlanResult& result) const {
  // Closer to obstacles than the corridor clearance (gusts, a corridor that had to shrink
  // around the start): move away along the distance field's gradient at the recovery pace
  // until the clearance is back, instead of hovering where the last plan left the UAV.
  const DistanceField& field = *field_;
  const Eigen::Vector3d& p0 = c.p0;
  const double d_start = field.clearance(p0);
  if (!(d_start < c.seg_clear)) return;
  Eigen::Vector3d g;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d e = Eigen::Vector3d::Unit(i) * c.res;
    g(i) = (field.clearance(p0 + e) - field.clearance(p0 - e)) / (2.0 * c.res);
  }
  if (!g.allFinite() || !(g.norm() > 1e-6)) return;
  const Eigen::Vector3d away = g.normalized();
  TrajectoryQpProblem& qp = c.qp;
  // Not faster than the UAV can turn round: moving towards the obstacle it first has to stop.
  // Largest away·(x_k − p0) braking fully / at 70 %, less the cushion:
  const auto most = [&](double share) {
    std::vector<double> m = leastReach(-away, p0, qp.v0, qp.a0, qp.velocity, qp.acceleration, share, c.dt, c.N);
    for (double& x : m) x = -(x + kMomentumCushion) - away.dot(p0);
    return m;
  };
  const std::vector<double> most_full = most(1.0), most_soft = most(kMomentumAccelShare);
  for (int k = 1; k <= c.N; ++k) {
    double gain = std::min(c.seg_clear - d_start,
                           -0.5 * config_.recovery_slack_m + 1.2 * recoveryAllowance(config_, k * c.dt));
    // away·(x_k − p0) ≥ gain  ⇔  (−away)·x_k ≤ −away·p0 − gain
    if (gain > most_full[static_cast<std::size_t>(k)]) {
      gain = most_soft[static_cast<std::size_t>(k)];
      ++result.momentum_relaxed_rows;
    }
    qp.constraints.push_back(PositionConstraint{k, -away, -away.dot(p0) - gain, PositionConstraint::Kind::kCorridor});
  }
}

Eigen::Vector3d UavPlanner::linearisationPoint(const PlanContext& c, int k) const {
  // The last verified plan at t_k, else the current position.
  return c.have_prev ? evaluateTrajectory(last_verified_, c.req.t_now_s + k * c.dt).p : c.p0;
}

void UavPlanner::addSeparationRows(PlanContext& c) const {
  const PlanRequest& req = c.req;
  // Half-space keeping x_k at least `margin` from o, linearised at the last plan (at_guide: at
  // the guide point on this path).
  const auto addSeparation = [&](int k, const Eigen::Vector3d& o, double margin, PositionConstraint::Kind kind,
                                 bool at_guide = false) {
    if ((o - c.p0).norm() - margin > config_.limits.max_speed_mps * k * c.dt) return;  // cannot get that close by t_k
    Eigen::Vector3d n = (at_guide ? c.guide[static_cast<std::size_t>(k)] : linearisationPoint(c, k)) - o;
    if (n.norm() < 1e-6) n = c.guide[static_cast<std::size_t>(k)] - o;
    if (n.norm() < 1e-6) n = Eigen::Vector3d::UnitZ();
    n.normalize();
    // n·(x − o) ≥ margin  ⇔  (−n)·x ≤ −n·o − margin
    c.qp.constraints.push_back(PositionConstraint{k, -n, -n.dot(o) - margin, kind});
  };
  for (const auto& other : req.higher_priority_plans) {
    const double age = std::max(0.0, req.t_now_s - other.t0_s);
    const double margin = uavKeepOutDistance(config_, age) + config_.qp_distance_buffer_m;
    const double d0 = (c.p0 - evaluateTrajectory(other, req.t_now_s).p).norm();
    for (int k = 1; k <= c.N; ++k) {
      // Already inside at t0: recover at 1.2× the verifier's pace (recoveringDistance).
      addSeparation(k, evaluateTrajectory(other, req.t_now_s + k * c.dt).p,
                    recoveringDistance(config_, margin, d0, k * c.dt, true), PositionConstraint::Kind::kUav);
    }
    addBrakeEnvelopeRows(c, other);
  }
  if (c.has_worker) {
    const double d0 = (c.p0 - req.worker.p_world.col(0)).norm();
    const double margin = config_.worker_safety_distance_m + config_.qp_distance_buffer_m;
    for (int k = 1; k <= c.N; ++k) {
      // Already inside at t0 (the worker walked up): recover (recoveringDistance). When the path
      // goes around him, the half-spaces turn with it (through the guide point: on the path,
      // outside his keep-out); a previous plan that did not go around him would keep them a wall
      // between the UAV and its reference.
      addSeparation(k, req.worker.p_world.col(k), recoveringDistance(config_, margin, d0, k * c.dt, true),
                    PositionConstraint::Kind::kWorker, c.path_around_worker);
    }
  }
}

void UavPlanner::addBrakeEnvelopeRows(PlanContext& c, const PlannedTrajectory& other) const {
  // A plan may have been replaced by a brake plan that did not arrive yet (an old one), or, a
  // lower-priority UAV's, be by its next one (the lead): keep Γ_dis from every point where its UAV could stop
  // (one half-space per envelope segment and step, through the segment's point nearest to the
  // linearisation point: the whole segment lies on its far side).
  // Fewer segments: the polyline simplified to within kEnvelopeTolerance, which the margin adds.
  constexpr double kEnvelopeTolerance = 0.05;
  const std::vector<Eigen::Vector3d> kept = keptBrakeEnvelope(other, c.req.uav_index, c.req.t_now_s, config_);
  if (kept.empty()) return;
  const double vmax = config_.limits.max_speed_mps;
  const std::vector<Eigen::Vector3d> env = simplifyPolyline(kept, kEnvelopeTolerance);
  const double d0_env = distanceToPolyline(env, c.p0);
  const std::size_t segments = env.size() > 1 ? env.size() - 1 : env.size();
  for (std::size_t i = 0; i < segments; ++i) {
    const Eigen::Vector3d& a = env[i];
    const Eigen::Vector3d& b = env[std::min(i + 1, env.size() - 1)];
    const double d_seg = (c.p0 - closestPointOnSegment(a, b, c.p0)).norm();
    for (int k = 1; k <= c.N; ++k) {
      const double m = recoveringDistance(config_, config_.mutual_distance_m + config_.qp_distance_buffer_m, d0_env,
                                          k * c.dt, true) + kEnvelopeTolerance;
      if (d_seg - m > vmax * k * c.dt) continue;  // cannot get that close by t_k
      const Eigen::Vector3d lin = linearisationPoint(c, k);
      const Eigen::Vector3d q = closestPointOnSegment(a, b, lin);
      Eigen::Vector3d n = lin - q;
      if (n.norm() < 1e-6) n = c.guide[static_cast<std::size_t>(k)] - q;
      if (n.norm() < 1e-6) n = c.p0 - q;
      if (n.norm() < 1e-6) n = Eigen::Vector3d::UnitZ();
      n.normalize();
      c.qp.constraints.push_back(PositionConstraint{k, -n, -n.dot(q) - m, PositionConstraint::Kind::kUav});
    }
  }
}

std::string UavPlanner::solveQp(PlanContext& c, PlanResult& result) {
  // Warm start: the last verified plan re-timed (primal only; the constraint set changes).
  TrajectoryQpSolution warm;
  if (c.have_prev) {
    for (int k = 0; k <= c.N; ++k) {
      const TrajectoryPoint x = evaluateTrajectory(last_verified_, c.req.t_now_s + k * c.dt);
      warm.p.push_back(x.p);
      warm.v.push_back(x.v);
      warm.a.push_back(x.a);
    }
  }
  if (keep_last_qp_) {
    last_qp_ = std::make_unique<TrajectoryQpProblem>(c.qp);
    last_qp_warm_ = std::make_unique<TrajectoryQpSolution>(warm);
  }
  c.sol = qp_->solve(c.qp, c.have_prev ? &warm : nullptr);
  result.qp_variables = c.sol.variables;
  result.qp_constraints = c.sol.equalities + c.sol.inequalities;
  result.qp_iterations = c.sol.iterations;
  result.qp_sparse_timeouts += stoppedSparse(c.sol) ? 1 : 0;
  if (c.sol.solved()) return {};
  if (config_.qp_truncate_on_infeasible && c.sol.status == TrajectoryQpSolution::Status::kInfeasible &&
      solveTruncated(c, c.have_prev ? &warm : nullptr, result)) {
    return {};
  }
  return c.sol.reason + infeasibilityCause(c, result);
}

bool UavPlanner::solveTruncated(PlanContext& c, const TrajectoryQpSolution* warm, PlanResult& result) {
  const int N = c.N;
  int best_k = 0;
  TrajectoryQpSolution best;
  const auto attempt = [&](int k) {
    if (k < 1 || k >= N) return false;
    // A plan finished beyond the time budget is refused anyway (verifyAndAccept): no attempt then.
    if (budgetSpent(config_, c.t_start)) return false;
    TrajectoryQpProblem t = c.qp;
    t.intervals = k;
    t.reference.resize(static_cast<std::size_t>(k) + 1);
    t.constraints.erase(std::remove_if(t.constraints.begin(), t.constraints.end(),
                                       [k](const PositionConstraint& pc) { return pc.sample > k; }),
                        t.constraints.end());
    t.terminal_rest = true;
    // Warm start: the last verified plan re-timed, cut to the K samples (primal only, as solveQp).
    TrajectoryQpSolution w;
    if (warm != nullptr && warm->p.size() > static_cast<std::size_t>(k)) {
      w.p.assign(warm->p.begin(), warm->p.begin() + k + 1);
      w.v.assign(warm->v.begin(), warm->v.begin() + k + 1);
      w.a.assign(warm->a.begin(), warm->a.begin() + k + 1);
    }
    TrajectoryQpSolution s = qp_->solve(t, w.p.empty() ? nullptr : &w);
    result.qp_sparse_timeouts += stoppedSparse(s) ? 1 : 0;
    if (!s.solved()) return false;
    best_k = k;
    best = std::move(s);
    return true;
  };
  const int half = N / 2;
  if (attempt(half)) {
    attempt(half + (N - half) / 2);
  } else {
    attempt(half / 2);
  }
  if (best_k == 0) return false;
  // Hover where it stopped: at rest at sample K (v = a = 0), so the dynamics hold with a = 0.
  for (int k = best_k + 1; k <= N; ++k) {
    best.p.push_back(best.p.back());
    best.v.push_back(Eigen::Vector3d::Zero());
    best.a.push_back(Eigen::Vector3d::Zero());
  }
  c.sol = std::move(best);
  result.qp_truncated_at = best_k;
  return true;
}

std::string UavPlanner::infeasibilityCause(const PlanContext& c, PlanResult& result) {
  // Name the constraint family that makes it infeasible (users and the simulator's failure
  // statistics need the cause; costs up to three more solves, only on failure). The most
  // frequent cause first: a relaxed problem that is still infeasible costs 2–4× the failed
  // solve before ProxQP proves it (power towers seed 7: ~450 ms of a 560 ms failed replanning
  // with the worker and UAV families tried first, docs/planning.md §7.1). Not beyond the time
  // budget: the fallback must not wait for a diagnosis (harsh seed 1: 1.6 s, mostly re-solves).
  // Cold and with the problem's own iterations: a warm start or a cap of 10 outer iterations per
  // relaxed solve named the same causes in no less time on the mission's instances (planning.md §10).
  const auto t_diagnosis = Clock::now();
  const auto budget_spent = [&] { return budgetSpent(config_, c.t_start); };
  const QpDiagnosis d = diagnoseInfeasibleQp(*qp_, c.qp, nullptr, c.qp.max_iterations, budget_spent);
  result.qp_sparse_timeouts += d.sparse_stops;
  result.timings.qp_diagnosis_ms = msSince(t_diagnosis);
  if (d.cause != QpDiagnosis::Cause::kStopped) return describe(d.cause);
  std::ostringstream os;
  os << " (cause not diagnosed: the time budget of " << config_.time_budget_ms << " ms is spent)";
  return os.str();
}

// ---- camera heading / pitch (filter or Ceres) -----------------------------------------------

std::string UavPlanner::planCamera(PlanContext& c) const {
  const PlanRequest& req = c.req;
  c.heading.assign(static_cast<std::size_t>(c.N) + 1, req.state.heading_rad);
  c.pitch.assign(static_cast<std::size_t>(c.N) + 1, req.state.pitch_rad);
  if (!c.has_worker) {  // no worker: follow the reference's angles within the rate limits
    for (int k = 1; k <= c.N; ++k) {
      const double sh = config_.limits.max_heading_rate_radps * c.dt, sp = config_.limits.max_pitch_rate_radps * c.dt;
      const auto i = static_cast<std::size_t>(k);
      c.heading[i] = common::wrapAngle(c.heading[i - 1] +
                                       std::clamp(common::wrapAngle(req.reference.heading_rad(k) - c.heading[i - 1]), -sh, sh));
      c.pitch[i] = c.pitch[i - 1] + std::clamp(std::clamp(req.reference.pitch_rad(k), config_.limits.min_pitch_rad,
                                                          config_.limits.max_pitch_rad) - c.pitch[i - 1], -sp, sp);
    }
    return {};
  }
  CameraTrackingProblem cam;
  cam.dt_s = c.dt;
  cam.heading0_rad = req.state.heading_rad;
  cam.pitch0_rad = req.state.pitch_rad;
  cam.p_world = c.sol.p;
  const bool search = req.camera_target.cols() == req.worker.steps() && req.camera_target.allFinite();
  for (int k = 0; k <= c.N; ++k) cam.target_world.push_back(search ? req.camera_target.col(k) : req.worker.p_world.col(k));
  setCameraLimits(config_.limits, cam);
  cam.weight = config_.heading_weight;
  cam.smoothness_weight = config_.heading_smoothness_weight;
  const CameraTrack track =
      config_.camera_solver == PlannerConfig::CameraSolver::kCeres ? solveCameraCeres(cam) : cameraFilter(cam);
  if (!track.ok) return track.reason;
  c.heading = track.heading_rad;
  c.pitch = track.pitch_rad;
  return {};
}

// ---- verification ---------------------------------------------------------------------------

std::string UavPlanner::verifyAndAccept(PlanContext& c, PlanResult& result) {
  const auto t_stage = Clock::now();
  PlannedTrajectory tr;
  tr.uav_index = c.req.uav_index;
  tr.t0_s = c.req.t_now_s;
  tr.dt_s = c.dt;
  for (int k = 0; k <= c.N; ++k) {
    const auto i = static_cast<std::size_t>(k);
    TrajectorySample s;
    s.p_world = c.sol.p[i];
    s.v_world = c.sol.v[i];
    s.a_world = c.sol.a[i];
    s.heading_rad = c.heading[i];
    s.pitch_rad = c.pitch[i];
    tr.samples.push_back(s);
  }
  const VerificationReport rep =
      verifier_->verify(tr, c.req.t_now_s, c.req.higher_priority_plans, c.req.worker, c.req.t_now_s, c.dt);
  result.timings.verify_ms = msSince(t_stage);
  if (!rep.ok) return rep.reason;
  if (budgetSpent(config_, c.t_start)) {
    std::ostringstream os;
    os << "time budget exceeded (" << msSince(c.t_start) << " ms > " << config_.time_budget_ms << " ms)";
    return os.str();
  }
  tr.sequence = ++sequence_;
  result.trajectory = tr;
  result.status = PlanStatus::kOptimized;
  result.reason.clear();
  result.verified = true;
  result.min_obstacle_clearance_m = rep.min_obstacle_clearance_m;
  result.min_uav_margin_m = rep.min_uav_margin_m;
  result.min_worker_distance_m = rep.min_worker_distance_m;
  last_verified_ = tr;
  brake_ = PlannedTrajectory{};
  return {};
}

std::vector<PlanResult> planInPriorityOrder(const std::vector<UavPlanner*>& planners, std::vector<PlanRequest> requests) {
  std::vector<PlanResult> results;
  results.reserve(planners.size());
  for (std::size_t i = 0; i < planners.size() && i < requests.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (!results[j].trajectory.empty()) requests[i].higher_priority_plans.push_back(results[j].trajectory);
    }
    results.push_back(planners[i]->plan(requests[i]));
  }
  return results;
}

}  // namespace gesture_formation::planning

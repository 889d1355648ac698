// UavPlanner: stage 2 (projection, path), stage 3 (corridors, QP, camera), verification and
// fallback. docs/planning.md §5–§8.
#include "gesture_formation/planning/uav_planner.hpp"

#include <algorithm>
#include <functional>
#include <chrono>
#include <cmath>
#include <sstream>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/planning/camera_tracking.hpp"
#include "gesture_formation/planning/corridor_builder.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/path_search.hpp"
#include "gesture_formation/planning/trajectory_qp.hpp"
#include "gesture_formation/planning/trajectory_verifier.hpp"

namespace gesture_formation::planning {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

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
                       std::shared_ptr<const DistanceField> field)
    : config_(config), map_(std::move(map)), field_(std::move(field)) {
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
    verifier_ = std::make_unique<TrajectoryVerifier>(*map_, *field_, config_);
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
  wind_speeds_.clear();
  sequence_ = 0;
}

void UavPlanner::updateTrackingAllowance(const PlanRequest& req) {
  if (!std::isfinite(req.t_now_s)) return;
  // The held deviation decays with the time since the last measurement ...
  const double elapsed = std::max(0.0, req.t_now_s - allowance_t_s_);
  tracking_deviation_m_ = std::max(0.0, tracking_deviation_m_ - config_.tracking_allowance_decay_mps * elapsed);
  allowance_t_s_ = req.t_now_s;
  // ... and grows to the deviation of the state from the plan being flown.
  if (!flown_.empty() && req.state.p_world.allFinite()) {
    const double d = (evaluateTrajectory(flown_, req.t_now_s).p - req.state.p_world).norm();
    if (std::isfinite(d)) tracking_deviation_m_ = std::max(tracking_deviation_m_, d);
  }
}

double UavPlanner::updateWindAllowance(const PlanRequest& req) {
  if (!std::isfinite(req.t_now_s)) return 0.0;
  // A clock that jumps back (a restarted simulation, a replayed bag) starts a new window.
  if (!wind_speeds_.empty() && req.t_now_s < wind_speeds_.back().first) wind_speeds_.clear();
  const Eigen::Vector3d& w = req.wind_estimate_mps;
  if (w.head<2>().allFinite()) wind_speeds_.emplace_back(req.t_now_s, w.head<2>().norm());
  while (!wind_speeds_.empty() && wind_speeds_.front().first < req.t_now_s - config_.wind_window_s) {
    wind_speeds_.pop_front();
  }
  if (wind_speeds_.empty()) return 0.0;
  double peak = 0.0;
  for (const auto& [t, v] : wind_speeds_) peak = std::max(peak, v);
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
                    config_.mutual_distance_m + config_.age_margin_speed_mps * age + config_.qp_distance_buffer_m,
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
    cam.max_heading_rate_radps = config_.limits.max_heading_rate_radps;
    cam.max_pitch_rate_radps = config_.limits.max_pitch_rate_radps;
    cam.min_pitch_rad = config_.limits.min_pitch_rad;
    cam.max_pitch_rad = config_.limits.max_pitch_rad;
  }
  const CameraTrack track = worker_ok ? cameraFilter(cam) : CameraTrack{};
  for (int k = 0; k < n; ++k) {
    const auto i = static_cast<std::size_t>(k);
    tr.samples[i].heading_rad = track.ok ? track.heading_rad[i] : cam.heading0_rad;
    tr.samples[i].pitch_rad = track.ok ? track.pitch_rad[i] : cam.pitch0_rad;
  }
}

PlanResult UavPlanner::fallback(const PlanRequest& req, PlanResult result, const std::string& reason) {
  const auto t_fb = Clock::now();
  result.reason = reason;
  const bool state_finite = req.state.p_world.allFinite();
  const int n = std::max(2, req.reference.steps());
  const double dt = req.dt_s > 0.0 && std::isfinite(req.dt_s) ? req.dt_s : 0.2;
  // 1. The last verified plan, re-timed to t_now, if it still covers enough and verifies now.
  std::string why_not;
  if (last_verified_.empty()) {
    why_not = "no previous plan";
  } else if (!std::isfinite(req.t_now_s) || last_verified_.tEnd() < req.t_now_s + config_.fallback_min_horizon_s) {
    std::ostringstream os;
    os << "previous plan ends at " << last_verified_.tEnd() << " s, before t_now + " << config_.fallback_min_horizon_s << " s";
    why_not = os.str();
  } else {
    const TrajectoryPoint at_now = evaluateTrajectory(last_verified_, req.t_now_s);
    const double deviation = (at_now.p - req.state.p_world).norm();
    if (state_finite && !(deviation <= config_.fallback_max_deviation_m)) {
      std::ostringstream os;
      os << "previous plan is " << deviation << " m from the state";
      why_not = os.str();
    } else {
      PlannedTrajectory prev = retimeThenBrake(last_verified_, req.t_now_s, dt, n, config_.limits);
      prev.uav_index = req.uav_index;
      const VerificationReport rep =
          verifier_ ? verifier_->verify(prev, req.t_now_s, req.higher_priority_plans, req.worker, req.t_now_s, dt)
                    : VerificationReport{};
      if (rep.ok) {
        result.trajectory = prev;
        result.status = PlanStatus::kFallbackPrevious;
        result.verified = true;
        result.min_obstacle_clearance_m = rep.min_obstacle_clearance_m;
        result.min_uav_margin_m = rep.min_uav_margin_m;
        result.min_worker_distance_m = rep.min_worker_distance_m;
        result.reason += "; reusing verified plan #" + std::to_string(last_verified_.sequence);
        if (brake_.sequence != last_verified_.sequence) brake_ = PlannedTrajectory{};  // another plan is flown now
        result.trajectory.sequence = ++sequence_;
        result.timings.verify_ms += msSince(t_fb);
        return result;
      }
      why_not = "previous plan fails now: " + rep.reason;
    }
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
  if (auto moved = separateHoldPoint(req, result.trajectory, separated)) {
    result.trajectory = std::move(*moved);
    result.reason += separated;
  }
  result.trajectory.sequence = ++sequence_;
  brake_ = result.trajectory;  // held: the same curve (re-timed), now under this sequence number
  if (verifier_) {
    const VerificationReport rep =
        verifier_->verify(result.trajectory, req.t_now_s, req.higher_priority_plans, req.worker, req.t_now_s, dt);
    result.verified = rep.ok;
    result.min_obstacle_clearance_m = rep.min_obstacle_clearance_m;
    result.min_uav_margin_m = rep.min_uav_margin_m;
    result.min_worker_distance_m = rep.min_worker_distance_m;
    if (rep.ok) {
      last_verified_ = result.trajectory;  // the UAV now executes it; reusable next time
    } else {
      result.reason += " (brake plan NOT verified: " + rep.reason + ")";
    }
  }
  result.timings.verify_ms += msSince(t_fb);
  return result;
}

// ---- the three stages ------------------------------------------------------------------------

PlanResult UavPlanner::plan(const PlanRequest& req) {
  const auto t_start = Clock::now();
  PlanResult result;
  result.trajectory.uav_index = req.uav_index;
  updateTrackingAllowance(req);
  const double wind_allowance = updateWindAllowance(req);
  const double allowance = std::clamp(tracking_deviation_m_, config_.tracking_allowance_min_m + wind_allowance,
                                      config_.tracking_allowance_max_m + wind_allowance);
  result.tracking_allowance_m = allowance;
  result.wind_allowance_m = wind_allowance;
  const auto finish = [&](PlanResult r) {
    flown_ = r.trajectory;
    r.timings.total_ms = msSince(t_start);
    return r;
  };
  if (!config_error_.empty()) return finish(fallback(req, result, "invalid planner config: " + config_error_));
  if (!req.state.p_world.allFinite()) return finish(fallback(req, result, "bad request: state.p_world is not finite"));
  const std::string bad = checkRequest(req);
  if (!bad.empty()) return finish(fallback(req, result, bad));

  const OccupancyMap& map = *map_;
  const DistanceField& field = *field_;
  const double res = map.resolution();
  const double dt = req.dt_s;
  const int N = req.reference.steps() - 1;
  const Eigen::Vector3d p0 = req.state.p_world;
  const bool has_worker = req.worker.steps() > 0;

  // ---- stage 2: project the references, connect them, merge -----------------------------
  auto t_stage = Clock::now();
  std::vector<Eigen::Vector3d> ref(static_cast<std::size_t>(N) + 1, p0);
  const double worker_keep = config_.worker_safety_distance_m + config_.qp_distance_buffer_m;
  // Obstacle clearances of planning (not of verification) grown by the tracking allowance.
  const double path_clear = config_.path_clearance_m + allowance;
  const double seg_clear = config_.obstacle_clearance_m + allowance;
  for (int k = 1; k <= N; ++k) {
    Eigen::Vector3d r = req.reference.p_world.col(k);
    bool moved = false;
    if (has_worker) {  // out of the worker's safety sphere, horizontally away from it
      const Eigen::Vector3d w = req.worker.p_world.col(k);
      Eigen::Vector3d d = r - w;
      if (d.norm() < worker_keep) {
        Eigen::Vector3d h(d.x(), d.y(), 0.0);
        if (h.norm() < 1e-6) h = Eigen::Vector3d(p0.x() - w.x(), p0.y() - w.y(), 0.0);
        if (h.norm() < 1e-6) h = Eigen::Vector3d::UnitX();
        d = d + h.normalized() * (worker_keep - d.norm() + 1e-3);
        if (d.norm() < worker_keep) d = d.normalized() * (worker_keep + 1e-3);
        r = w + d;
        moved = true;
      }
    }
    const auto proj = projectToClearance(field, map, r, path_clear, config_.max_projection_m);
    if (proj) {
      moved = moved || (*proj - r).norm() > 1e-9;
      r = *proj;
    } else {
      r = ref[static_cast<std::size_t>(k) - 1];  // nothing clear nearby: hold the previous target
      moved = true;
    }
    if (moved) ++result.projected_references;
    ref[static_cast<std::size_t>(k)] = r;
  }
  // Waypoints: the current position, then the projected references (duplicates dropped),
  // with A* detours where the straight segment is not clear.
  const double start_clear = field.clearance(p0);
  // The worker's keep-out for the path: a tube around his predicted positions over the horizon
  // (a ball for a standing worker). A straight segment to a reference far away may pass right by
  // him, and where obstacles make the corridor around that segment a sliver the QP cannot bend
  // around him (harsh seed 65: the leader stuck for 180 s beside the tower he climbed, every
  // replanning infeasible; docs/planning.md §5). Shrunk per segment so that neither end lies
  // inside it (a worker who walked up to the UAV; a reference on his track that he will have
  // passed when the UAV gets there): the QP's half-spaces keep the full distance in time.
  KeepOutTube worker_tube;
  if (has_worker) {
    std::vector<Eigen::Vector3d> track;
    for (int k = 0; k < req.worker.steps(); ++k) track.push_back(req.worker.p_world.col(k));
    worker_tube.polyline_world = simplifyPolyline(track, 0.05);  // within 5 cm of every step
  }
  const auto keepOutFor = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    KeepOutTube tube = worker_tube;
    if (tube.polyline_world.empty()) return tube;
    tube.radius_m = std::min({worker_keep, tube.distance(a) - res, tube.distance(b) - res});
    return tube;
  };
  std::vector<Eigen::Vector3d> raw{p0};
  bool truncated = false, path_around_worker = false;
  for (int k = 1; k <= N && !truncated; ++k) {
    const Eigen::Vector3d& target = ref[static_cast<std::size_t>(k)];
    if ((target - raw.back()).norm() < 1e-3) continue;
    const bool from_start = raw.size() == 1;
    const double need = from_start ? std::min(seg_clear, start_clear - res) : seg_clear;
    const KeepOutTube tube = keepOutFor(raw.back(), target);
    const bool outside = tube.segmentOutside(raw.back(), target);
    if (segmentClear(field, res, raw.back(), target, need) && outside) {
      raw.push_back(target);
      continue;
    }
    path_around_worker = path_around_worker || !outside;
    ++result.path_searches;
    const auto detour = search_->search(raw.back(), target, path_clear, seg_clear, config_.search_margin_m,
                                        config_.search_max_expansions, nullptr, tube);
    if (!detour) {
      truncated = true;  // the rest of the reference is unreachable for now
      break;
    }
    for (std::size_t i = 1; i < detour->size(); ++i) raw.push_back((*detour)[i]);
  }
  // Greedy merge: extend a segment over the following waypoints while it stays clear and
  // every skipped waypoint lies within the merge tolerance of it.
  std::vector<Eigen::Vector3d> path{raw.front()};
  {
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
          close = (raw[m] - (a + s * ab)).norm() <= config_.path_merge_tolerance_m;
        }
        const double need = i == 0 ? std::min(seg_clear, start_clear - res) : seg_clear;
        if (!close || !segmentClear(field, res, a, b, need) || !keepOutFor(a, b).segmentOutside(a, b)) break;
        j = c;
      }
      path.push_back(raw[j]);
      i = j;
    }
  }
  if (path.size() == 1) {  // already at the (static) reference: a short segment to hold a corridor
    Eigen::Vector3d d = req.state.v_world.norm() > 1e-3 ? Eigen::Vector3d(req.state.v_world.normalized()) : Eigen::Vector3d::UnitZ();
    path.push_back(p0 + 0.05 * d);
  }
  result.path_world = path;
  result.timings.path_ms = msSince(t_stage);
  (void)truncated;

  // ---- stage 3a: corridors ----------------------------------------------------------------
  t_stage = Clock::now();
  std::vector<SegmentCorridor> corridors;
  corridors.reserve(path.size() - 1);
  std::unique_ptr<CorridorBuilder> inflated;
  if (allowance > 0.0) {
    CorridorConfig cc = corridors_->config();
    cc.clearance_m += allowance;
    inflated = std::make_unique<CorridorBuilder>(cc);
  }
  const CorridorBuilder& builder = inflated ? *inflated : *corridors_;
  // A start closer to an obstacle than the corridor clearance (flying low over the ground, a
  // gust): the first corridor is asked for a little less than the start has — its exact distance
  // to the nearest voxel centre − the builder's seed margin (the ends lie that far inside every
  // plane) − kFirstCorridorGap — not less than the verifier's clearance. Asked for more, the builder
  // shrinks its planes point by point around the start — a fan of ~100 planes for a start near
  // flat ground, whose QP rows (× 40 samples) made single replannings take seconds; within ~1 cm of
  // that distance the fan appears too (tangent planes through points just beyond the start). Not
  // less: the corridor must not let the UAV much closer than it is (the move-away rows below ask
  // it to recover).
  std::unique_ptr<CorridorBuilder> first_builder;
  if (start_clear < seg_clear) {
    constexpr double kFirstCorridorGap = 0.03;
    std::vector<Eigen::Vector3d> near;
    map.pointsInBox(Aabb{p0 - Eigen::Vector3d::Constant(seg_clear), p0 + Eigen::Vector3d::Constant(seg_clear)}, near);
    double d_exact = std::numeric_limits<double>::infinity();
    for (const auto& q : near) d_exact = std::min(d_exact, (q - p0).norm());
    CorridorConfig cc = corridors_->config();
    const double first_clear = std::clamp(d_exact - cc.seed_margin_m - kFirstCorridorGap,
                                          config_.verify_clearance_m + OccupancyMap::rasterInflation(res), seg_clear);  // to centres
    if (first_clear < seg_clear - 1e-9) {
      cc.clearance_m = first_clear;
      first_builder = std::make_unique<CorridorBuilder>(cc);
    }
  }
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    auto c = (i == 0 && first_builder ? *first_builder : builder).buildSegment(path[i], path[i + 1], map);
    if (!c) {
      result.timings.corridor_ms = msSince(t_stage);
      return finish(fallback(req, result, "corridor " + std::to_string(i) + ": " + c.reason()));
    }
    corridors.push_back(std::move(c.value()));
  }
  result.corridor_count = static_cast<int>(corridors.size());
  result.timings.corridor_ms = msSince(t_stage);

  // ---- stage 3b: QP ---------------------------------------------------------------------------
  t_stage = Clock::now();
  TrajectoryQpProblem qp;
  qp.dt_s = dt;
  qp.intervals = N;
  qp.p0 = p0;
  qp.v0 = req.state.v_world;
  qp.a0 = req.state.a_world;
  qp.reference = ref;
  qp.velocity = NormPolygon{config_.limits.max_speed_mps, config_.limits.max_vertical_speed_mps};
  qp.acceleration = NormPolygon{config_.limits.max_acceleration_mps2, config_.limits.max_vertical_acceleration_mps2};
  qp.w_reference = config_.weights.reference;
  qp.w_acceleration = config_.weights.acceleration;
  qp.w_jerk = config_.weights.jerk;
  qp.w_terminal_velocity = config_.weights.terminal_velocity;
  qp.eps_abs = config_.qp_eps_abs;
  qp.max_iterations = config_.qp_max_iterations;
  qp.solve_timeout_s = config_.qp_solve_timeout_s;

  // Assignment of samples to corridors: a guide point moves along the path no faster than the
  // inner speed/acceleration sets allow (70 %), towards the projection of r_k, stopping on
  // every waypoint it passes; sample k must lie in the corridors of the guide's segments at
  // k−1 and k (so every chord x_{k−1}x_k lies in one convex corridor).
  const int M = static_cast<int>(path.size()) - 1;
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
  std::vector<int> seg(static_cast<std::size_t>(N) + 1, 0);
  std::vector<Eigen::Vector3d> guide(static_cast<std::size_t>(N) + 1, p0);
  {
    double sigma = 0.0, target_sigma = 0.0;
    double u = std::max(0.0, req.state.v_world.dot(tangent(0)));
    int search_from = 0;
    for (int k = 1; k <= N; ++k) {
      // Projection of r_k onto the path (monotone, a window of segments ahead).
      double best = std::numeric_limits<double>::infinity(), best_sigma = target_sigma;
      for (int s = search_from; s < std::min(M, search_from + 12); ++s) {
        const Eigen::Vector3d a = path[static_cast<std::size_t>(s)], b = path[static_cast<std::size_t>(s) + 1];
        const Eigen::Vector3d ab = b - a;
        const double t = std::clamp((ref[static_cast<std::size_t>(k)] - a).dot(ab) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
        const double d = (ref[static_cast<std::size_t>(k)] - (a + t * ab)).norm();
        if (d < best - 1e-9) best = d, best_sigma = S[static_cast<std::size_t>(s)] + t * ab.norm();
      }
      target_sigma = std::max(target_sigma, best_sigma);
      const int s_prev = segOf(sigma);
      search_from = s_prev;
      const Eigen::Vector3d t_dir = tangent(s_prev);
      const double v_cap = 0.7 * supportAlong(qp.velocity, t_dir);
      const double a_cap = 0.5 * supportAlong(qp.acceleration, t_dir);
      u = std::min(u + a_cap * dt, v_cap);
      double next = std::min(target_sigma, sigma + u * dt);
      const double boundary = S[static_cast<std::size_t>(s_prev) + 1];
      if (s_prev < M - 1 && next > boundary) next = boundary;  // stop on the waypoint
      if (next < sigma + u * dt) u = (next - sigma) / dt;       // waiting slows the guide down
      sigma = std::min(next, S.back());
      const int s = segOf(sigma);
      seg[static_cast<std::size_t>(k)] = s;
      const double local = std::clamp(sigma - S[static_cast<std::size_t>(s)], 0.0, S[static_cast<std::size_t>(s) + 1] - S[static_cast<std::size_t>(s)]);
      guide[static_cast<std::size_t>(k)] = path[static_cast<std::size_t>(s)] + local * tangent(s);
    }
  }
  // Corridor rows, pruned when the sample cannot reach them (‖x_k − p0‖ ≤ v_max t_k). A row the
  // UAV cannot meet (with a 2 cm cushion) even braking with all its acceleration — its momentum
  // carries it over the plane (leastReach) — is moved out to where it can braking at 70 %, by at
  // most the tracking allowance: the part of the corridor clearance that is there to absorb
  // deviations from the plan, and never closer to the obstacle points behind it than the
  // verifier's clearance (catch-up 18–34 m low over the
  // ground: the plan flown descended towards its floor, the new corridor's floor was 2 cm too high
  // for the state; docs/planning.md §12). Rows it can meet are not touched (plans unchanged); a row
  // still out of reach after the allowance leaves the QP infeasible: the planner falls back.
  const double vmax = config_.limits.max_speed_mps;
  constexpr double kMomentumAccelShare = 0.7, kMomentumCushion = 0.02;
  const double verify_clear = config_.verify_clearance_m + OccupancyMap::rasterInflation(res);  // to voxel centres
  struct Reach {
    std::vector<double> full, soft;  // leastReach braking fully / at kMomentumAccelShare, per k
  };
  std::vector<std::vector<Reach>> least(corridors.size());  // [corridor][row], computed lazily
  for (int k = 1; k <= N; ++k) {
    const double reach = vmax * k * dt;
    const int s_prev = seg[static_cast<std::size_t>(k) - 1], s_cur = seg[static_cast<std::size_t>(k)];
    for (int s : {s_prev, s_cur}) {
      const Polytope& P = corridors[static_cast<std::size_t>(s)].polytope;
      const double cap = std::min(allowance, corridors[static_cast<std::size_t>(s)].clearance_m - verify_clear);
      auto& rows_least = least[static_cast<std::size_t>(s)];
      if (rows_least.empty()) rows_least.resize(static_cast<std::size_t>(P.rows()));
      for (int r = 0; r < P.rows(); ++r) {
        const Eigen::Vector3d a = P.A.row(r).transpose();
        double b = P.b(r) - config_.corridor_margin_m;
        if (a.dot(p0) + reach < b) continue;  // unreachable plane
        Reach& lr = rows_least[static_cast<std::size_t>(r)];
        if (lr.full.empty()) lr.full = leastReach(a, p0, qp.v0, qp.a0, qp.velocity, qp.acceleration, 1.0, dt, N);
        if (lr.full[static_cast<std::size_t>(k)] + kMomentumCushion > b && cap > 0.0) {
          if (lr.soft.empty()) lr.soft = leastReach(a, p0, qp.v0, qp.a0, qp.velocity, qp.acceleration, kMomentumAccelShare, dt, N);
          b = std::min(lr.soft[static_cast<std::size_t>(k)] + kMomentumCushion, b + cap);
          ++result.momentum_relaxed_rows;
        }
        qp.constraints.push_back(PositionConstraint{k, a, b, PositionConstraint::Kind::kCorridor});
      }
      if (s_prev == s_cur) break;
    }
  }
  result.corridors = std::move(corridors);  // for display; not used below
  // Closer to obstacles than the corridor clearance (gusts, a corridor that had to shrink
  // around the start): move away along the distance field's gradient at the recovery pace
  // until the clearance is back, instead of hovering where the last plan left the UAV.
  {
    const double d_start = field.clearance(p0);
    if (d_start < seg_clear) {
      Eigen::Vector3d g;
      for (int i = 0; i < 3; ++i) {
        const Eigen::Vector3d e = Eigen::Vector3d::Unit(i) * res;
        g(i) = (field.clearance(p0 + e) - field.clearance(p0 - e)) / (2.0 * res);
      }
      if (g.allFinite() && g.norm() > 1e-6) {
        const Eigen::Vector3d away = g.normalized();
        // Not faster than the UAV can turn round: moving towards the obstacle it first has to stop.
        // Largest away·(x_k − p0) braking fully / at 70 %, less the cushion:
        const auto most = [&](double share) {
          std::vector<double> m = leastReach(-away, p0, qp.v0, qp.a0, qp.velocity, qp.acceleration, share, dt, N);
          for (double& x : m) x = -(x + kMomentumCushion) - away.dot(p0);
          return m;
        };
        const std::vector<double> most_full = most(1.0), most_soft = most(kMomentumAccelShare);
        for (int k = 1; k <= N; ++k) {
          double gain = std::min(seg_clear - d_start,
                                 -0.5 * config_.recovery_slack_m + 1.2 * recoveryAllowance(config_, k * dt));
          // away·(x_k − p0) ≥ gain  ⇔  (−away)·x_k ≤ −away·p0 − gain
          if (gain > most_full[static_cast<std::size_t>(k)]) {
            gain = most_soft[static_cast<std::size_t>(k)];
            ++result.momentum_relaxed_rows;
          }
          qp.constraints.push_back(PositionConstraint{k, -away, -away.dot(p0) - gain, PositionConstraint::Kind::kCorridor});
        }
      }
    }
  }
  // Linearisation points for the distance half-spaces: the last verified plan at t_k, else
  // the current position.
  const bool have_prev = !last_verified_.empty() && last_verified_.tEnd() > req.t_now_s;
  const auto linPoint = [&](int k) {
    return have_prev ? evaluateTrajectory(last_verified_, req.t_now_s + k * dt).p : p0;
  };
  // Half-space keeping x_k at least `margin` from o, linearised at the last plan (at_guide: at
  // the guide point on this path).
  const auto addSeparation = [&](int k, const Eigen::Vector3d& o, double margin, PositionConstraint::Kind kind,
                                  bool at_guide = false) {
    if ((o - p0).norm() - margin > vmax * k * dt) return;  // cannot get that close by t_k
    Eigen::Vector3d n = (at_guide ? guide[static_cast<std::size_t>(k)] : linPoint(k)) - o;
    if (n.norm() < 1e-6) n = guide[static_cast<std::size_t>(k)] - o;
    if (n.norm() < 1e-6) n = Eigen::Vector3d::UnitZ();
    n.normalize();
    // n·(x − o) ≥ margin  ⇔  (−n)·x ≤ −n·o − margin
    qp.constraints.push_back(PositionConstraint{k, -n, -n.dot(o) - margin, kind});
  };
  const double buffer = config_.qp_distance_buffer_m;
  for (const auto& other : req.higher_priority_plans) {
    const double age = std::max(0.0, req.t_now_s - other.t0_s);
    const double margin = config_.mutual_distance_m + config_.age_margin_speed_mps * age + buffer;
    const double d0 = (p0 - evaluateTrajectory(other, req.t_now_s).p).norm();
    for (int k = 1; k <= N; ++k) {
      // Already inside at t0: recover at 1.2× the verifier's pace (recoveringDistance).
      addSeparation(k, evaluateTrajectory(other, req.t_now_s + k * dt).p, recoveringDistance(config_, margin, d0, k * dt, true),
                    PositionConstraint::Kind::kUav);
    }
    // A plan may have been replaced by a brake plan that did not arrive yet (an old one), or, a
    // lower-priority UAV's, be by its next one (the lead): keep Γ_dis from every point where its UAV could stop
    // (one half-space per envelope segment and step, through the segment's point nearest to the
    // linearisation point: the whole segment lies on its far side).
    // Fewer segments: the polyline simplified to within kEnvelopeTolerance, which the margin adds.
    constexpr double kEnvelopeTolerance = 0.05;
    const std::vector<Eigen::Vector3d> kept = keptBrakeEnvelope(other, req.uav_index, req.t_now_s, config_);
    if (kept.empty()) continue;
    const std::vector<Eigen::Vector3d> env = simplifyPolyline(kept, kEnvelopeTolerance);
    const double d0_env = distanceToPolyline(env, p0);
    const std::size_t segments = env.size() > 1 ? env.size() - 1 : env.size();
    for (std::size_t i = 0; i < segments; ++i) {
      const Eigen::Vector3d& a = env[i];
      const Eigen::Vector3d& b = env[std::min(i + 1, env.size() - 1)];
      const double d_seg = (p0 - closestPointOnSegment(a, b, p0)).norm();
      for (int k = 1; k <= N; ++k) {
        const double m = recoveringDistance(config_, config_.mutual_distance_m + buffer, d0_env, k * dt, true) + kEnvelopeTolerance;
        if (d_seg - m > vmax * k * dt) continue;  // cannot get that close by t_k
        const Eigen::Vector3d c = closestPointOnSegment(a, b, linPoint(k));
        Eigen::Vector3d n = linPoint(k) - c;
        if (n.norm() < 1e-6) n = guide[static_cast<std::size_t>(k)] - c;
        if (n.norm() < 1e-6) n = p0 - c;
        if (n.norm() < 1e-6) n = Eigen::Vector3d::UnitZ();
        n.normalize();
        qp.constraints.push_back(PositionConstraint{k, -n, -n.dot(c) - m, PositionConstraint::Kind::kUav});
      }
    }
  }
  if (has_worker) {
    const double d0 = (p0 - req.worker.p_world.col(0)).norm();
    const double margin = config_.worker_safety_distance_m + config_.qp_distance_buffer_m;
    for (int k = 1; k <= N; ++k) {
      // Already inside at t0 (the worker walked up): recover (recoveringDistance). When the path
      // goes around him, the half-spaces turn with it (through the guide point: on the path,
      // outside his keep-out); a previous plan that did not go around him would keep them a wall
      // between the UAV and its reference.
      addSeparation(k, req.worker.p_world.col(k), recoveringDistance(config_, margin, d0, k * dt, true),
                    PositionConstraint::Kind::kWorker, path_around_worker);
    }
  }
  // Warm start: the last verified plan re-timed (primal only; the constraint set changes).
  TrajectoryQpSolution warm;
  if (have_prev) {
    for (int k = 0; k <= N; ++k) {
      const TrajectoryPoint x = evaluateTrajectory(last_verified_, req.t_now_s + k * dt);
      warm.p.push_back(x.p);
      warm.v.push_back(x.v);
      warm.a.push_back(x.a);
    }
  }
  if (keep_last_qp_) last_qp_ = std::make_unique<TrajectoryQpProblem>(qp);
  const TrajectoryQpSolution sol = qp_->solve(qp, have_prev ? &warm : nullptr);
  result.qp_variables = sol.variables;
  result.qp_constraints = sol.equalities + sol.inequalities;
  result.qp_iterations = sol.iterations;
  result.qp_sparse_timeouts += sol.sparse_timed_out ? 1 : 0;
  result.timings.qp_ms = msSince(t_stage);
  if (!sol.solved()) {
    // Name the constraint family that makes it infeasible (users and the simulator's failure
    // statistics need the cause; costs up to three more solves, only on failure). The most
    // frequent cause first: a relaxed problem that is still infeasible costs 2–4× the failed
    // solve before ProxQP proves it (power towers seed 7: ~450 ms of a 560 ms failed replanning
    // with the worker and UAV families tried first, docs/planning.md §7). Not beyond the time
    // budget: the fallback must not wait for a diagnosis (harsh seed 1: 1.6 s, mostly re-solves).
    std::string cause;
    using Kind = PositionConstraint::Kind;
    for (const auto& [kind, name] : {std::pair{Kind::kCorridor, "corridors"}, std::pair{Kind::kUav, "UAV separation"},
                                     std::pair{Kind::kWorker, "worker separation"}}) {
      if (config_.time_budget_ms > 0.0 && msSince(t_start) > config_.time_budget_ms) {
        std::ostringstream os;
        os << " (cause not diagnosed: the time budget of " << config_.time_budget_ms << " ms is spent)";
        cause = os.str();
        break;
      }
      TrajectoryQpProblem relaxed = qp;
      const auto before = relaxed.constraints.size();
      relaxed.constraints.erase(std::remove_if(relaxed.constraints.begin(), relaxed.constraints.end(),
                                               [kind = kind](const PositionConstraint& c) { return c.kind == kind; }),
                                relaxed.constraints.end());
      if (relaxed.constraints.size() == before) continue;
      const TrajectoryQpSolution relaxed_sol = qp_->solve(relaxed, nullptr);
      result.qp_sparse_timeouts += relaxed_sol.sparse_timed_out ? 1 : 0;
      if (relaxed_sol.solved()) {
        cause = std::string(" (feasible without the ") + name + " constraints)";
        break;
      }
    }
    if (cause.empty()) cause = " (infeasible even without any single family: dynamics vs the initial state)";
    result.timings.qp_ms = msSince(t_stage);
    return finish(fallback(req, result, sol.reason + cause));
  }

  // ---- camera heading / pitch (filter or Ceres) ----------------------------------------------------------
  t_stage = Clock::now();
  std::vector<double> heading(static_cast<std::size_t>(N) + 1, req.state.heading_rad);
  std::vector<double> pitch(static_cast<std::size_t>(N) + 1, req.state.pitch_rad);
  if (has_worker) {
    CameraTrackingProblem cam;
    cam.dt_s = dt;
    cam.heading0_rad = req.state.heading_rad;
    cam.pitch0_rad = req.state.pitch_rad;
    cam.p_world = sol.p;
    const bool search = req.camera_target.cols() == req.worker.steps() && req.camera_target.allFinite();
    for (int k = 0; k <= N; ++k) cam.target_world.push_back(search ? req.camera_target.col(k) : req.worker.p_world.col(k));
    cam.max_heading_rate_radps = config_.limits.max_heading_rate_radps;
    cam.max_pitch_rate_radps = config_.limits.max_pitch_rate_radps;
    cam.min_pitch_rad = config_.limits.min_pitch_rad;
    cam.max_pitch_rad = config_.limits.max_pitch_rad;
    cam.weight = config_.heading_weight;
    cam.smoothness_weight = config_.heading_smoothness_weight;
    const CameraTrack track =
        config_.camera_solver == PlannerConfig::CameraSolver::kCeres ? solveCameraCeres(cam) : cameraFilter(cam);
    if (!track.ok) {
      result.timings.heading_ms = msSince(t_stage);
      return finish(fallback(req, result, track.reason));
    }
    heading = track.heading_rad;
    pitch = track.pitch_rad;
  } else {  // no worker: follow the reference's angles within the rate limits
    for (int k = 1; k <= N; ++k) {
      const double sh = config_.limits.max_heading_rate_radps * dt, sp = config_.limits.max_pitch_rate_radps * dt;
      const auto i = static_cast<std::size_t>(k);
      heading[i] = common::wrapAngle(heading[i - 1] +
                                     std::clamp(common::wrapAngle(req.reference.heading_rad(k) - heading[i - 1]), -sh, sh));
      pitch[i] = pitch[i - 1] + std::clamp(std::clamp(req.reference.pitch_rad(k), config_.limits.min_pitch_rad,
                                                      config_.limits.max_pitch_rad) - pitch[i - 1], -sp, sp);
    }
  }
  result.timings.heading_ms = msSince(t_stage);

  // ---- verification ---------------------------------------------------------------------------
  t_stage = Clock::now();
  PlannedTrajectory tr;
  tr.uav_index = req.uav_index;
  tr.t0_s = req.t_now_s;
  tr.dt_s = dt;
  for (int k = 0; k <= N; ++k) {
    const auto i = static_cast<std::size_t>(k);
    TrajectorySample s;
    s.p_world = sol.p[i];
    s.v_world = sol.v[i];
    s.a_world = sol.a[i];
    s.heading_rad = heading[i];
    s.pitch_rad = pitch[i];
    tr.samples.push_back(s);
  }
  const VerificationReport rep =
      verifier_->verify(tr, req.t_now_s, req.higher_priority_plans, req.worker, req.t_now_s, dt);
  result.timings.verify_ms = msSince(t_stage);
  if (!rep.ok) return finish(fallback(req, result, rep.reason));
  if (config_.time_budget_ms > 0.0 && msSince(t_start) > config_.time_budget_ms) {
    std::ostringstream os;
    os << "time budget exceeded (" << msSince(t_start) << " ms > " << config_.time_budget_ms << " ms)";
    return finish(fallback(req, result, os.str()));
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
  return finish(result);
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

#include "gesture_formation/planning/trajectory_verifier.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "gesture_formation/common/angles.hpp"

namespace gesture_formation::planning {

TrajectoryPoint evaluateTrajectory(const PlannedTrajectory& tr, double t) {
  TrajectoryPoint out;
  if (tr.samples.empty()) return out;
  const std::size_t n = tr.samples.size();
  const auto& first = tr.samples.front();
  out.p = first.p_world;
  if (n == 1 || !(tr.dt_s > 0.0)) return out;  // a single point: hover there
  if (!(t > tr.t0_s)) {
    out.v = first.v_world;
    out.a = first.a_world;
    return out;
  }
  const double u = (t - tr.t0_s) / tr.dt_s;
  if (u >= static_cast<double>(n - 1)) {
    out.p = tr.samples.back().p_world;
    if (u <= static_cast<double>(n - 1) + 1e-9) {
      out.v = tr.samples.back().v_world;
      out.a = tr.samples.back().a_world;
    }
    return out;  // after the end: hover
  }
  const auto k = static_cast<std::size_t>(std::floor(u));
  const double s = u - static_cast<double>(k);
  const double dt = tr.dt_s;
  const auto& A = tr.samples[k];
  const auto& B = tr.samples[k + 1];
  const double s2 = s * s, s3 = s2 * s;
  out.p = (2 * s3 - 3 * s2 + 1) * A.p_world + (s3 - 2 * s2 + s) * dt * A.v_world + (-2 * s3 + 3 * s2) * B.p_world +
          (s3 - s2) * dt * B.v_world;
  out.v = ((6 * s2 - 6 * s) * A.p_world + (-6 * s2 + 6 * s) * B.p_world) / dt + (3 * s2 - 4 * s + 1) * A.v_world +
          (3 * s2 - 2 * s) * B.v_world;
  out.a = ((12 * s - 6) * A.p_world + (-12 * s + 6) * B.p_world) / (dt * dt) +
          ((6 * s - 4) * A.v_world + (6 * s - 2) * B.v_world) / dt;
  return out;
}

Eigen::Vector3d workerPositionAt(const formation::WorkerHorizon& w, double t0, double dt, double t) {
  const int n = w.steps();
  if (n == 0) return Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  if (n == 1 || !(dt > 0.0) || !(t > t0)) return w.p_world.col(0);
  const double u = (t - t0) / dt;
  if (u >= n - 1) return w.p_world.col(n - 1);
  const int k = static_cast<int>(std::floor(u));
  const double s = u - k;
  return (1.0 - s) * w.p_world.col(k) + s * w.p_world.col(k + 1);
}

BrakeProfile brakeProfile(const Eigen::Vector3d& v, const DynamicLimits& limits, double dt) {
  BrakeProfile b;
  const double speed = v.norm();
  if (!(speed > 1e-9) || !std::isfinite(speed) || !(dt > 0.0)) return b;
  b.speed_mps = speed;
  b.dir = v / speed;
  double amax = limits.max_acceleration_mps2;
  if (std::abs(b.dir.z()) * amax > limits.max_vertical_acceleration_mps2) {
    amax = limits.max_vertical_acceleration_mps2 / std::abs(b.dir.z());
  }
  // The stop on a sample: the braking curve is then one quadratic per interval, which the
  // Hermite spline reproduces exactly.
  b.t_stop_s = std::ceil(speed / amax / dt - 1e-9) * dt;
  b.decel_mps2 = speed / b.t_stop_s;
  return b;
}

Eigen::Vector3d brakeStop(const Eigen::Vector3d& p, const Eigen::Vector3d& v, const DynamicLimits& limits, double dt) {
  const BrakeProfile b = brakeProfile(v, limits, dt);
  return p + 0.5 * b.speed_mps * b.t_stop_s * b.dir;
}

PlannedTrajectory retimeThenBrake(const PlannedTrajectory& plan, double t0, double dt, int n, const DynamicLimits& limits) {
  PlannedTrajectory out;
  out.uav_index = plan.uav_index;
  out.t0_s = t0;
  out.dt_s = dt;
  if (plan.samples.empty()) return out;
  const double t_end = plan.tEnd();
  const TrajectorySample& last = plan.samples.back();
  const BrakeProfile b = brakeProfile(last.v_world, limits, dt);
  for (int k = 0; k < n; ++k) {
    const double t = t0 + k * dt;
    TrajectorySample s;
    const double tau = t - t_end;
    if (tau > 1e-9 && b.speed_mps > 0.0) {  // braking after the end (a stop on a sample of the end's grid)
      const double tb = std::min(tau, b.t_stop_s);
      s.p_world = last.p_world + (b.speed_mps * tb - 0.5 * b.decel_mps2 * tb * tb) * b.dir;
      s.v_world = (b.speed_mps - b.decel_mps2 * tb) * b.dir;
      s.a_world = tau < b.t_stop_s ? Eigen::Vector3d(-b.decel_mps2 * b.dir) : Eigen::Vector3d::Zero();
    } else {
      const TrajectoryPoint x = evaluateTrajectory(plan, t);
      s.p_world = x.p;
      s.v_world = x.v;
      s.a_world = x.a;
    }
    const TrajectorySample angles = plan.sampleAt(t);
    s.heading_rad = angles.heading_rad;
    s.pitch_rad = angles.pitch_rad;
    out.samples.push_back(s);
  }
  return out;
}

std::vector<Eigen::Vector3d> brakeEnvelope(const PlannedTrajectory& plan, double t_until, const DynamicLimits& limits) {
  std::vector<Eigen::Vector3d> out;
  if (plan.samples.empty()) return out;
  const double t_last = std::isfinite(t_until) ? std::min(std::max(t_until, plan.t0_s), plan.tEnd()) : plan.t0_s;
  const auto add = [&](double t) {
    const TrajectoryPoint x = evaluateTrajectory(plan, t);
    const Eigen::Vector3d stop = brakeStop(x.p, x.v, limits, plan.dt_s);
    if (out.empty() || (stop - out.back()).norm() > 1e-6) out.push_back(stop);
  };
  for (std::size_t k = 0; k < plan.samples.size() && plan.t0_s + static_cast<double>(k) * plan.dt_s < t_last; ++k) {
    add(plan.t0_s + static_cast<double>(k) * plan.dt_s);
  }
  add(t_last);
  return out;
}

std::vector<Eigen::Vector3d> keptBrakeEnvelope(const PlannedTrajectory& other, int own_index, double t_now,
                                               const PlannerConfig& config) {
  if (config.brake_envelope_lead_s > 0.0 && other.uav_index > own_index) {
    return brakeEnvelope(other, t_now + config.brake_envelope_lead_s, config.limits);
  }
  if (t_now - other.t0_s > config.brake_envelope_age_s) return brakeEnvelope(other, t_now, config.limits);
  return {};
}

namespace {

/// Another plan without a finite t0 or a positive, finite dt would read as hovering at its first
/// sample (evaluateTrajectory): where its UAV is is unknown. The reason, or empty.
std::string untimedPlan(const std::vector<PlannedTrajectory>& others) {
  for (const auto& other : others) {
    if (!std::isfinite(other.t0_s) || !(other.dt_s > 0.0) || !std::isfinite(other.dt_s)) {
      std::ostringstream os;
      os << "verify: UAV " << other.uav_index << "'s plan has t0 " << other.t0_s << " s, dt " << other.dt_s
         << " s: its positions are unknown";
      return os.str();
    }
  }
  return {};
}

}  // namespace

TrajectoryVerifier::TrajectoryVerifier(const OccupancyMap& map, const DistanceField& field, const PlannerConfig& config,
                                       const SeenSpace* seen)
    : map_(map), field_(field), config_(config), fcl_(map), seen_(seen) {}

std::string TrajectoryVerifier::seenViolation(const PlannedTrajectory& tr) const {
  // From every point within the horizon (samples and substeps), the straight braking path to
  // brakeStop() must run through observed space (seen_space.hpp); the plan's start is exempt
  // within the margin (the UAV is there).
  const Eigen::Vector3d start = tr.samples.front().p_world;
  const double step = 0.5 * seen_->resolution();
  const int sub = config_.verify_substeps;
  const int intervals = static_cast<int>(tr.samples.size()) - 1;
  for (int k = 0; k < intervals; ++k) {
    for (int q = (k == 0 ? 0 : 1); q <= sub; ++q) {
      const double tau = (k + static_cast<double>(q) / sub) * tr.dt_s;
      if (tau > seen_->rule().horizon_s + 1e-9) return {};
      const TrajectoryPoint x = evaluateTrajectory(tr, tr.t0_s + tau);
      const Eigen::Vector3d stop = brakeStop(x.p, x.v, config_.limits, tr.dt_s);
      const double length = (stop - x.p).norm();
      const int n = std::max(1, static_cast<int>(std::ceil(length / step)));
      for (int i = 0; i <= n; ++i) {
        const Eigen::Vector3d p = x.p + (stop - x.p) * (static_cast<double>(i) / n);
        const auto unseen = seen_->unseenNear(p, start);
        if (!unseen) continue;
        std::ostringstream os;
        os.precision(4);
        os << "verify: braking from t=" << tr.t0_s + tau << " passes (" << p.transpose() << "), within "
           << seen_->rule().margin_m << " m of the unobserved voxel (" << unseen->transpose() << ")";
        return os.str();
      }
    }
  }
  return {};
}

TrajectoryVerifier::~TrajectoryVerifier() = default;

VerificationReport TrajectoryVerifier::verify(const PlannedTrajectory& tr, double t_now, const std::vector<PlannedTrajectory>& others,
                                              const formation::WorkerHorizon& worker, double worker_t0, double worker_dt) const {
  VerificationReport rep;
  const auto fail = [&rep](const std::string& why) {
    rep.ok = false;
    if (rep.reason.empty()) rep.reason = why;
    return rep;
  };
  if (tr.samples.size() < 2 || !(tr.dt_s > 0.0) || !std::isfinite(tr.t0_s)) return fail("verify: trajectory has < 2 samples or bad dt/t0");
  for (std::size_t k = 0; k < tr.samples.size(); ++k) {
    const auto& s = tr.samples[k];
    if (!s.p_world.allFinite() || !s.v_world.allFinite() || !s.a_world.allFinite() || !std::isfinite(s.heading_rad) ||
        !std::isfinite(s.pitch_rad)) {
      std::ostringstream os;
      os << "verify: sample " << k << " is not finite";
      return fail(os.str());
    }
  }
  const DynamicLimits& L = config_.limits;
  const double rel = 1.0 + config_.verify_tolerance;
  const double tol = config_.verify_tolerance;
  const double rho = OccupancyMap::rasterInflation(map_.resolution());
  // Heading / pitch rate limits between samples.
  for (std::size_t k = 0; k + 1 < tr.samples.size(); ++k) {
    const double dh = std::abs(common::wrapAngle(tr.samples[k + 1].heading_rad - tr.samples[k].heading_rad));
    const double dp = std::abs(tr.samples[k + 1].pitch_rad - tr.samples[k].pitch_rad);
    if (dh > L.max_heading_rate_radps * tr.dt_s * rel + 1e-9 || dp > L.max_pitch_rate_radps * tr.dt_s * rel + 1e-9) {
      std::ostringstream os;
      os << "verify: camera rate limit exceeded between samples " << k << " and " << k + 1 << " (heading step " << dh
         << " rad, pitch step " << dp << " rad)";
      return fail(os.str());
    }
  }
  if (const std::string why = untimedPlan(others); !why.empty()) return fail(why);
  // Required distances to the other plans (age margin; recovery: requiredUavDistance) and to the worker.
  std::vector<double> required(others.size());
  for (std::size_t j = 0; j < others.size(); ++j) {
    required[j] = uavKeepOutDistance(config_, t_now - others[j].t0_s);
  }
  const TrajectoryPoint start = evaluateTrajectory(tr, tr.t0_s);
  std::vector<double> start_dist(others.size());
  for (std::size_t j = 0; j < others.size(); ++j) start_dist[j] = (start.p - evaluateTrajectory(others[j], tr.t0_s).p).norm();
  // Braking envelopes: where the others may have stopped (or stop before we learn of it).
  std::vector<std::vector<Eigen::Vector3d>> envelope(others.size());
  std::vector<double> start_envelope(others.size(), std::numeric_limits<double>::infinity());
  for (std::size_t j = 0; j < others.size(); ++j) {
    envelope[j] = keptBrakeEnvelope(others[j], tr.uav_index, t_now, config_);
    if (!envelope[j].empty()) start_envelope[j] = distanceToPolyline(envelope[j], start.p);
  }
  const bool has_worker = worker.steps() > 0;
  const double start_worker = has_worker ? (start.p - workerPositionAt(worker, worker_t0, worker_dt, tr.t0_s)).norm() : 0.0;
  // The first interval is relaxed only for a start that is itself closer than verify_clearance_m,
  // and then to "not worse" than it (docs/planning.md §7): measured exactly once the field's lower
  // bound — up to sqrt(3)·resolution + rho short — says it might be; the bound alone relaxed a start
  // that was clear, and let one that was not get closer by the field's error.
  double start_clear = field_.clearance(start.p) - rho;
  // Less a tenth of a millimetre: a ball of exactly the start's clearance touches the nearest cube,
  // which FCL counts as a collision — the start itself would fail.
  if (start_clear < config_.verify_clearance_m) start_clear = fcl_.clearance(start.p) - 1e-4;

  rep.min_obstacle_clearance_m = std::numeric_limits<double>::infinity();
  rep.min_uav_margin_m = std::numeric_limits<double>::infinity();
  rep.min_worker_distance_m = std::numeric_limits<double>::infinity();
  const int sub = config_.verify_substeps;
  const int intervals = static_cast<int>(tr.samples.size()) - 1;
  for (int k = 0; k < intervals; ++k) {
    const bool first = k == 0;
    const TrajectoryPoint s0 = evaluateTrajectory(tr, tr.t0_s + k * tr.dt_s);
    for (int q = (k == 0 ? 0 : 1); q <= sub; ++q) {
      const double t = tr.t0_s + (k + static_cast<double>(q) / sub) * tr.dt_s;
      TrajectoryPoint x = evaluateTrajectory(tr, t);
      if (q == sub) {  // the sample itself (exact, avoids the after-end hover rule)
        const auto& smp = tr.samples[static_cast<std::size_t>(k + 1)];
        x.p = smp.p_world;
        x.v = smp.v_world;
        x.a = (evaluateTrajectory(tr, t - 1e-9 * tr.dt_s)).a;
      }
      std::ostringstream os;
      os.precision(4);
      // Dynamic limits (the first interval: not worse than the measured state).
      const double vmax = first ? std::max(L.max_speed_mps, s0.v.norm()) : L.max_speed_mps;
      const double vzmax = first ? std::max(L.max_vertical_speed_mps, std::abs(s0.v.z())) : L.max_vertical_speed_mps;
      const double amax = first ? std::max(L.max_acceleration_mps2, s0.a.norm()) : L.max_acceleration_mps2;
      const double azmax = first ? std::max(L.max_vertical_acceleration_mps2, std::abs(s0.a.z())) : L.max_vertical_acceleration_mps2;
      rep.max_speed_mps = std::max(rep.max_speed_mps, x.v.norm());
      rep.max_acceleration_mps2 = std::max(rep.max_acceleration_mps2, x.a.norm());
      if (x.v.norm() > vmax * rel || std::abs(x.v.z()) > vzmax * rel) {
        os << "verify: speed " << x.v.norm() << " m/s (vertical " << x.v.z() << ") exceeds the limit at t=" << t;
        return fail(os.str());
      }
      if (x.a.norm() > amax * rel || std::abs(x.a.z()) > azmax * rel) {
        os << "verify: acceleration " << x.a.norm() << " m/s^2 (vertical " << x.a.z() << ") exceeds the limit at t=" << t;
        return fail(os.str());
      }
      // Obstacles.
      const double lower = field_.clearance(x.p) - rho;
      rep.min_obstacle_clearance_m = std::min(rep.min_obstacle_clearance_m, std::max(0.0, lower));
      const double need = first ? std::min(config_.verify_clearance_m, std::max(0.0, start_clear)) : config_.verify_clearance_m;
      if (lower < need && fcl_.collides(x.p, need)) {
        os << "verify: obstacle within " << need << " m of (" << x.p.transpose() << ") at t=" << t;
        return fail(os.str());
      }
      // Other UAVs' plans.
      for (std::size_t j = 0; j < others.size(); ++j) {
        const double d = (x.p - evaluateTrajectory(others[j], t).p).norm();
        const double req = recoveringDistance(config_, required[j], start_dist[j], t - tr.t0_s);
        rep.min_uav_margin_m = std::min(rep.min_uav_margin_m, d - required[j]);
        if (!(d >= req - tol)) {  // a NaN plan sample fails (a NaN compares false)
          os << "verify: " << d << " m from UAV " << others[j].uav_index << "'s plan at t=" << t << " (need " << req << " m)";
          return fail(os.str());
        }
        if (!envelope[j].empty()) {
          const double de = distanceToPolyline(envelope[j], x.p);
          const double req_e = recoveringDistance(config_, config_.mutual_distance_m, start_envelope[j], t - tr.t0_s);
          rep.min_uav_margin_m = std::min(rep.min_uav_margin_m, de - config_.mutual_distance_m);
          if (!(de >= req_e - tol)) {
            os << "verify: " << de << " m from UAV " << others[j].uav_index << "'s braking envelope at t=" << t << " (need "
               << req_e << " m)";
            return fail(os.str());
          }
        }
      }
      // Worker.
      if (has_worker) {
        const double d = (x.p - workerPositionAt(worker, worker_t0, worker_dt, t)).norm();
        rep.min_worker_distance_m = std::min(rep.min_worker_distance_m, d);
        const double limit = config_.worker_safety_distance_m;
        const double req = recoveringDistance(config_, limit, start_worker, t - tr.t0_s);
        if (!(d >= req - tol)) {  // a NaN worker prediction fails
          os << "verify: " << d << " m from the worker at t=" << t << " (need " << req << " m)";
          return fail(os.str());
        }
      }
    }
  }
  if (seen_ != nullptr) {
    const std::string unseen = seenViolation(tr);
    if (!unseen.empty()) return fail(unseen);
  }
  rep.ok = true;
  return rep;
}

}  // namespace gesture_formation::planning

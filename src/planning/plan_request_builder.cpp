#include "gesture_formation/planning/plan_request_builder.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "gesture_formation/common/csv.hpp"

namespace gesture_formation::planning {

const char* toString(HoldMode mode) {
  switch (mode) {
    case HoldMode::kTrack: return "track";
    case HoldMode::kHold: return "hold";
    case HoldMode::kSearch: return "search";
  }
  return "unknown";
}

PlanRequest buildPlanRequest(const PlanRequestInputs& in) {
  PlanRequest req;
  const int i = in.uav_index;
  const int steps = in.worker.steps();
  req.uav_index = i;
  req.t_now_s = in.t_s;
  req.dt_s = in.dt_s;
  req.state = in.state;
  req.state.t_s = in.t_s;
  req.wind_estimate_mps = in.wind_estimate_mps;
  req.worker = in.worker;
  if (in.camera_target != nullptr) req.camera_target = *in.camera_target;
  const int slot = in.slot >= 0 ? in.slot : i;  // the reference flown (a hand-over moves it)
  const bool hold = in.hold_reference != nullptr;
  const bool has_leader_plan = slot != 0 && in.leader_plan != nullptr && !in.leader_plan->empty();
  const bool leader_plan_fresh = has_leader_plan && in.t_s - in.leader_plan->t0_s <= in.leader_plan_max_age_s;
  if (hold) {
    req.reference = *in.hold_reference;
    if (has_leader_plan) req.higher_priority_plans.push_back(*in.leader_plan);
  } else if (slot == 0) {
    formation::leaderHorizon(in.worker, in.params->leader, req.reference);
  } else {
    formation::LeaderPlan lp;
    const formation::UavObservation& own = in.params->followers[static_cast<std::size_t>(slot - 1)];
    if (leader_plan_fresh) {
      lp.heading_rad.resize(1, steps);
      lp.pitch_rad.resize(1, steps);
      // Every follower's elevation γ_j − ξ_L within the limits: ξ_L in [max_j γ_j − gamma_max,
      // min_j γ_j − gamma_min] — one range for all followers (clamped each to its own, two could
      // meet at one elevation); FormationState keeps the desired −γ_L inside it.
      const double deg = M_PI / 180.0;
      double lo = -1e9, hi = 1e9;
      if (in.limits) {
        for (const formation::UavObservation& f : in.params->followers) {
          lo = std::max(lo, (f.gamma_deg - in.limits->gamma_max_deg) * deg);
          hi = std::min(hi, (f.gamma_deg - in.limits->gamma_min_deg) * deg);
        }
      }
      for (int k = 0; k < steps; ++k) {
        const auto s = in.leader_plan->sampleAt(in.t_s + k * in.dt_s);
        lp.heading_rad(k) = s.heading_rad;
        lp.pitch_rad(k) = std::clamp(s.pitch_rad, lo, hi);
      }
    }
    formation::followerHorizon(in.worker, in.params->leader, leader_plan_fresh ? &lp : nullptr, own, req.reference);
    if (has_leader_plan) req.higher_priority_plans.push_back(*in.leader_plan);
  }
  if (in.received == nullptr) return req;
  for (int j = 0; j < static_cast<int>(in.received->size()); ++j) {
    const auto& m = (*in.received)[static_cast<std::size_t>(j)];
    if (j == i || j == in.leader_index || !m || m->plan.empty()) continue;  // the leader's plan: leader_plan
    // A UAV not heard from for max_plan_age_s (dropout, outage, lost link) cannot be expected
    // to dodge: it has right of way, like one that fell back.
    const bool silent = in.t_s - m->plan.t0_s > in.rule.max_plan_age_s;
    if (hold || j < i || m->fallback || silent || in.rule.avoid_all_plans) req.higher_priority_plans.push_back(m->plan);
  }
  return req;
}

std::string holdReason(int uav_index, double t_s, double share_stamp_s, double worker_stamp_s,
                       const FreshnessLimits& limits) {
  // A stamp further in the future than the limit (a clock gone back, another time line) is as
  // unusable as an old one: its age would pass for fresh for as long as the clocks differ.
  const auto older = [&](double stamp, double limit) {
    return !std::isfinite(stamp) || !(t_s - stamp <= limit) || !(stamp - t_s <= limit);
  };
  if (uav_index == 0) {
    return older(worker_stamp_s, limits.max_worker_age_s) ? "worker not seen for more than max_worker_age_s" : "";
  }
  if (older(share_stamp_s, limits.max_share_age_s)) return "leader share older than max_share_age_s";
  if (older(worker_stamp_s, limits.max_worker_age_s)) return "worker estimate older than max_worker_age_s";
  return "";
}

Eigen::Vector3d brakingPoint(const Eigen::Vector3d& p_world, const Eigen::Vector3d& v_world, double brake_accel_mps2) {
  const double a = std::max(1e-3, brake_accel_mps2);
  return p_world + v_world * (v_world.norm() / (2.0 * a));
}

bool searching(int uav_index, const std::string& hold_reason, double t_s, double worker_stamp_s,
               const FreshnessLimits& limits, const SearchConfig& config) {
  return uav_index == 0 && config.timeout_s > 0.0 && hold_reason == "worker not seen for more than max_worker_age_s" &&
         std::isfinite(worker_stamp_s) && t_s - worker_stamp_s <= limits.max_worker_age_s + config.timeout_s;
}

formation::HorizonPoints searchTargets(const Eigen::Vector3d& worker_world, const Eigen::Vector3d& camera_world,
                                       double t_s, double dt_s, int steps, double worker_stamp_s, double sweep_begin_s,
                                       const SearchConfig& config) {
  formation::HorizonPoints out(3, std::max(0, steps));
  const double period = config.period_s > 0.0 ? config.period_s : 1.0;
  const auto triangle = [](double phase) {  // 0 → 1 → 0 → −1 → 0 per unit of phase
    const double f = phase - std::floor(phase);
    return f < 0.25 ? 4.0 * f : (f < 0.75 ? 2.0 - 4.0 * f : 4.0 * f - 4.0);
  };
  const Eigen::Vector2d rel = (worker_world - camera_world).head<2>();
  const double horizontal = rel.norm();
  const bool turn = config.horizontal_speed_mps > 0.0 && horizontal > 1e-6;
  for (int k = 0; k < out.cols(); ++k) {
    const double t = t_s + k * dt_s;
    const double phase = std::max(0.0, t - sweep_begin_s) / period;
    const double age = std::max(0.0, t - worker_stamp_s);
    const double amplitude = std::min(config.height_m, config.vertical_speed_mps * age);
    Eigen::Vector3d target = worker_world;
    if (turn) {
      const double angle = std::atan2(config.horizontal_speed_mps * age, horizontal) * triangle(0.5 * phase);
      target.head<2>() = camera_world.head<2>() + Eigen::Rotation2Dd(angle) * rel;
    }
    out.col(k) = target + Eigen::Vector3d(0.0, 0.0, amplitude * triangle(phase));
  }
  return out;
}

formation::ReferenceTrajectory holdReference(const Eigen::Vector3d& hold_world, const Eigen::Vector3d& worker_world,
                                             double heading_rad, int steps) {
  const Eigen::Vector3d to_worker = worker_world - hold_world;
  const double horizontal = to_worker.head<2>().norm();
  const double heading = horizontal > 1e-6 ? std::atan2(to_worker.y(), to_worker.x()) : heading_rad;
  const double pitch = std::atan2(to_worker.z(), std::max(1e-6, horizontal));
  formation::ReferenceTrajectory ref;
  ref.resize(steps);
  for (int k = 0; k < steps; ++k) {
    ref.p_world.col(k) = hold_world;
    ref.heading_rad(k) = heading;
    ref.pitch_rad(k) = pitch;
  }
  return ref;
}

HoldPlanner::Decision HoldPlanner::decide(const Situation& s) {
  Decision d;
  if (s.hold_reason.empty()) {
    hold_p_.reset();
    sweep_begin_s_ = std::numeric_limits<double>::quiet_NaN();
    return d;
  }
  if (!hold_p_) hold_p_ = brakingPoint(s.p_world, s.v_world, brake_accel_mps2_);  // latched: no drift
  d.reference = holdReference(*hold_p_, s.worker_world, s.heading_rad, s.steps);
  const bool search =
      s.worker_lost && searching(s.uav_index, s.hold_reason, s.t_s, s.worker_stamp_s, limits_, search_);
  if (!search) {
    sweep_begin_s_ = std::numeric_limits<double>::quiet_NaN();
    d.mode = HoldMode::kHold;
    return d;
  }
  if (!std::isfinite(sweep_begin_s_)) sweep_begin_s_ = s.t_s;
  d.mode = HoldMode::kSearch;
  d.camera_target =
      searchTargets(s.worker_world, *hold_p_, s.t_s, s.dt_s, s.steps, s.worker_stamp_s, sweep_begin_s_, search_);
  return d;
}

}  // namespace gesture_formation::planning

#include "gesture_formation/planning/replan_step.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace gesture_formation::planning {

const char* toString(ReplanMode mode) {
  switch (mode) {
    case ReplanMode::kSkipped: return "skipped";
    case ReplanMode::kTrack: return "track";
    case ReplanMode::kHold: return "hold";
    case ReplanMode::kSearch: return "search";
    case ReplanMode::kAbort: return "abort";
  }
  return "unknown";
}

const common::FieldTable<ReplanConfig>& replanConfigFields() {
  using common::Range;
  using C = ReplanConfig;
  static const common::FieldTable<C> t{{
      {"horizon_dt_s", Range::openClosed(0.0, 2.0), [](C& c) { return &c.dt_s; }},
      {"horizon_steps", Range::closed(2, formation::kMaxHorizonSteps), [](C& c) { return &c.steps; }},
      {"controller.brake_accel_mps2", Range::openClosed(0.0, 50.0), [](C& c) { return &c.brake_accel_mps2; }},
      {"faults.max_share_age_s", Range::positive(), [](C& c) { return &c.freshness.max_share_age_s; }},
      {"faults.max_worker_age_s", Range::positive(), [](C& c) { return &c.freshness.max_worker_age_s; }},
      {"faults.max_plan_age_s", Range::positive(), [](C& c) { return &c.rule.max_plan_age_s; }},
      {"faults.search_timeout_s", Range::nonNegative(), [](C& c) { return &c.search.timeout_s; }},
      {"faults.search_height_m", Range::positive(), [](C& c) { return &c.search.height_m; }},
      {"faults.search_vertical_speed_mps", Range::positive(), [](C& c) { return &c.search.vertical_speed_mps; }},
      {"faults.search_period_s", Range::positive(), [](C& c) { return &c.search.period_s; }},
      {"faults.search_horizontal_speed_mps", Range::nonNegative(),
       [](C& c) { return &c.search.horizontal_speed_mps; }},
      {"faults.reach_walking_speed_mps", Range::closed(0.0, 10.0), [](C& c) { return &c.reach.walking_speed_mps; }},
      {"faults.reach_base_m", Range::closed(0.0, 20.0), [](C& c) { return &c.reach.base_m; }},
      {"faults.reach_max_m", Range::openClosed(0.0, 100.0), [](C& c) { return &c.reach.max_radius_m; }},
      {"faults.reach_margin_m", Range::closed(0.0, 20.0), [](C& c) { return &c.reach.margin_m; }},
  }};
  return t;
}

std::vector<std::string> ReplanConfig::validate(const std::string& prefix) const {
  return common::problemLines(replanConfigFields().rangeProblems(*this), prefix);
}

ReplanStep::ReplanStep(const ReplanConfig& config, std::unique_ptr<Planner> planner, const RetreatSpace& space)
    : config_(config),
      planner_(std::move(planner)),
      hold_(config.freshness, config.search, config.brake_accel_mps2),
      abort_(config.uav_index, config.uav_count, config.abort, space),
      reach_(config.uav_index, config.uav_count, config.reach, config.abort, space),
      space_(space),
      heading_(config.worker_heading) {}

void ReplanStep::restart(std::unique_ptr<Planner> planner) {
  planner_ = std::move(planner);
  hold_ = HoldPlanner(config_.freshness, config_.search, config_.brake_accel_mps2);
  abort_ = AbortPlanner(config_.uav_index, config_.uav_count, config_.abort, space_);
  reach_ = ReachKeeper(config_.uav_index, config_.uav_count, config_.reach, config_.abort, space_);
  heading_ = formation::WorkerHeading(config_.worker_heading);
  flown_ = PlannedTrajectory{};
  listen_since_s_ = std::numeric_limits<double>::quiet_NaN();
  listening_ = true;
  flying_backoff_ = false;
  verified_for_.reset();
}

std::vector<int> ReplanStep::unheardSince(const ReplanInputs& in, double since_s) const {
  if (in.received == nullptr) return {};
  const auto& plans = *in.received;
  const int self = config_.uav_index;
  std::vector<int> unheard;
  // Every other UAV — UAV 0 too when, after a hand-over, it flies as a follower — but the leader
  // whose plan came with its share (gfctl simulate; over ROS it comes on the plan link only). A UAV
  // missing from a short received table is waited for too.
  for (int j = 0; j < std::max(config_.uav_count, static_cast<int>(plans.size())); ++j) {
    if (j == self || (j == in.leader_index && in.leader_plan_in_share)) continue;
    const bool heard = j < static_cast<int>(plans.size()) && plans[static_cast<std::size_t>(j)] &&
                       plans[static_cast<std::size_t>(j)]->plan.t0_s >= since_s;
    if (!heard) unheard.push_back(j);
  }
  return unheard;
}

std::string ReplanStep::listeningHold(const ReplanInputs& in) {
  if (!listening_) return "";
  if (!std::isfinite(listen_since_s_)) listen_since_s_ = in.t_s;
  const std::vector<int> unheard = unheardSince(in, listen_since_s_);
  if (unheard.empty() || in.t_s - listen_since_s_ > config_.rule.max_plan_age_s) {
    listening_ = false;
    return "";
  }
  return "listening: waiting for a plan from every other UAV since the (re)start";
}

struct ReplanStep::Choice {
  formation::ReferenceTrajectory reference;  ///< hold / search / abort: the reference
  formation::HorizonPoints camera_target;    ///< search: the sweep; otherwise 0 columns
  bool given = false;                        ///< a reference is given (the UAV does not track)
};

ReplanStep::Choice ReplanStep::choose(const ReplanInputs& in, const std::string& hold, const Eigen::Vector3d& worker_p0,
                                      ReplanOutcome& out) {
  Choice c;
  if (abort_.aborting() && hold.empty()) {
    AbortPlanner::Situation s;
    s.t_s = in.t_s;
    s.dt_s = config_.dt_s;
    s.steps = config_.steps;
    s.p_world = in.state.p_world;
    s.v_world = in.state.v_world;
    s.heading_rad = in.state.heading_rad;
    s.worker_world = worker_p0;
    s.home_world = *home_;
    s.brake_accel_mps2 = config_.brake_accel_mps2;
    AbortPlanner::Decision d = abort_.decide(s);
    out.mode = ReplanMode::kAbort;
    out.reason = d.reason;
    out.abort_phase = d.phase;
    out.abort_phase_changed = d.phase_changed;
    c.reference = std::move(d.reference);
    c.given = true;
    reach_.release();
    return c;
  }
  HoldPlanner::Situation situation;
  situation.uav_index = in.slot >= 0 ? in.slot : config_.uav_index;  // the leader's slot searches
  situation.t_s = in.t_s;
  situation.dt_s = config_.dt_s;
  situation.steps = config_.steps;
  situation.hold_reason = hold;
  situation.worker_stamp_s = in.worker->fused_s;
  situation.worker_lost = in.worker->lost;
  situation.p_world = in.state.p_world;
  situation.v_world = in.state.v_world;
  situation.heading_rad = in.state.heading_rad;
  situation.worker_world = worker_p0;
  HoldPlanner::Decision decision = hold_.decide(situation);
  out.mode = decision.mode == HoldMode::kSearch ? ReplanMode::kSearch
             : decision.holding()               ? ReplanMode::kHold
                                                : ReplanMode::kTrack;
  out.reason = hold;
  c.given = decision.holding();
  c.reference = std::move(decision.reference);
  c.camera_target = std::move(decision.camera_target);
  if (c.given) {
    keepReachClear(in, worker_p0, c, out);
  } else {
    reach_.release();
  }
  return c;
}

void ReplanStep::keepReachClear(const ReplanInputs& in, const Eigen::Vector3d& worker_p0, Choice& c,
                                ReplanOutcome& out) {
  ReachKeeper::Situation s;
  s.t_s = in.t_s;
  s.p_world = in.state.p_world;
  s.hold_world = hold_.holdPoint().value_or(in.state.p_world);
  s.fused_s = in.worker->fused_s;
  const ReachKeeper::Decision d = reach_.decide(s);
  out.backoff_started = d.started;
  out.backoff = d.reason;
  if (!d.goal) return;
  out.backing_off = true;
  // An ordinary reference through the planner (verification, fallbacks), camera on the estimate.
  c.reference = approachReference(in.state.p_world, *d.goal, worker_p0, in.state.heading_rad, config_.abort.speed_mps,
                                  config_.dt_s, config_.steps);
}

std::string ReplanStep::reflyRefusal(ReplanMode mode) const {
  if (!verified_for_) return "";  // none, or a stop
  // A hold or search that flew on the tracking plan would follow the stale prediction the hold
  // is for, for up to the plan's horizon; an abort that flew on anything but its own would not
  // retreat.
  const bool refused = mode == ReplanMode::kAbort ? *verified_for_ != ReplanMode::kAbort
                       : mode == ReplanMode::kHold || mode == ReplanMode::kSearch ? *verified_for_ == ReplanMode::kTrack
                                                                                  : false;
  return refused ? std::string("previous plan made for ") + toString(*verified_for_) + ", not " + toString(mode) : "";
}

ReplanOutcome ReplanStep::step(const ReplanInputs& in) {
  ReplanOutcome out;
  const int i = config_.uav_index;
  const int role = in.slot >= 0 ? in.slot : i;  // 0: plans as the leader (a hand-over moves the slot)
  const double t = in.t_s;
  // A state that is not finite (odometry gone wrong) plans nothing: a braking point, a hold point,
  // an abort's goal or the take-off point latched from it would stay NaN for the rest of the hold
  // or abort (every plan then refused, the reach check silently off).
  if (!in.state.p_world.allFinite() || !in.state.v_world.allFinite() || !std::isfinite(t)) {
    out.reason = "the UAV's state (position, velocity) or the time is not finite";
    return out;
  }
  if (!home_) home_ = config_.home_world.allFinite() ? config_.home_world : in.state.p_world;
  if (in.worker == nullptr) {
    out.reason = role == 0 ? "no confirmed worker estimate yet" : "no leader share received yet";
    return out;
  }
  const WorkerKnowledge& w = *in.worker;
  reach_.observe(w);
  // Freshness first, then listening (a UAV listens from its first replanning with data). An
  // aborting UAV does not hold for stale data (it retreats from what it last knew); it listens.
  const std::string stale = holdReason(role, t, w.stamp_s, w.fused_s, config_.freshness);
  std::string hold = abort_.aborting() ? std::string() : stale;
  if (hold.empty()) {
    const double since = listen_since_s_;
    const bool was_listening = listening_;
    hold = listeningHold(in);
    if (was_listening && !listening_ && in.received != nullptr) {
      const std::vector<int> unheard = unheardSince(in, std::isfinite(since) ? since : t);
      if (!unheard.empty()) {
        out.note = "no plan since the start from UAV(s)";
        for (int j : unheard) out.note += " " + std::to_string(j);
        out.note += " after max_plan_age_s; tracking without them";
      }
    }
  }
  // The worker over the horizon: extrapolated from its stamp while fresh (a listening hold too:
  // he may walk up to the holding UAV), frozen otherwise.
  const bool still = !stale.empty() || w.lost;
  const Eigen::Vector3d v0 = still ? Eigen::Vector3d::Zero() : w.v_world;
  const Eigen::Vector3d p0 = still ? w.p_world : w.positionAt(std::max(t, w.stamp_s));
  const double heading = still ? heading_.heading() : heading_.update(v0);
  out.worker = formation::constantVelocityHorizon(p0, v0, heading, config_.steps, config_.dt_s);
  const Choice choice = choose(in, hold, p0, out);

  PlanRequestInputs req_in;
  req_in.uav_index = i;
  req_in.slot = in.slot;
  req_in.leader_index = in.leader_index;
  req_in.t_s = t;
  req_in.dt_s = config_.dt_s;
  req_in.state = in.state;
  req_in.state.a_world = flown_.empty() ? Eigen::Vector3d::Zero() : Eigen::Vector3d(flown_.sampleAt(t).a_world);
  req_in.wind_estimate_mps = in.wind_estimate_mps;
  req_in.worker = out.worker;
  req_in.params = in.params;
  req_in.leader_plan = in.leader_plan;
  req_in.leader_plan_max_age_s = config_.freshness.max_share_age_s;
  req_in.received = in.received;
  req_in.hold_reference = choice.given ? &choice.reference : nullptr;  // also: avoid every received plan
  if (choice.camera_target.cols() > 0) req_in.camera_target = &choice.camera_target;
  req_in.rule = config_.rule;
  req_in.limits = &config_.formation_limits;
  PlanRequest request = buildPlanRequest(req_in);
  // A back-off is for an unseen worker's reach; once the UAV tracks (or holds) again, a failed plan
  // brakes where it is rather than flying the back-off on, away from the worker and out of view.
  const std::string refly_refusal = reflyRefusal(out.mode);
  request.reuse_previous = (!flying_backoff_ || out.backing_off) && refly_refusal.empty();
  if (!refly_refusal.empty()) request.no_reuse_reason = refly_refusal;
  out.reference = request.reference;
  out.result = planner_->plan(request);
  if (out.result.verified && out.result.status == PlanStatus::kOptimized) verified_for_ = out.mode;
  if (out.result.verified && out.result.status == PlanStatus::kFallbackBrake) verified_for_.reset();
  if (out.backing_off) {
    flying_backoff_ = !out.result.trajectory.empty();
  } else if (out.result.status == PlanStatus::kOptimized) {
    flying_backoff_ = false;
  }
  // Holding and aborting UAVs have right of way: nobody counts on them to dodge.
  out.fallback = out.result.status != PlanStatus::kOptimized || choice.given;
  flown_ = out.result.trajectory;  // empty: the controller brakes to hover on its own
  return out;
}

}  // namespace gesture_formation::planning

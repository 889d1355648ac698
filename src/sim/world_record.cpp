#include "gesture_formation/sim/world_record.hpp"

#include "gesture_formation/formation/formation_commands.hpp"

namespace gesture_formation::sim {

WorldRecord::WorldRecord(const MissionConfig& config, const ObstacleDistance& obstacles, std::uint64_t seed)
    : n_(config.formation.params.uavCount()),
      metrics_(config, obstacles, seed),
      schedule_(config.requests, "mission"),
      versions_(config.formation.params),
      params_(config.formation.params),
      plan_mode_(static_cast<std::size_t>(n_)),
      config_(config),
      obstacles_(obstacles) {}

std::uint64_t WorldRecord::planVersion(const PlanReport& p) const {
  if (p.uav == formation::kLeader || p.params_version > 0 || !p.formation || p.formation->uavCount() != n_) {
    return p.params_version;
  }
  return versions_.versionOf(*p.formation).value_or(p.params_version);
}

void WorldRecord::plan(const PlanReport& p) {
  if (p.uav < 0 || p.uav >= n_) return;
  metrics_.plan(p.uav, p.planned_at_s, planVersion(p), p.status, p.planning_ms, p.reason);
  // The planners' modes (docs/safety.md §1): hold replannings and every change → modes.csv.
  if (p.mode == "hold" || p.mode == "search") ++metrics_.counters().plans_hold;
  auto& last = plan_mode_[static_cast<std::size_t>(p.uav)];
  if (!p.mode.empty() && p.mode != last) {
    last = p.mode;
    modes_.push_back(ModeChange{p.planned_at_s, p.uav, p.mode, p.mode_reason.empty() ? "fresh data" : p.mode_reason});
  }
}

void WorldRecord::params(const ParamsReport& p) {
  if (p.params && p.params->uavCount() == n_) {
    params_ = *p.params;
    versions_.published(p.version, *p.params);
  }
  if (p.last_command.empty()) return;
  // Re-published parameters repeat the last command: one outcome per (command, status).
  const std::string key = p.last_command + "|" + p.last_status;
  if (key == last_outcome_key_) return;
  last_outcome_key_ = key;
  if (p.last_status == formation::toString(formation::CommandStatus::kDuplicate)) {
    ++metrics_.counters().commands_duplicate;
  }
  metrics_.commandOutcome(
      CommandOutcome{p.last_source, p.last_status, p.last_command_stamp_s, p.stamp_s, p.version, p.last_uavs},
      kStampToleranceS);
}

std::vector<formation::FormationCommand> WorldRecord::dueRequests(double t_s) {
  std::vector<formation::FormationCommand> out;
  for (auto& d : schedule_.due(t_s)) {
    metrics_.addRequest(d.record);
    out.push_back(std::move(d.command));
  }
  metrics_.resolveOutcomes(kStampToleranceS);
  return out;
}

bool WorldRecord::abortDue(double t_s) {
  const std::optional<AbortEvent>& e = config_.faults.abort;
  if (!e || abort_requested_ || e->source != planning::AbortSource::kOperator || t_s < e->t_s) return false;
  abort_requested_ = true;
  if (!abort_) abort_.emplace(*e, n_, obstacles_);
  return true;
}

void WorldRecord::abortState(const AbortReport& r) {
  if (r.uav < 0 || r.uav >= n_ || !r.phase) return;
  if (!abort_) abort_.emplace(AbortEvent{r.accepted_s, r.source}, n_, obstacles_);
  abort_->accepted(r.uav, r.accepted_s);
  abort_->phase(r.uav, r.t_s, *r.phase);
}

void WorldRecord::gestureFired(double t_s, int gesture_id, const gesture::GestureMapping& mapping) {
  metrics_.addRequest(firedGestureRecord(t_s, gesture_id, mapping));
  metrics_.resolveOutcomes(kStampToleranceS);
}

void WorldRecord::divertWorker(double t_s, WorkerModel& worker, const std::vector<std::optional<MultirotorState>>& truths) {
  const std::optional<WorkerApproach>& a = config_.faults.worker_approach;
  if (!a || approach_ || t_s < a->t_s || a->uav >= static_cast<int>(truths.size())) return;
  const auto& target = truths[static_cast<std::size_t>(a->uav)];
  if (!target) return;
  divertTowards(worker, t_s, *a, target->p_world);
  approach_.emplace(*a, n_, config_.formation.limits.safety_distance_m, config_.faults.camera_blackouts);
}

bool WorldRecord::sampleSafety(double t_s, const std::vector<std::optional<MultirotorState>>& truths,
                               const WorkerState& worker) {
  std::vector<Eigen::Vector3d> p_world;
  for (const auto& s : truths) {
    if (!s) return false;
    p_world.push_back(s->p_world);
  }
  metrics_.sampleSafety(t_s, p_world, worker);
  if (approach_) approach_->sample(t_s, p_world, worker.p_world);
  if (abort_) abort_->sample(t_s, p_world, worker.p_world);
  return true;
}

bool WorldRecord::finish(const std::vector<GestureEpisode>& gestures, double sim_time_s, double wall_time_s,
                         const std::string& dir, std::string* error, std::string* warning) {
  // What the ROS system does not report (docs/ros.md): the planners' skipped replannings, command
  // ages, the LCM links' counters, QP sparse timeouts (logged by the planner).
  metrics_.counters().not_measured = {"plans_skipped",  "commands_stale",      "messages_sent",
                                      "messages_lost", "messages_duplicated", "messages_reordered",
                                      "qp_sparse_timeouts"};
  MissionOutput out = metrics_.finish(gestures, sim_time_s, wall_time_s);
  if (approach_) out.metrics.worker_approach = approach_->summary();
  if (abort_) out.metrics.abort = abort_->summary();
  out.modes = modes_;  // from the plans' mode fields (the planners' hold decisions)
  const bool ok = writeMissionFiles(dir, out, n_, true, error);
  if (const auto& left = metrics_.unmatchedOutcomes(); !left.empty() && warning != nullptr) {
    *warning = std::to_string(left.size()) + " command outcome(s) matched no request (e.g. " + left.front().source +
               " at " + std::to_string(left.front().issued_s) + " s)";
  }
  return ok;
}

}  // namespace gesture_formation::sim

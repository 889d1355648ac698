#include "gesture_formation/planning/plan_request_builder.hpp"

namespace gesture_formation::planning {

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
  const bool hold = in.hold_reference != nullptr;
  const bool has_leader_plan = i != 0 && in.leader_plan != nullptr && !in.leader_plan->empty();
  if (hold) {
    req.reference = *in.hold_reference;
    if (has_leader_plan) req.higher_priority_plans.push_back(*in.leader_plan);
  } else if (i == 0) {
    formation::leaderHorizon(in.worker, in.params->leader, req.reference);
  } else {
    formation::LeaderPlan lp;
    if (has_leader_plan) {
      lp.heading_rad.resize(1, steps);
      lp.pitch_rad.resize(1, steps);
      for (int k = 0; k < steps; ++k) {
        const auto s = in.leader_plan->sampleAt(in.t_s + k * in.dt_s);
        lp.heading_rad(k) = s.heading_rad;
        lp.pitch_rad(k) = s.pitch_rad;
      }
    }
    formation::followerHorizon(in.worker, in.params->leader, has_leader_plan ? &lp : nullptr,
                               in.params->followers[static_cast<std::size_t>(i - 1)], req.reference);
    if (has_leader_plan) req.higher_priority_plans.push_back(*in.leader_plan);
  }
  if (in.received == nullptr) return req;
  for (int j = 1; j < static_cast<int>(in.received->size()); ++j) {
    const auto& m = (*in.received)[static_cast<std::size_t>(j)];
    if (j == i || !m || m->plan.empty()) continue;
    // A UAV not heard from for max_plan_age_s (dropout, outage, lost link) cannot be expected
    // to dodge: it has right of way, like one that fell back.
    const bool silent = in.t_s - m->plan.t0_s > in.rule.max_plan_age_s;
    if (hold || j < i || m->fallback || silent || in.rule.avoid_all_plans) req.higher_priority_plans.push_back(m->plan);
  }
  return req;
}

}  // namespace gesture_formation::planning

#include "gesture_formation/onboard/setpoint_relay.hpp"

#include <cmath>
#include <sstream>

#include "gesture_formation/common/angles.hpp"

namespace gesture_formation::onboard {

const char* toString(SetpointOutputs outputs) {
  switch (outputs) {
    case SetpointOutputs::kPosition: return "position";
    case SetpointOutputs::kVelocity: return "velocity";
    case SetpointOutputs::kBoth: return "both";
  }
  return "unknown";
}

common::Result<SetpointOutputs> parseSetpointOutputs(const std::string& name) {
  using R = common::Result<SetpointOutputs>;
  for (const auto o : {SetpointOutputs::kPosition, SetpointOutputs::kVelocity, SetpointOutputs::kBoth}) {
    if (name == toString(o)) return R::ok(o);
  }
  return R::fail("setpoints '" + name + "': expected position | velocity | both");
}

std::vector<std::string> RelayConfig::validate() const {
  std::vector<std::string> problems;
  if (!kRateHz.contains(rate_hz)) {
    std::ostringstream os;
    os << "rate_hz: value " << rate_hz << " out of range " << kRateHz.describe();
    problems.push_back(os.str());
  }
  return problems;
}

const char* toString(RelayMode mode) {
  switch (mode) {
    case RelayMode::kNoPlan: return "no_plan";
    case RelayMode::kTracking: return "tracking";
    case RelayMode::kHoldingEnd: return "holding_end";
  }
  return "unknown";
}

std::optional<std::string> SetpointRelay::accept(planning::PlannedTrajectory plan, double t_now_s) {
  if (plan.samples.empty()) return std::string("plan: no samples");
  if (!std::isfinite(plan.t0_s)) return std::string("plan t0: not finite");
  if (!(plan.dt_s > 0.0) || !std::isfinite(plan.dt_s)) {
    return "plan dt_s: " + std::to_string(plan.dt_s) + " (must be > 0)";
  }
  for (std::size_t k = 0; k < plan.samples.size(); ++k) {
    const planning::TrajectorySample& s = plan.samples[k];
    if (!s.p_world.allFinite() || !s.v_world.allFinite() || !std::isfinite(s.heading_rad) || !std::isfinite(s.pitch_rad)) {
      return "plan sample " + std::to_string(k) + ": not finite";
    }
  }
  // A plan from the future (another timeline: queued before ROS time went back) is not flown.
  if (plan.t0_s > t_now_s + kClockBackS) {
    std::ostringstream os;
    os << "plan t0 " << plan.t0_s << " s: more than " << kClockBackS << " s after now (" << t_now_s << " s)";
    return os.str();
  }
  if (plan_ && !heldPlanAhead(t_now_s)) {
    const bool newer = plan.t0_s > plan_->t0_s || (plan.t0_s == plan_->t0_s && plan.sequence > plan_->sequence);
    if (!newer) {
      std::ostringstream os;
      os << "plan t0 " << plan.t0_s << " s (sequence " << plan.sequence << "): not newer than the held plan's "
         << plan_->t0_s << " s (sequence " << plan_->sequence << ")";
      return os.str();
    }
  }
  plan_ = std::move(plan);
  return std::nullopt;
}

std::optional<Setpoint> SetpointRelay::sample(double t_s) const {
  if (!plan_) return std::nullopt;
  const planning::TrajectorySample s = plan_->sampleAt(t_s);  // the tracker's interpolation; past the end: hold
  Setpoint out;
  out.t_s = t_s;
  out.p_world = s.p_world;
  out.v_world = s.v_world;
  out.heading_rad = s.heading_rad;
  out.pitch_rad = s.pitch_rad;
  const double t_end = plan_->tEnd();
  if (t_s >= t_end) {  // the last point, held: zero velocity (sampleAt's too, for more than one sample)
    out.mode = RelayMode::kHoldingEnd;
    out.past_end_s = t_s - t_end;
    out.v_world.setZero();
    return out;
  }
  out.mode = RelayMode::kTracking;
  if (plan_->samples.size() > 1) {
    // The segment sampleAt interpolates in (before t0: the first one).
    const double s_index = std::max(0.0, (t_s - plan_->t0_s) / plan_->dt_s);
    const auto k = std::min(static_cast<std::size_t>(std::floor(s_index)), plan_->samples.size() - 2);
    const double dh = common::wrapAngle(plan_->samples[k + 1].heading_rad - plan_->samples[k].heading_rad);
    out.yaw_rate_radps = dh / plan_->dt_s;
  }
  return out;
}

double SetpointRelay::planT0() const { return plan_ ? plan_->t0_s : std::nan(""); }

}  // namespace gesture_formation::onboard

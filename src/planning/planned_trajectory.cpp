#include <algorithm>
#include <cmath>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/planning/planned_trajectory.hpp"
#include "gesture_formation/planning/uav_planner.hpp"

namespace gesture_formation::planning {

const char* toString(PlanStatus status) {
  switch (status) {
    case PlanStatus::kOptimized: return "optimized";
    case PlanStatus::kFallbackPrevious: return "fallback_previous";
    case PlanStatus::kFallbackBrake: return "fallback_brake";
  }
  return "unknown";
}

TrajectorySample PlannedTrajectory::sampleAt(double t_s) const {
  if (samples.empty()) return TrajectorySample{};
  if (samples.size() == 1 || !(t_s > t0_s) || !(dt_s > 0.0)) return samples.front();
  const double s = (t_s - t0_s) / dt_s;
  const auto last = samples.size() - 1;
  if (s >= static_cast<double>(last)) {
    TrajectorySample end = samples.back();
    end.v_world.setZero();
    end.a_world.setZero();
    return end;
  }
  const auto k = static_cast<std::size_t>(std::floor(s));
  const double w = s - static_cast<double>(k);
  const TrajectorySample& a = samples[k];
  const TrajectorySample& b = samples[k + 1];
  TrajectorySample out;
  out.p_world = (1.0 - w) * a.p_world + w * b.p_world;
  out.v_world = (1.0 - w) * a.v_world + w * b.v_world;
  out.a_world = (1.0 - w) * a.a_world + w * b.a_world;
  out.heading_rad = common::wrapAngle(a.heading_rad + w * common::wrapAngle(b.heading_rad - a.heading_rad));
  out.pitch_rad = (1.0 - w) * a.pitch_rad + w * b.pitch_rad;
  return out;
}

UavKinematicState PlannedTrajectory::stateAt(double t_s) const {
  const TrajectorySample s = sampleAt(t_s);
  UavKinematicState out;
  out.t_s = t_s;
  out.p_world = s.p_world;
  out.v_world = s.v_world;
  out.a_world = s.a_world;
  out.heading_rad = s.heading_rad;
  out.pitch_rad = s.pitch_rad;
  return out;
}

}  // namespace gesture_formation::planning

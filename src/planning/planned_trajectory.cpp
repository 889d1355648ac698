#include <algorithm>
#include <cmath>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/planning/planned_trajectory.hpp"
#include "gesture_formation/planning/trajectory_verifier.hpp"
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
  // Position, velocity and acceleration on the cubic Hermite curve through the samples — the
  // curve the verifier checks and the other UAVs assume (evaluateTrajectory), and exactly the
  // QP's constant-jerk trajectory (docs/planning.md §6.1). Linear interpolation of the position
  // (before) cut the corners of what had been verified by up to ~a·dt²/8 (1.5 cm at 3 m/s² and
  // dt 0.2 s, four times that at dt 0.4 s).
  const TrajectoryPoint x = evaluateTrajectory(*this, t_s);
  TrajectorySample out;
  out.p_world = x.p;
  out.v_world = x.v;
  out.a_world = x.a;
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

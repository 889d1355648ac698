#include "gesture_formation/planning/worker_reach.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "gesture_formation/common/format_number.hpp"
#include "gesture_formation/planning/replan_step.hpp"

namespace gesture_formation::planning {

WorkerReach workerReach(const Eigen::Vector3d& centre_world, double age_s, const ReachConfig& config) {
  WorkerReach r;
  r.centre_world = centre_world;
  r.age_s = std::isfinite(age_s) && age_s >= 0.0 ? age_s : std::numeric_limits<double>::infinity();
  const double grown = config.base_m + config.walking_speed_mps * r.age_s;  // inf · 0 is NaN: no growth
  const double radius = config.walking_speed_mps > 0.0 ? grown : config.base_m;
  r.capped = !(radius < config.max_radius_m);
  r.radius_m = r.capped ? config.max_radius_m : radius;
  return r;
}

bool reachTooClose(const WorkerReach& reach, const Eigen::Vector3d& p_world, const ReachConfig& config) {
  return reach.distanceTo(p_world) < config.worker_min_distance_m + config.margin_m;
}

common::Result<Eigen::Vector3d> chooseBackoffGoal(int uav_index, int uav_count, const Eigen::Vector3d& p_uav_world,
                                                  const WorkerReach& reach, const RetreatSpace& space,
                                                  const AbortConfig& abort, const ReachConfig& config) {
  AbortConfig c = abort;
  c.retreat_distance_m = config.max_radius_m + config.worker_min_distance_m + config.margin_m;
  // The rings of every UAV up to the abort's farthest, and at least two rings of this UAV's.
  c.max_distance_m = std::max(abort.max_distance_m, c.retreat_distance_m + (uav_index + 2 * std::max(1, uav_count)) *
                                                                               abort.layer_spacing_m);
  return chooseRetreatGoal(uav_index, uav_count, p_uav_world, reach.centre_world, space, c);
}

void ReachKeeper::observe(const WorkerKnowledge& w) {
  if (!std::isfinite(w.fused_s)) return;
  if (centre_ && !(centre_fused_s_ == w.fused_s)) release();  // seen again: a new reach, a new back-off
  if (!w.lost && std::isfinite(w.stamp_s)) {
    // Constant velocity since the last fused measurement: take the estimate back to it.
    centre_ = Eigen::Vector3d(w.p_world - w.v_world * std::max(0.0, w.stamp_s - w.fused_s));
    centre_fused_s_ = w.fused_s;
  } else if (!(centre_fused_s_ == w.fused_s)) {
    centre_ = w.p_world;  // lost before this UAV knew the fused position: the held estimate
    centre_fused_s_ = w.fused_s;
  }
}

ReachKeeper::Decision ReachKeeper::decide(const Situation& s) {
  Decision d;
  if (!centre_) return d;
  d.reach = workerReach(*centre_, s.t_s - centre_fused_s_, config_);
  if (!goal_ && !failed_ && (reachTooClose(d.reach, s.p_world, config_) || reachTooClose(d.reach, s.hold_world, config_))) {
    const auto g = chooseBackoffGoal(uav_index_, uav_count_, s.p_world, d.reach, space_, abort_, config_);
    d.started = true;
    if (g) {
      goal_ = *g;
    } else {
      failed_ = true;
      fail_reason_ = g.reason();
    }
  }
  std::ostringstream os;
  if (goal_) {
    os << "backing off from the worker's reach (" << common::formatNumber(d.reach.radius_m) << " m around ("
       << common::formatNumber(d.reach.centre_world.x()) << ", " << common::formatNumber(d.reach.centre_world.y())
       << ", " << common::formatNumber(d.reach.centre_world.z()) << ")) to (" << common::formatNumber(goal_->x())
       << ", " << common::formatNumber(goal_->y()) << ", " << common::formatNumber(goal_->z()) << ")";
  } else if (failed_) {
    os << "no back-off goal from the worker's reach: " << fail_reason_;
  }
  d.goal = goal_;
  d.reason = os.str();
  return d;
}

}  // namespace gesture_formation::planning

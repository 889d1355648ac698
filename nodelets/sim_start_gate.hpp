#pragma once
// SimWorld's start: sim time starts once every UAV's planner is up (it advertises its plan after
// loading the map), so that no UAV misses the mission's start; after kMaxWaitS of wall time it
// starts anyway (with a warning). Thread safety: none (SimWorld's lock).
#include <vector>

#include <ros/ros.h>

namespace gesture_formation::nodelets {

class SimStartGate {
 public:
  static constexpr double kMaxWaitS = 120.0;  ///< [s] of wall time

  /// Waiting starts now.
  void arm() { wall0_ = ros::WallTime::now(); }
  /// True once started: now, when every subscriber in `plan_subs` has a publisher (or after kMaxWaitS).
  bool open(const std::vector<ros::Subscriber>& plan_subs) {
    if (started_) return true;
    bool all = true;
    for (const auto& sub : plan_subs) all = all && sub.getNumPublishers() > 0;
    const double waited = (ros::WallTime::now() - wall0_).toSec();
    if (!all && waited < kMaxWaitS) return false;
    if (!all) ROS_WARN("SimWorld: not every UAV planner is up after 120 s; starting anyway");
    ROS_INFO_STREAM("SimWorld: every UAV is up after " << waited << " s wall; sim time starts");
    started_ = true;
    wall0_ = ros::WallTime::now();
    return true;
  }
  bool started() const { return started_; }
  /// Wall time since the start (since arm() before it).
  double wallSinceStart() const { return (ros::WallTime::now() - wall0_).toSec(); }

 private:
  bool started_ = false;
  ros::WallTime wall0_;
};

}  // namespace gesture_formation::nodelets

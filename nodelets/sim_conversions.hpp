#pragma once
// Message ↔ simulator-core conversions: used by the simulation nodelets only (SimUav, SimWorld);
// the nodelets that fly never include the simulator (docs/architecture.md).
#include <nav_msgs/Odometry.h>

#include "conversions.hpp"
#include "gesture_formation/sim/multirotor.hpp"

namespace gesture_formation::nodelets {

/// A true state (ground truth odometry) as the sim core's plant state: position, velocity,
/// camera heading and pitch.
inline sim::MultirotorState toMultirotorState(const nav_msgs::Odometry& odom) {
  const planning::UavKinematicState k = toKinematicState(odom);
  sim::MultirotorState s;
  s.p_world = k.p_world;
  s.v_world = k.v_world;
  s.heading_rad = k.heading_rad;
  s.pitch_rad = k.pitch_rad;
  return s;
}

}  // namespace gesture_formation::nodelets

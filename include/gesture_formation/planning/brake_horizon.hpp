#pragma once
/// \file
/// \brief The rule between the planning horizon and the dynamic limits: a braking plan
/// (UavPlanner's brake fallback, planning::brakeProfile) must come to rest inside the horizon,
/// else its last sample still moves and the relay, holding that sample with zero velocity once the
/// plan ends (onboard::SetpointRelay), asks the flight stack for a stop it cannot make — an
/// overshoot into space nothing verified (docs/planning.md §8).

#include <string>
#include <vector>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/planning/planner_config.hpp"

namespace gesture_formation::planning {

/// \brief The longest braking time from any velocity the limits allow, as brakeProfile brakes
/// (along −v at the largest deceleration ‖a‖ ≤ max_acceleration, |a_z| ≤ max_vertical_acceleration):
/// max(max_speed / max_acceleration, max_vertical_speed / max_vertical_acceleration) [s].
double longestBrakeS(const DynamicLimits& limits);

/// \brief Problems (keyed `horizon_steps`, with the numbers) when the horizon, (steps − 1)·dt_s,
/// is shorter than the longest braking time rounded up to a sample (brakeProfile's stop falls on
/// a sample); empty when it fits. `prefix` goes before the key.
std::vector<common::ConfigError> brakeHorizonProblems(const DynamicLimits& limits, double dt_s, int steps,
                                                      const std::string& prefix);

}  // namespace gesture_formation::planning

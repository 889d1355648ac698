#pragma once
/// \file
/// \brief The relay from the FormationPlanner's plan to the flight stack (docs/ros.md, "Flight
/// stacks"): the newest plan sampled at the tracker's rate into a setpoint — position, velocity,
/// heading and its rate, camera pitch — as the flight stack's position/velocity controller and
/// the gimbal take it.
///
/// Which plan is flown is the planner's decision: every plan it publishes (its verified plan, or
/// its fallback — previous plan or brake — flagged `fallback`) is the one to fly, as the other
/// UAVs avoid exactly that plan (docs/safety.md §1 rules 1, 5).
/// No plan yet: no setpoint (the flight stack stays in its own mode; MAVROS/PX4 does not enter
/// offboard without a setpoint stream). A plan past its end (older than its horizon: the planner
/// stopped): the plan's last point with zero velocity, held — rule 5, what the simulated tracker
/// does (`PlannedTrajectory::sampleAt`), and where the other UAVs expect this one to be.

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/result.hpp"
#include "gesture_formation/planning/planned_trajectory.hpp"

namespace gesture_formation::onboard {

/// \brief Which setpoints the relay publishes: MAVROS sends each as its own
/// SET_POSITION_TARGET_LOCAL_NED, so give it one of position or velocity (docs/ros.md).
enum class SetpointOutputs { kPosition, kVelocity, kBoth };
const char* toString(SetpointOutputs outputs);
/// \brief "position" | "velocity" | "both"; fails naming the value.
common::Result<SetpointOutputs> parseSetpointOutputs(const std::string& name);

/// \brief The relay's settings.
struct RelayConfig {
  static inline const common::Range kRateHz = common::Range::closed(1.0, 500.0);
  double rate_hz = 100.0;  ///< setpoints per second (the flight stack's tracker rate; PX4 offboard needs > 2 Hz), [1, 500]
  SetpointOutputs outputs = SetpointOutputs::kPosition;
  /// \brief Every problem, each naming its field and value; empty when valid.
  std::vector<std::string> validate() const;
};

/// \brief What the relay does at one instant.
enum class RelayMode { kNoPlan, kTracking, kHoldingEnd };
const char* toString(RelayMode mode);

/// \brief One setpoint (world ENU, SI units).
struct Setpoint {
  double t_s = 0.0;
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();
  double heading_rad = 0.0;     ///< camera heading φ = the body's yaw (the camera turns with the body)
  double yaw_rate_radps = 0.0;  ///< dφ/dt of the plan's segment at t_s (0 while holding the end)
  double pitch_rad = 0.0;       ///< camera pitch ξ, positive up (the gimbal's)
  RelayMode mode = RelayMode::kTracking;
  double past_end_s = 0.0;      ///< how long ago the plan ended (0 while tracking)
};

/// \brief Holds the newest plan and samples it. Thread safety: none (the nodelet locks).
class SetpointRelay {
 public:
  /// \brief Takes `plan` when it is usable and newer than the one held (by t0_s; an equal t0_s
  /// with a higher sequence also replaces); else the reason, naming the field and value, and the
  /// held plan is kept. A held plan whose t0_s is more than kClockBackS after `t_now_s` (ROS time
  /// went back: the simulation restarted, a bag looped) is replaced by any usable plan — else
  /// every new plan would be refused as older until the clock caught up, the UAV holding the old
  /// plan's end; and a plan whose t0_s is more than kClockBackS after `t_now_s` is refused (one of
  /// the old timeline still queued). NaN `t_now_s`: neither check.
  std::optional<std::string> accept(planning::PlannedTrajectory plan,
                                    double t_now_s = std::numeric_limits<double>::quiet_NaN());
  static constexpr double kClockBackS = 1.0;
  /// \brief The setpoint at `t_s`; nullopt without a plan.
  std::optional<Setpoint> sample(double t_s) const;
  bool hasPlan() const { return plan_.has_value(); }
  /// \brief The held plan starts more than kClockBackS after `t_s`: ROS time went back (the next
  /// usable plan replaces it, see accept). False without a plan or for a NaN `t_s`.
  bool heldPlanAhead(double t_s) const { return plan_ && plan_->t0_s > t_s + kClockBackS; }
  /// \brief The held plan's t0_s (NaN without one).
  double planT0() const;

 private:
  std::optional<planning::PlannedTrajectory> plan_;
};

}  // namespace gesture_formation::onboard

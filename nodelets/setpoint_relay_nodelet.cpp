// SetpointRelay nodelet: the FormationPlanner's plan → the flight stack's setpoints (docs/ros.md,
// "Flight stacks"). A thin adapter over onboard::SetpointRelay: the newest plan sampled at
// rate_hz on ROS time; no plan yet: nothing is published; a plan past its end: its last point,
// held with zero velocity (docs/safety.md §1 rule 5).
//
// Topics: plan_in (gesture_formation/PlannedTrajectory: this UAV's FormationPlanner `plan`)
//   → pose_out (geometry_msgs/PoseStamped: MAVROS setpoint_position/local),
//     twist_out (geometry_msgs/TwistStamped: MAVROS setpoint_velocity/cmd_vel, angular.z = yaw rate),
//     gimbal_out (geometry_msgs/Vector3Stamped: y = camera pitch ξ rad positive up, z = camera
//     heading φ rad ENU, x = 0; stamped, in world_frame), /diagnostics.
// Parameters (required): ~uav_index (a plan of another UAV is refused), ~world_frame (a plan in
//   another frame is refused, naming both), ~rate_hz [1, 500], ~setpoints (position | velocity | both).
#include <mutex>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "diagnostics.hpp"
#include "flight_stack_conversions.hpp"
#include "gesture_formation/onboard/frame_check.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class SetpointRelayNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ParamLoader params(getPrivateNodeHandle());
    params.load("uav_index", uav_index_, 0, comm::kMaxUavIndex);
    params.load("world_frame", world_frame_);
    params.load("rate_hz", config_.rate_hz);  // its range: RelayConfig::validate() below
    std::string outputs;
    params.load("setpoints", outputs);
    if (!outputs.empty()) {
      const auto o = onboard::parseSetpointOutputs(outputs);
      if (o) config_.outputs = *o;
      else params.addError(o.reason());
    }
    if (world_frame_.empty()) params.addError("world_frame: must be non-empty");
    params.addErrors(config_.validate());
    if (!params.ok()) {
      NODELET_ERROR_STREAM("SetpointRelay refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("SetpointRelay loaded:\n" << params.loaded());
    const bool position = config_.outputs != onboard::SetpointOutputs::kVelocity;
    const bool velocity = config_.outputs != onboard::SetpointOutputs::kPosition;
    if (position) pose_pub_ = nh.advertise<geometry_msgs::PoseStamped>("pose_out", 10);
    if (velocity) twist_pub_ = nh.advertise<geometry_msgs::TwistStamped>("twist_out", 10);
    gimbal_pub_ = nh.advertise<geometry_msgs::Vector3Stamped>("gimbal_out", 10);
    plan_sub_ = nh.subscribe("plan_in", 5, &SetpointRelayNodelet::onPlan, this);
    timer_ = nh.createTimer(ros::Duration(1.0 / config_.rate_hz), &SetpointRelayNodelet::onTimer, this);
    diagnostics_.start(nh, 1.0, [this](double since_s) { return health(since_s); });
  }

  void onPlan(const gesture_formation::PlannedTrajectory::ConstPtr& msg) {
    std::optional<std::string> refusal = onboard::checkFrame("plan_in header.frame_id", world_frame_, msg->header.frame_id);
    if (!refusal && msg->uav_index != uav_index_) {
      refusal = "plan_in uav_index: expected " + std::to_string(uav_index_) + ", received " + std::to_string(msg->uav_index);
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (!refusal) {
      auto plan = fromMsg(*msg);
      const double now = ros::Time::now().toSec();
      const bool held_ahead = relay_.heldPlanAhead(now);
      const double held_t0 = relay_.planT0();
      refusal = plan ? relay_.accept(std::move(*plan), now) : std::optional<std::string>(plan.reason());
      if (!refusal && held_ahead) {
        NODELET_WARN_STREAM("SetpointRelay: ROS time went back (held plan from " << held_t0 << " s, now " << now
                                                                                 << " s): the new plan replaced it");
      }
    }
    if (refusal) {
      ++refused_;
      last_refusal_ = *refusal;
      NODELET_ERROR_STREAM_THROTTLE(2.0, "SetpointRelay: plan refused (nothing from it is used): " << *refusal);
      return;
    }
    ++plans_since_report_;
  }

  void onTimer(const ros::TimerEvent&) {
    std::lock_guard<std::mutex> lock(mutex_);
    const double t = ros::Time::now().toSec();
    const auto s = relay_.sample(t);
    mode_ = s ? s->mode : onboard::RelayMode::kNoPlan;
    if (!s) return;  // no plan yet: nothing to fly
    past_end_s_ = s->past_end_s;
    if (pose_pub_) pose_pub_.publish(toPoseSetpoint(*s, world_frame_));
    if (twist_pub_) twist_pub_.publish(toTwistSetpoint(*s, world_frame_));
    gimbal_pub_.publish(toGimbalSetpoint(*s, world_frame_));
    ++setpoints_since_report_;
  }

  /// The relay on /diagnostics: WARN without a plan, while holding a plan's end, or when plans
  /// were refused since the last report.
  std::vector<diagnostic_msgs::DiagnosticStatus> health(double since_s) {
    std::lock_guard<std::mutex> lock(mutex_);
    const double t = ros::Time::now().toSec();
    Health h("SetpointRelay uav" + std::to_string(uav_index_), "uav" + std::to_string(uav_index_));
    h.warn(mode_ == onboard::RelayMode::kNoPlan, "no plan yet: no setpoints")
        .warn(mode_ == onboard::RelayMode::kHoldingEnd,
              "plan ended " + std::to_string(past_end_s_) + " s ago: holding its last point")
        .warn(refused_ > refused_reported_, std::to_string(refused_ - refused_reported_) + " plan(s) refused: " + last_refusal_)
        .value("mode", std::string(onboard::toString(mode_)))
        .value("setpoints", std::string(onboard::toString(config_.outputs)))
        .value("setpoints_per_s", setpoints_since_report_ / since_s)
        .value("plans_per_s", plans_since_report_ / since_s)
        .value("plans_refused", refused_)
        .value("plan_age_s", relay_.hasPlan() ? t - relay_.planT0() : -1.0)
        .value("past_end_s", mode_ == onboard::RelayMode::kHoldingEnd ? past_end_s_ : 0.0);
    refused_reported_ = refused_;
    setpoints_since_report_ = plans_since_report_ = 0;
    return {h.status()};
  }

  std::mutex mutex_;
  onboard::RelayConfig config_;
  onboard::SetpointRelay relay_;
  int uav_index_ = 0;
  std::string world_frame_;
  onboard::RelayMode mode_ = onboard::RelayMode::kNoPlan;
  double past_end_s_ = 0.0;
  int setpoints_since_report_ = 0, plans_since_report_ = 0;
  std::uint64_t refused_ = 0, refused_reported_ = 0;
  std::string last_refusal_;
  DiagnosticsPublisher diagnostics_;
  ros::Publisher pose_pub_, twist_pub_, gimbal_pub_;
  ros::Subscriber plan_sub_;
  ros::Timer timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::SetpointRelayNodelet, nodelet::Nodelet)

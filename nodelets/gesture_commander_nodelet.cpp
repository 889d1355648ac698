// GestureCommander nodelet: classifier outputs → gesture::GestureFilter (K, t_c, Π_d, t_d) →
// gesture::GestureMapping → formation commands (DESIGN §2, §8.3; docs/formation.md §6–7).
// A thin adapter: the filter decides, the mapping translates, the leader's FormationPlanner
// applies (and clamps) the command.
//
// Topics: gesture_in (gesture_formation/Gesture) → formation_command_out (FormationCommand),
//   gesture_status_out (GestureStatus, one per classifier output).
// Parameters (required): ~gesture_config (config/gestures.yaml) or ~mission_file (a scenario's
//   mission.gestures), ~uav_count, ~sender_name. Command sequence numbers start at the wall
//   clock in microseconds, so a restarted commander is never taken for a duplicate.
#include <mutex>
#include <optional>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "config_sources.hpp"
#include "conversions.hpp"
#include "gesture_formation/Gesture.h"
#include "gesture_formation/GestureStatus.h"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class GestureCommanderNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ParamLoader params(getPrivateNodeHandle());
    std::string gesture_file, mission_file;
    int uav_count = 0;
    params.load("uav_count", uav_count, 1, comm::kMaxUavIndex + 1);
    params.load("sender_name", sender_);
    params.loadOptional("mission_file", mission_file, "");
    gesture::GestureFilterConfig fcfg;
    if (!mission_file.empty()) {
      sim::MissionConfig mission;
      if (loadMission(mission_file, params, mission)) {
        fcfg = mission.gesture_filter;
        mapping_ = mission.gesture_mapping;
      }
    } else {
      params.load("gesture_config", gesture_file);
      if (!gesture_file.empty() && uav_count >= 1) loadGestures(gesture_file, uav_count - 1, params, fcfg, mapping_);
    }
    if (sender_.empty() || sender_.find(' ') != std::string::npos) params.addError("sender_name: must be non-empty without spaces");
    if (!params.ok()) {
      NODELET_ERROR_STREAM("GestureCommander refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("GestureCommander loaded:\n" << params.loaded());
    filter_.emplace(fcfg);
    sequence_ = static_cast<std::uint64_t>(ros::WallTime::now().toNSec() / 1000);
    command_pub_ = nh.advertise<gesture_formation::FormationCommand>("formation_command_out", 10);
    status_pub_ = nh.advertise<gesture_formation::GestureStatus>("gesture_status_out", 10);
    gesture_sub_ = nh.subscribe("gesture_in", 50, &GestureCommanderNodelet::onGesture, this);
  }

  void onGesture(const gesture_formation::Gesture::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto out = filter_->update(msg->header.stamp.toSec(), msg->gesture_id);
    gesture_formation::GestureStatus st;
    st.header = msg->header;
    st.gesture_id = msg->gesture_id;
    st.dominant_id = out.dominant_id;
    st.dominant_ratio = out.dominant_ratio;
    st.window_count = static_cast<std::uint32_t>(out.window_count);
    st.verdict = gesture::toString(out.verdict);
    st.fired = out.fired;
    if (!out.accepted) NODELET_WARN_STREAM_THROTTLE(1.0, "GestureCommander: measurement rejected: " << out.reason);
    if (out.fired) {
      const gesture::GestureAction* action = mapping_.find(out.dominant_id);
      if (action == nullptr) {
        last_fired_ = "gesture " + std::to_string(out.dominant_id) + ": unmapped";
      } else if (action->kind == gesture::GestureAction::Kind::kEvent) {
        last_fired_ = "gesture " + std::to_string(out.dominant_id) + ": event " + gesture::toString(action->event);
      } else {
        auto cmd = toMsg(gesture::toCommand(*action, ++sequence_));
        cmd.sender = sender_;
        cmd.header.stamp = msg->header.stamp;
        command_pub_.publish(cmd);
        last_fired_ = "gesture " + std::to_string(out.dominant_id) + ": " + action->parameter_path + " " +
                      (action->increment >= 0 ? "+" : "") + std::to_string(action->increment);
      }
      NODELET_INFO_STREAM("GestureCommander: fired " << last_fired_);
    }
    st.last_fired = last_fired_;
    status_pub_.publish(st);
  }

  std::mutex mutex_;
  std::string sender_;
  std::optional<gesture::GestureFilter> filter_;
  gesture::GestureMapping mapping_;
  std::uint64_t sequence_ = 0;
  std::string last_fired_;
  ros::Publisher command_pub_, status_pub_;
  ros::Subscriber gesture_sub_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::GestureCommanderNodelet, nodelet::Nodelet)

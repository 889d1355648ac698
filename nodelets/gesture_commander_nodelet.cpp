// GestureCommander nodelet (the leader): every UAV's classification of a camera frame →
// gesture::ViewFusion (the formation's cameras vote, docs/gestures.md §4.1) → gesture::GestureFilter
// (K, t_c, Π_d, t_d) → gesture::GestureMapping → formation commands (docs/design.md §2, §8.3;
// docs/formation.md §6–7). A thin adapter: the vote and the filter decide, the mapping
// translates, the leader's FormationPlanner applies (and clamps) the command.
//
// Frames: observations are grouped by their stamp (the frame's time). A frame is fused and given
// to the filter once every view has reported it, or ~frame_wait_s after its stamp (a view that
// did not classify it, or an offline follower) — view_fusion.fusion_lag_s after it when that is
// longer (a delayed link: the views are compared at the frame's time, docs/gestures.md §4.1);
// a frame none of whose observations was accepted
// is not given to the filter (as `gfctl simulate`). With view_fusion.min_agreeing_views 1 the
// leader's own classification goes to the filter unchanged (the paper's single camera) and the
// followers' observations are ignored.
//
// Topics: observation_in (GestureObservation: the leader's own ViewObserver), peer_observations_in
//   (GestureObservation: the followers', from the LcmBridge) → formation_command_out
//   (FormationCommand), gesture_status_out (GestureStatus, one per fused frame).
// Parameters (required): ~gesture_config (config/gestures.yaml: filter, mapping, view_fusion.*)
//   or ~mission_file (a scenario's mission.gestures), ~uav_count, ~sender_name, ~frame_wait_s.
//   Command sequence numbers start at the wall clock in microseconds, so a restarted commander
//   is never taken for a duplicate.
#include <algorithm>
#include <map>
#include <mutex>
#include <optional>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "config_sources.hpp"
#include "conversions.hpp"
#include "gesture_formation/GestureObservation.h"
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
    params.load("frame_wait_s", frame_wait_s_, 0.0, 1.0);
    params.loadOptional("mission_file", mission_file, "");
    gesture::GestureFilterConfig fcfg;
    gesture::ViewFusionConfig vcfg;
    if (!mission_file.empty()) {
      sim::MissionConfig mission;
      if (loadMission(mission_file, params, mission)) {
        fcfg = mission.gesture_filter;
        mapping_ = mission.gesture_mapping;
        vcfg = mission.view_fusion;
        if (mission.formation.params.uavCount() != uav_count) {
          params.addError("uav_count: " + std::to_string(uav_count) + " but the mission has " +
                          std::to_string(mission.formation.params.uavCount()) + " UAVs");
        }
      }
    } else {
      params.load("gesture_config", gesture_file);
      if (!gesture_file.empty() && uav_count >= 1) loadGestures(gesture_file, uav_count - 1, params, fcfg, mapping_, vcfg);
    }
    if (sender_.empty() || sender_.find(' ') != std::string::npos) params.addError("sender_name: must be non-empty without spaces");
    if (params.ok() && frame_wait_s_ >= vcfg.max_age_s) {
      params.addError("frame_wait_s: value " + std::to_string(frame_wait_s_) +
                      " must be below view_fusion.max_age_s " + std::to_string(vcfg.max_age_s));
    }
    if (!params.ok()) {
      NODELET_ERROR_STREAM("GestureCommander refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    views_ = vcfg.min_agreeing_views > 1 ? uav_count : 1;
    close_after_s_ = std::max(frame_wait_s_, views_ > 1 ? vcfg.fusion_lag_s : 0.0);
    NODELET_INFO_STREAM("GestureCommander loaded:\n"
                        << params.loaded() << "  view_fusion: " << views_ << " camera(s), min_agreeing_views "
                        << vcfg.min_agreeing_views << ", max_age_s " << vcfg.max_age_s << ", envelope "
                        << (vcfg.gate_envelope ? "on" : "off") << " [" << vcfg.distance_min_m << ", "
                        << vcfg.distance_max_m << "] m, [" << vcfg.elevation_min_deg << ", " << vcfg.elevation_max_deg
                        << "] deg, confirm_3d " << (vcfg.confirm_3d ? "on" : "off") << ", frames closed "
                        << close_after_s_ << " s after their stamp\n");
    filter_.emplace(fcfg);
    fusion_.emplace(vcfg, views_, fcfg.max_gesture_id);
    sequence_ = static_cast<std::uint64_t>(ros::WallTime::now().toNSec() / 1000);
    command_pub_ = nh.advertise<gesture_formation::FormationCommand>("formation_command_out", 10);
    status_pub_ = nh.advertise<gesture_formation::GestureStatus>("gesture_status_out", 10);
    own_sub_ = nh.subscribe("observation_in", 50, &GestureCommanderNodelet::onObservation, this);
    peer_sub_ = nh.subscribe("peer_observations_in", 100, &GestureCommanderNodelet::onObservation, this);
    timer_ = nh.createTimer(ros::Duration(0.01), [this](const ros::TimerEvent&) {
      std::lock_guard<std::mutex> lock(mutex_);
      closeFrames(ros::Time::now().toSec() - close_after_s_);
    });
  }

  struct Frame {
    int reported = 0;
    bool accepted = false;
    int own_id = 0;  ///< the leader's classification (single-camera mode)
  };

  void onObservation(const gesture_formation::GestureObservation::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (msg->uav_index >= views_) return;  // single camera: the followers do not vote
    std::string skeleton_problem;
    const gesture::ViewObservation o = toViewObservation(*msg, &skeleton_problem);
    if (!skeleton_problem.empty()) {
      NODELET_WARN_STREAM_THROTTLE(5.0, "GestureCommander: skeleton of UAV " << int(msg->uav_index)
                                            << " left out of the 3-D confirmation: " << skeleton_problem);
    }
    std::string reason;
    const bool accepted = fusion_->observe(o, &reason);
    if (!accepted) {
      NODELET_WARN_STREAM_THROTTLE(1.0, "GestureCommander: observation of UAV " << int(msg->uav_index) << " rejected: " << reason);
    }
    if (o.t_s <= last_closed_s_) return;  // its frame is closed: it votes in the next ones
    Frame& f = pending_[o.t_s];
    ++f.reported;
    f.accepted = f.accepted || accepted;
    if (accepted && o.view == 0) f.own_id = o.gesture_id;
    if (f.reported >= views_) closeFrames(o.t_s);
  }

  /// Fuses and filters every pending frame stamped at or before t_s, in time order.
  void closeFrames(double t_s) {
    while (!pending_.empty() && pending_.begin()->first <= t_s) {
      const double t = pending_.begin()->first;
      const Frame f = pending_.begin()->second;
      pending_.erase(pending_.begin());
      last_closed_s_ = t;
      if (f.accepted) process(t, f);
    }
  }

  void process(double t_s, const Frame& f) {
    gesture::FusedGesture fused;
    if (views_ > 1) {
      fused = fusion_->fuse(t_s);
    } else {
      fused.gesture_id = f.own_id;
      fused.voting_views = fused.agreeing_views = 1;
    }
    const auto out = filter_->update(t_s, fused.gesture_id);
    gesture_formation::GestureStatus st;
    st.header.stamp = ros::Time(t_s);
    st.gesture_id = fused.gesture_id;
    st.dominant_id = out.dominant_id;
    st.dominant_ratio = out.dominant_ratio;
    st.window_count = static_cast<std::uint32_t>(out.window_count);
    st.verdict = gesture::toString(out.verdict);
    st.fired = out.fired;
    st.reported_views = f.reported;
    st.voting_views = fused.voting_views;
    st.agreeing_views = fused.agreeing_views;
    st.confirmed_3d = fused.confirmed_3d;
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
        cmd.header.stamp = st.header.stamp;
        command_pub_.publish(cmd);
        last_fired_ = "gesture " + std::to_string(out.dominant_id) + ": " + action->parameter_path + " " +
                      (action->increment >= 0 ? "+" : "") + std::to_string(action->increment);
      }
      NODELET_INFO_STREAM("GestureCommander: fired " << last_fired_ << " (" << fused.agreeing_views << " of "
                                                     << fused.voting_views << " voting views agreed"
                                                     << (fused.confirmed_3d ? ", confirmed in 3-D" : "") << ")");
    }
    st.last_fired = last_fired_;
    status_pub_.publish(st);
  }

  std::mutex mutex_;
  std::string sender_;
  double frame_wait_s_ = 0.0;
  double close_after_s_ = 0.0;  ///< max(frame_wait_s, view_fusion.fusion_lag_s)
  int views_ = 1;
  std::optional<gesture::GestureFilter> filter_;
  std::optional<gesture::ViewFusion> fusion_;
  gesture::GestureMapping mapping_;
  std::map<double, Frame> pending_;
  double last_closed_s_ = -1e9;
  std::uint64_t sequence_ = 0;
  std::string last_fired_;
  ros::Publisher command_pub_, status_pub_;
  ros::Subscriber own_sub_, peer_sub_;
  ros::Timer timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::GestureCommanderNodelet, nodelet::Nodelet)

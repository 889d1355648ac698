// GestureCommander nodelet (the leader): every UAV's classification of a camera frame →
// gesture::ViewFusion (the formation's cameras vote, docs/gestures.md §4.1) → gesture::GestureFilter
// (K, t_c, Π_d, t_d) → gesture::GestureMapping → formation commands (docs/design.md §2, §8.3;
// docs/formation.md §6–7). A thin adapter: the vote and the filter decide, the mapping
// translates, the leader's FormationPlanner applies (and clamps) the command.
//
// Frames (gesture::GestureFrames, the aggregation gfctl simulate runs too): observations are
// grouped by their stamp (the frame's time); a frame is fused and given to the filter once every
// view has reported it, or max(frame_wait_s, view_fusion.fusion_lag_s) after its stamp; a frame
// none of whose observations was accepted is not given to the filter. With
// view_fusion.min_agreeing_views 1 the leader's own classification goes to the filter unchanged
// (the paper's single camera) and the followers' observations are ignored.
//
// Topics: observation_in (GestureObservation: the leader's own ViewObserver), peer_observations_in
//   (GestureObservation: the followers', from the LcmBridge) → formation_command_out
//   (FormationCommand), abort_out (AbortCommand, source gesture: a fired {event: abort}; to the
//   leader's FormationPlanner), assistance_out (AssistanceState PHASE_REQUESTED: a fired
//   {event: assist_requested}; to the leader's FormationPlanner), gesture_status_out (GestureStatus,
//   one per fused frame).
// Parameters (required): ~gesture_config (config/gestures.yaml: filter, mapping, view_fusion.*)
//   or ~mission_file (a scenario's mission.gestures), ~uav_count, ~sender_name, ~frame_wait_s,
//   ~frame_merge_s (unsynchronised cameras: one observation per view per frame, gesture::GestureFrames).
//   Command sequence numbers start at the sender's boot counter (optional ~sequence_file,
//   command_sequence.hpp), so a restarted commander is never taken for a duplicate nor refused as
//   stale, whatever the clock did.
// Leader hand-over (optional ~leadership, default false; docs/safety.md §1.2): the commander runs on
// every UAV and follows this UAV's leadership_state_in (LeadershipState): only while it acts are
// observations taken and commands sent — and through a lapse of its lease in the term it acts in (the
// FormationPlanner keeps those commands until the lease is back); each time it starts voting the frames
// and the filter start afresh (as gfctl simulate's new leader: no half-seen performance of the
// predecessor's fires).
#include <algorithm>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "config_sources.hpp"
#include "conversions.hpp"
#include "diagnostics.hpp"
#include "gesture_formation/GestureObservation.h"
#include "gesture_formation/GestureStatus.h"
#include "gesture_formation/LeadershipState.h"
#include "gesture_formation/gesture/gesture_frames.hpp"
#include "command_sequence.hpp"
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
    params.load("frame_merge_s", frame_merge_s_, 0.0, 1.0);
    params.loadOptional("mission_file", mission_file, "");
    gesture::GestureFilterConfig fcfg;
    gesture::ViewFusionConfig vcfg;
    gesture::GestureMapping mapping;
    bool gestures_loaded = false;
    if (!mission_file.empty()) {
      onboard::OnboardSettings mission;
      if (loadOnboard(mission_file, params, mission)) {
        gestures_loaded = true;
        fcfg = mission.gesture_filter;
        mapping = mission.gesture_mapping;
        vcfg = mission.view_fusion;
        if (mission.formation.params.uavCount() != uav_count) {
          params.addError("uav_count: " + std::to_string(uav_count) + " but the mission has " +
                          std::to_string(mission.formation.params.uavCount()) + " UAVs");
        }
      }
    } else {
      params.load("gesture_config", gesture_file);
      gestures_loaded = !gesture_file.empty() && uav_count >= 1 &&
                        loadGestures(gesture_file, uav_count - 1, params, fcfg, mapping, vcfg);
    }
    if (sender_.empty() || sender_.find(' ') != std::string::npos) params.addError("sender_name: must be non-empty without spaces");
    if (gestures_loaded && frame_wait_s_ >= vcfg.max_age_s) {
      params.addError("frame_wait_s: value " + std::to_string(frame_wait_s_) +
                      " must be below view_fusion.max_age_s " + std::to_string(vcfg.max_age_s));
    }
    params.loadOptional("leadership", leadership_, false);  // optional (see the file comment); not a bool: refused
    if (params.ok()) sequence_ = commandSequenceStart(params, getPrivateNodeHandle().getNamespace());
    if (!params.ok()) {
      NODELET_ERROR_STREAM("GestureCommander refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    make_frames_ = [=] { frames_.emplace(fcfg, vcfg, mapping, uav_count, frame_wait_s_, frame_merge_s_); };
    make_frames_();
    last_seen_s_.assign(static_cast<std::size_t>(frames_->views()), -1e9);
    NODELET_INFO_STREAM("GestureCommander loaded:\n"
                        << params.loaded() << "  view_fusion: " << frames_->views() << " camera(s), min_agreeing_views "
                        << vcfg.min_agreeing_views << ", max_age_s " << vcfg.max_age_s << ", envelope "
                        << (vcfg.gate_envelope ? "on" : "off") << " [" << vcfg.distance_min_m << ", "
                        << vcfg.distance_max_m << "] m, [" << vcfg.elevation_min_deg << ", " << vcfg.elevation_max_deg
                        << "] deg, confirm_3d " << (vcfg.confirm_3d ? "on" : "off") << ", require_3d "
                        << (vcfg.require_3d ? "on" : "off") << ", frames closed "
                        << frames_->closeAfterS() << " s after their stamp\n");
    command_pub_ = nh.advertise<gesture_formation::FormationCommand>("formation_command_out", 10);
    status_pub_ = nh.advertise<gesture_formation::GestureStatus>("gesture_status_out", 10);
    abort_pub_ = nh.advertise<gesture_formation::AbortCommand>("abort_out", 10);
    assistance_pub_ = nh.advertise<gesture_formation::AssistanceState>("assistance_out", 10);
    own_sub_ = nh.subscribe<gesture_formation::GestureObservation>(
        "observation_in", 50, [this](const gesture_formation::GestureObservation::ConstPtr& m) { onObservation(m, true); });
    peer_sub_ = nh.subscribe<gesture_formation::GestureObservation>(
        "peer_observations_in", 100, [this](const gesture_formation::GestureObservation::ConstPtr& m) { onObservation(m, false); });
    timer_ = nh.createTimer(ros::Duration(0.01), [this](const ros::TimerEvent&) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!acts()) return;
      for (const auto& f : frames_->closeDue(ros::Time::now().toSec())) publishFrame(f);
    });
    if (leadership_) {
      leadership_sub_ = nh.subscribe<gesture_formation::LeadershipState>(
          "leadership_state_in", 5, [this](const gesture_formation::LeadershipState::ConstPtr& m) {
            std::lock_guard<std::mutex> lock(mutex_);
            // It votes while it acts and through a lapse of its lease in the term it acted in (its
            // commands then wait at the FormationPlanner: planner_params_role.hpp).
            const bool votes = m->acting || (m->role == gesture_formation::LeadershipState::ROLE_LEADER && m->term == acted_term_);
            if (m->acting) acted_term_ = m->term;
            if (votes == acting_) return;
            acting_ = votes;
            make_frames_();  // a new leader's vote and filter start afresh,
            // waiting for the gesture in progress to be released (its predecessor may have fired)
            if (acting_) frames_->awaitRelease();
            NODELET_WARN_STREAM("GestureCommander: " << (acting_ ? "acts as leader (term " + std::to_string(m->term) + "): votes from now on"
                                                                 : std::string("no longer the leader of its term: no vote")));
          });
    }
    diagnostics_.start(nh, 1.0, [this](double since_s) { return health(since_s); });
  }

  /// The vote and filter on /diagnostics: WARN when observations were rejected since the last
  /// report or a camera has not reported for 2 s; values: frames, views, what fired last.
  std::vector<diagnostic_msgs::DiagnosticStatus> health(double /*since_s*/) {
    std::lock_guard<std::mutex> lock(mutex_);
    const double t = ros::Time::now().toSec();
    Health h("GestureCommander", "leader");
    if (!acts()) return {h.value("acting", 0).status()};  // ~leadership, not acting: no vote here
    std::string silent;
    for (std::size_t v = 0; v < last_seen_s_.size(); ++v) {
      if (!(t - last_seen_s_[v] <= 2.0)) silent += (silent.empty() ? "" : ", ") + std::to_string(v);
    }
    h.warn(rejected_since_report_ > 0, std::to_string(rejected_since_report_) + " observation(s) rejected")
        .warn(!silent.empty(), "no observation for 2 s from UAV(s) " + silent)
        .value("frames", frames_since_report_)
        .value("observations", observations_since_report_)
        .value("rejected", rejected_since_report_)
        .value("fired", fired_since_report_)
        .value("last_fired", last_fired_.empty() ? std::string("none") : last_fired_);
    frames_since_report_ = observations_since_report_ = rejected_since_report_ = fired_since_report_ = 0;
    return {h.status()};
  }

  bool acts() const { return !leadership_ || acting_; }

  /// `own`: this UAV's camera (observation_in). With one camera voting, that camera is the vote's
  /// view 0 whichever UAV this is — after a hand-over the acting UAV's own camera, not UAV 0's
  /// relayed one (as gfctl simulate does) — and the others' are ignored.
  void onObservation(const gesture_formation::GestureObservation::ConstPtr& msg, bool own) {
    std::lock_guard<std::mutex> lock(mutex_);
    const bool single = frames_->views() == 1;
    if (!acts() || (single ? !own : msg->uav_index >= frames_->views())) return;
    std::string skeleton_problem;
    gesture::ViewObservation o = toViewObservation(*msg, &skeleton_problem);
    if (single) o.view = 0;
    if (!skeleton_problem.empty()) {
      NODELET_WARN_STREAM_THROTTLE(5.0, "GestureCommander: skeleton of UAV " << int(msg->uav_index)
                                            << " left out of the 3-D confirmation: " << skeleton_problem);
    }
    bool accepted = false;
    std::string reason;
    const auto closed = frames_->observe(o, &accepted, &reason);
    ++observations_since_report_;
    if (accepted) last_seen_s_[static_cast<std::size_t>(o.view)] = ros::Time::now().toSec();
    else ++rejected_since_report_;
    if (!accepted) {
      NODELET_WARN_STREAM_THROTTLE(1.0, "GestureCommander: observation of UAV " << int(msg->uav_index) << " rejected: " << reason);
    }
    for (const auto& f : closed) publishFrame(f);
  }

  /// One closed frame (gesture::GestureFrames): its status, and the command when it fired.
  void publishFrame(const gesture::GestureFrame& f) {
    ++frames_since_report_;
    if (f.filter.fired) ++fired_since_report_;
    gesture_formation::GestureStatus st;
    st.header.stamp = ros::Time(f.t_s);
    st.gesture_id = f.fused.gesture_id;
    st.dominant_id = f.filter.dominant_id;
    st.dominant_ratio = f.filter.dominant_ratio;
    st.window_count = static_cast<std::uint32_t>(f.filter.window_count);
    st.verdict = gesture::toString(f.filter.verdict);
    st.fired = f.filter.fired;
    st.reported_views = f.reported;
    st.voting_views = f.fused.voting_views;
    st.agreeing_views = f.fused.agreeing_views;
    st.confirmed_3d = f.fused.confirmed_3d;
    if (!f.filter.accepted) NODELET_WARN_STREAM_THROTTLE(1.0, "GestureCommander: measurement rejected: " << f.filter.reason);
    if (f.filter.fired) {
      const int id = f.filter.dominant_id;
      if (f.action == nullptr) {
        last_fired_ = "gesture " + std::to_string(id) + ": unmapped";
      } else if (f.action->kind == gesture::GestureAction::Kind::kEvent) {
        last_fired_ = "gesture " + std::to_string(id) + ": event " + gesture::toString(f.action->event);
        if (f.action->event == gesture::GestureEvent::kAbort) {
          // The leader's own ReplanStep takes it (abort_out → its FormationPlanner's abort_in); once
          // accepted every UAV's LcmBridge relays it with its heartbeats, as in gfctl simulate.
          gesture_formation::AbortCommand abort;
          abort.source = gesture_formation::AbortCommand::SOURCE_GESTURE;
          abort.sender = sender_;
          abort.sequence = ++sequence_;
          abort.stamp = st.header.stamp;  // when the filter fired: the frame's time
          abort.link_sender = -1;
          abort_pub_.publish(abort);
        } else {  // {event: assist_requested}: the leader's planner latches it (docs/safety.md §2.10)
          gesture_formation::AssistanceState request;
          request.header.stamp = st.header.stamp;
          request.phase = gesture_formation::AssistanceState::PHASE_REQUESTED;
          request.requested_at = st.header.stamp;  // when the filter fired
          request.requested_by = sender_;
          assistance_pub_.publish(request);
        }
      } else {
        auto cmd = toMsg(gesture::toCommand(*f.action, ++sequence_));
        cmd.sender = sender_;
        cmd.header.stamp = st.header.stamp;
        command_pub_.publish(cmd);
        last_fired_ = "gesture " + std::to_string(id) + ": " + f.action->parameter_path + " " +
                      (f.action->increment >= 0 ? "+" : "") + std::to_string(f.action->increment);
      }
      NODELET_INFO_STREAM("GestureCommander: fired " << last_fired_ << " (" << f.fused.agreeing_views << " of "
                                                     << f.fused.voting_views << " voting views agreed"
                                                     << (f.fused.confirmed_3d ? ", confirmed in 3-D" : "") << ")");
    }
    st.last_fired = last_fired_;
    status_pub_.publish(st);
  }

  std::mutex mutex_;
  DiagnosticsPublisher diagnostics_;
  int frames_since_report_ = 0, observations_since_report_ = 0, rejected_since_report_ = 0, fired_since_report_ = 0;
  std::vector<double> last_seen_s_;  ///< per camera: ROS time of its last accepted observation
  std::string sender_;
  double frame_wait_s_ = 0.0;
  double frame_merge_s_ = 0.0;  ///< observations of different views this close in time form one frame (0: exact stamps)
  std::optional<gesture::GestureFrames> frames_;  ///< vote, filter, mapping (shared with gfctl simulate)
  std::function<void()> make_frames_;             ///< (re)starts frames_ from the loaded settings
  bool leadership_ = false, acting_ = false;      ///< ~leadership; this UAV votes (acts, or its lease lapsed in its term)
  std::uint32_t acted_term_ = 0;                 ///< the term in which it last acted
  std::uint64_t sequence_ = 0;
  std::string last_fired_;
  ros::Publisher command_pub_, status_pub_, abort_pub_, assistance_pub_;
  ros::Subscriber own_sub_, peer_sub_, leadership_sub_;
  ros::Timer timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::GestureCommanderNodelet, nodelet::Nodelet)

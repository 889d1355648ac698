// LcmBridge nodelet: the only code that touches LCM (through lcm_bridge::SecureLink:
// HMAC-SHA256 envelopes with sender id, sequence and stamp; docs/security.md). It carries,
// between UAVs and the ground station:
//   ROS → LCM: worker_state_in (the leader's estimate), plan_in (this UAV's plan),
//              formation_params_in (the leader's parameters), formation_command_in (operator),
//              gesture_observation_in (this UAV's gesture vote, GestureObservation),
//              and a heartbeat at ~heartbeat_rate_hz.
//   LCM → ROS: worker_state_out, plans_out (other UAVs' plans), formation_params_out,
//              formation_command_out, gesture_observations_out (other UAVs' votes; refused
//              and counted when the observing UAV is not the envelope's sender or the stamp
//              is not a valid time).
// Operator / gesture commands are single events, not a stream: one lost datagram would lose the
// request (found by the multi-host test, docs/safety.md §5). The sender therefore sends each
// command ~command_repeats times, ~command_repeat_period_s apart (new envelopes: new sequence and
// stamp); the receiver forwards only the first copy of each command id (envelope sender, command
// sender name, sequence) to ROS, with the name bound to the sender as NAME@ID (comm::CommandIntake),
// and counts the others. The leader's FormationState would apply a copy once anyway.
// A plan's fallback flag travels in a heartbeat sent just before the plan (status degraded,
// last_plan_sequence = the plan's sequence); the receiver marks that plan `fallback`.
// Stamps and freshness use ROS time (sim time in simulation: every process shares /clock).
// Parameters (required): ~sender_id, ~known_senders (int list: the fleet's ids, own id ignored), ~lcm_url, ~channel_prefix,
//   ~key_file (owner-only permissions), ~max_age_s, ~heartbeat_rate_hz, ~world_frame,
//   ~command_repeats (1..20), ~command_repeat_period_s.
// Optional, with their defaults (docs/security.md §4, §7):
//   ~command_max_age_s (5.0): the age limit of formation commands (others: ~max_age_s, heartbeats ≥ 2 s);
//   ~sequence_file ($ROS_HOME/gesture_formation/lcm_bridge_<sender_id>.boot): the boot counter in the
//     high bits of this sender's sequence numbers (created 0600), so a restart with the clock set
//     back is not refused as stale;
//   ~high_water_file ($ROS_HOME/gesture_formation/lcm_bridge_<sender_id>.marks): the highest sequence
//     accepted per sender, saved every second and on shutdown, restored at start: replays after
//     a restart of this receiver are refused without relying on the clocks;
//   ~recv_buf_bytes (4194304): UDP receive buffer requested for udpm:// URLs without
//     recv_buf_size (the kernel caps it at net.core.rmem_max);
//   ~max_rate_hz (400), ~burst (200): per-sender budget of envelopes reaching the signature check;
//   ~command_senders, ~params_senders (int lists; absent: any known sender): who may send formation
//     commands (the ground station, the leader) and formation parameters (the leader).
// Diagnostics: diagnostic_msgs/DiagnosticArray on /diagnostics at 1 Hz, one status for the link
// (every rejection class in total) and one per known sender (its claimed-name rejections);
// a throttled warning names the sender and the class of refused envelopes.

#include <deque>
#include <map>
#include <mutex>
#include <optional>

#include <diagnostic_msgs/DiagnosticArray.h>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "conversions.hpp"
#include "diagnostics.hpp"
#include "gesture_formation/comm/command_intake.hpp"
#include "gesture_formation/comm/link_settings.hpp"
#include "gesture_formation/comm/rejection_report.hpp"
#include "gesture_formation/comm/sequence_store.hpp"
#include "gesture_formation/comm/verifier.hpp"
#include "gesture_formation/lcm_bridge/lcm_transport.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class LcmBridgeNodelet : public nodelet::Nodelet {
 public:
  ~LcmBridgeNodelet() override {
    std::lock_guard<std::mutex> lock(mutex_);
    drain_timer_.stop();
    diagnostics_.stop();
    saveMarks();
    link_.reset();
    transport_.reset();
  }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ParamLoader params(getPrivateNodeHandle());
    int sender_id = 0;
    std::vector<int> known;
    std::string url, prefix, key_file;
    double max_age_s = 0.0, heartbeat_hz = 0.0;
    params.load("sender_id", sender_id, 0, 65535);
    params.load("known_senders", known);
    params.load("lcm_url", url);
    params.load("channel_prefix", prefix);
    params.load("key_file", key_file);
    params.load("max_age_s", max_age_s);  // range: the verifier's, checked with the link's settings below
    params.load("heartbeat_rate_hz", heartbeat_hz, 0.1, 50.0);
    params.load("world_frame", world_frame_);
    double repeat_period_s = 0.0;
    params.load("command_repeats", command_repeats_, 1, 20);
    params.load("command_repeat_period_s", repeat_period_s, 0.01, 1.0);
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    const std::string state_dir = comm::defaultStateDirectory();
    const std::string id_text = std::to_string(sender_id);
    std::string sequence_file, marks_file;
    params.loadOptional("sequence_file", sequence_file, state_dir + "/lcm_bridge_" + id_text + ".boot");
    params.loadOptional("high_water_file", marks_file, state_dir + "/lcm_bridge_" + id_text + ".marks");
    comm::LinkSettings link;
    link.sender_id = sender_id;
    link.known_senders = known;
    link.max_age_s = max_age_s;
    link.command_max_age_s = pnh.param("command_max_age_s", link.command_max_age_s);
    link.recv_buf_bytes = pnh.param("recv_buf_bytes", link.recv_buf_bytes);
    link.max_rate_hz = pnh.param("max_rate_hz", link.max_rate_hz);
    link.burst = pnh.param("burst", link.burst);
    for (auto [name, list] : {std::make_pair("command_senders", &link.command_senders),
                              std::make_pair("params_senders", &link.params_senders)}) {
      std::vector<int> ids;
      if (pnh.getParam(name, ids)) *list = ids;
    }
    params.note("command_max_age_s: " + std::to_string(link.command_max_age_s) + ", recv_buf_bytes: " +
                std::to_string(link.recv_buf_bytes) + ", max_rate_hz: " + std::to_string(link.max_rate_hz) +
                ", burst: " + std::to_string(link.burst) + ", command_senders: " +
                std::to_string(link.command_senders ? link.command_senders->size() : 0) + " id(s), params_senders: " +
                std::to_string(link.params_senders ? link.params_senders->size() : 0) + " id(s)");
    // Every problem of the link's settings at once (comm/link_settings.hpp).
    std::vector<common::ConfigError> link_problems;
    const comm::VerifierConfig vcfg = comm::verifierConfigOf(link, link_problems);
    for (const auto& e : link_problems) params.addError(e.key + ": " + e.message);
    url = comm::withReceiveBuffer(url, link.recv_buf_bytes);
    std::optional<comm::KeyRing> keys;
    if (!key_file.empty()) {
      auto k = comm::loadKeyFile(key_file);
      if (k) {
        keys.emplace(std::move(*k));
        if (const auto e = comm::keyRingOwnerProblem(*keys, sender_id)) params.addError(e->key + ": " + e->message);
      } else {
        params.addError("key_file: " + k.reason());
      }
    }
    if (params.ok()) {
      auto t = lcm_bridge::LcmTransport::create(url, prefix);
      if (!t) params.addError("lcm_url: " + t.reason());
      else transport_ = std::move(*t);
    }
    std::optional<comm::Verifier> verifier;
    std::uint32_t boot = 0;
    std::map<std::uint16_t, std::uint64_t> marks;
    if (params.ok()) {
      comm::ensureStateDirectory(state_dir, {sequence_file, marks_file});
      auto b = comm::advanceBootCounter(sequence_file);
      if (b) boot = b.value();
      else params.addError("sequence_file: " + b.reason());
      auto m = comm::loadHighWaterMarks(marks_file);
      if (m) marks = m.value();
      else params.addError("high_water_file: " + m.reason());
      marks_file_ = marks_file;
    }
    if (params.ok()) {
      auto v = comm::Verifier::create(vcfg, *keys);
      if (v) verifier.emplace(std::move(*v));
      else params.addError("key_file/known_senders: " + v.reason());
    }
    if (!params.ok()) {
      NODELET_ERROR_STREAM("LcmBridge refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("LcmBridge loaded:\n" << params.loaded());
    if (!keys->perSender()) {
      NODELET_WARN_STREAM("LcmBridge: key_file holds a group key: any holder can speak for any sender; use per-sender "
                          "keys (tools/make_fleet_keys.sh, docs/security.md: Keys)");
    }
    verifier->restoreHighWaterMarks(marks);
    NODELET_INFO_STREAM("LcmBridge: boot " << boot << " (sequence numbers from " << comm::firstSequenceOfBoot(boot)
                                           << "), restored high-water marks of " << marks.size() << " sender(s)");
    const std::uint64_t first_sequence = comm::firstSequenceOfBoot(boot);
    link_ = std::make_unique<lcm_bridge::SecureLink>(*transport_,
                                                     comm::Signer(static_cast<std::uint16_t>(sender_id), *keys, first_sequence),
                                                     std::move(*verifier), [] { return ros::Time::now().toSec(); });
    link_->setHandler([this](const comm::Envelope& e) { onEnvelope(e); });
    link_->setRejectHandler([this](const comm::VerifyResult& r, std::optional<std::uint16_t> claimed) {
      onRejected(r, claimed);
    });
    heartbeat_.uav_index = static_cast<std::uint16_t>(std::min(sender_id, comm::kMaxUavIndex));

    // Queues hold a burst: every peer's messages of ~1 s (several UAVs, 10–30 Hz each).
    worker_pub_ = nh.advertise<gesture_formation::WorkerState>("worker_state_out", 100);
    plans_pub_ = nh.advertise<gesture_formation::PlannedTrajectory>("plans_out", 100);
    params_pub_ = nh.advertise<gesture_formation::FormationParams>("formation_params_out", 20, true);
    command_pub_ = nh.advertise<gesture_formation::FormationCommand>("formation_command_out", 100);
    worker_sub_ = nh.subscribe("worker_state_in", 50, &LcmBridgeNodelet::onWorker, this);
    plan_sub_ = nh.subscribe("plan_in", 50, &LcmBridgeNodelet::onPlan, this);
    params_sub_ = nh.subscribe("formation_params_in", 20, &LcmBridgeNodelet::onParams, this);
    command_sub_ = nh.subscribe("formation_command_in", 100, &LcmBridgeNodelet::onCommand, this);
    observations_pub_ = nh.advertise<gesture_formation::GestureObservation>("gesture_observations_out", 200);
    observation_sub_ = nh.subscribe("gesture_observation_in", 100, &LcmBridgeNodelet::onObservation, this);
    drain_timer_ = nh.createWallTimer(ros::WallDuration(0.005), [this](const ros::WallTimerEvent&) {
      std::lock_guard<std::mutex> lock(mutex_);
      // Bounded: a flood must not keep the mutex from heartbeats and publishing.
      if (transport_) transport_->drain(kMaxDrainPerTick);
    });
    diagnostics_.start(nh, 1.0, [this](double) {
      std::lock_guard<std::mutex> lock(mutex_);
      saveMarks();
      return statuses();
    });
    repeat_timer_ = nh.createTimer(ros::Duration(repeat_period_s), [this](const ros::TimerEvent&) {
      std::lock_guard<std::mutex> lock(mutex_);
      for (auto it = repeating_.begin(); it != repeating_.end();) {
        send(it->first, "command (repeat)");
        it = --it->second == 0 ? repeating_.erase(it) : std::next(it);
      }
    });
    heartbeat_timer_ = nh.createTimer(ros::Duration(1.0 / heartbeat_hz), [this](const ros::TimerEvent&) {
      std::lock_guard<std::mutex> lock(mutex_);
      send(heartbeat_, "heartbeat");
    });
  }

  template <class T>
  void send(const T& m, const char* what) {
    if (!link_ || ros::Time::now().isZero()) return;
    const auto r = link_->publish(m);
    if (!r) NODELET_WARN_STREAM_THROTTLE(1.0, "LcmBridge: " << what << " not sent: " << r.reason());
  }

  void onWorker(const gesture_formation::WorkerState::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    heartbeat_.worker_visible = !msg->lost;
    send(toWire(*msg), "worker state");
  }
  void onPlan(const gesture_formation::PlannedTrajectory::ConstPtr& msg) {
    auto plan = fromMsg(*msg);
    if (!plan) return;
    std::lock_guard<std::mutex> lock(mutex_);
    heartbeat_.status = msg->fallback ? comm::Heartbeat::Status::kDegraded : comm::Heartbeat::Status::kOk;
    heartbeat_.last_plan_sequence = msg->sequence;
    send(heartbeat_, "heartbeat");  // before the plan: it carries the plan's fallback flag
    send(*plan, "plan");
  }
  void onParams(const gesture_formation::FormationParams::ConstPtr& msg) {
    auto p = fromMsg(*msg);
    if (!p) return;
    std::lock_guard<std::mutex> lock(mutex_);
    send(*p, "formation parameters");
  }
  void onCommand(const gesture_formation::FormationCommand::ConstPtr& msg) {
    auto c = fromMsg(*msg);
    if (!c) {
      NODELET_WARN_STREAM("LcmBridge: command not sent: " << c.reason());
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    send(*c, "command");
    if (command_repeats_ > 1) repeating_.emplace_back(*c, command_repeats_ - 1);
  }

  void onObservation(const gesture_formation::GestureObservation::ConstPtr& msg) {
    auto o = toWire(*msg);
    if (!o) {
      NODELET_WARN_STREAM_THROTTLE(1.0, "LcmBridge: gesture observation not sent: " << o.reason());
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    send(*o, "gesture observation");
  }

  // Called from drain() (mutex held).
  void onEnvelope(const comm::Envelope& e) {
    switch (e.type) {
      case comm::MessageType::kHeartbeat: {
        comm::Heartbeat h;
        if (decoder_.decode(e, h)) peers_[e.sender_id] = h;
        break;
      }
      case comm::MessageType::kWorkerState: {
        comm::WorkerStateMessage w;
        if (!decoder_.decode(e, w)) break;
        auto m = fromWire(w);
        m.header.frame_id = world_frame_;
        worker_pub_.publish(m);
        break;
      }
      case comm::MessageType::kPlannedTrajectory: {
        planning::PlannedTrajectory p;
        if (!decoder_.decode(e, p)) break;
        auto m = toMsg(p);
        m.header.frame_id = world_frame_;
        const auto peer = peers_.find(e.sender_id);
        m.fallback = peer != peers_.end() && peer->second.status != comm::Heartbeat::Status::kOk &&
                     peer->second.last_plan_sequence == p.sequence;
        m.status = m.fallback ? "fallback" : "optimized";
        plans_pub_.publish(m);
        break;
      }
      case comm::MessageType::kFormationParams: {
        formation::FormationParams p;
        if (!decoder_.decode(e, p)) break;
        auto m = toMsg(p, 0);
        m.header.stamp = ros::Time(e.stamp_s);
        m.header.frame_id = world_frame_;
        params_pub_.publish(m);
        break;
      }
      case comm::MessageType::kFormationCommand: {
        formation::FormationCommand c;
        if (!decoder_.decode(e, c)) break;
        // The sender repeats each command: forward its first copy only, its name bound to the
        // envelope's authenticated sender (NAME@ID; comm/command_intake.hpp).
        const auto forwarded = command_intake_.accept(e.sender_id, std::move(c));
        if (!forwarded) break;
        auto m = toMsg(*forwarded);
        m.header.stamp = ros::Time(e.stamp_s);
        command_pub_.publish(m);
        break;
      }
      case comm::MessageType::kGestureObservation: {
        comm::GestureObservationMessage o;
        if (!decoder_.decode(e, o)) break;
        // A UAV votes for its own camera only; the frame time must be a ROS time.
        if (o.uav_index != e.sender_id || !(o.t_s >= 0.0 && o.t_s < 4.0e9)) {
          ++observations_refused_;
          NODELET_WARN_STREAM_THROTTLE(1.0, "LcmBridge: gesture observation refused (" << observations_refused_
                                                << " so far): sender " << e.sender_id << ", uav_index " << o.uav_index
                                                << ", t " << o.t_s << " s");
          break;
        }
        observations_pub_.publish(fromWire(o));
        break;
      }
    }
    if (!decoder_.lastReason().empty()) {
      link_->verifier().countDecodeFailure(e.sender_id);
      NODELET_WARN_STREAM_THROTTLE(1.0, "LcmBridge: payload from sender " << e.sender_id << " refused (decode_failure): "
                                                                         << decoder_.lastReason());
    }
  }

  // Called from drain() (mutex held).
  void onRejected(const comm::VerifyResult& r, std::optional<std::uint16_t> claimed) {
    const std::string who = claimed ? "sender " + std::to_string(*claimed) : std::string("an unparsable datagram");
    NODELET_WARN_STREAM_THROTTLE(1.0, "LcmBridge: refused " << comm::toString(r.verdict) << " from " << who << " ("
                                                         << r.detail << "; " << link_->verifierCounters().rejected()
                                                         << " refused in all; /diagnostics has the counts)");
  }

  // Mutex held.
  void saveMarks() {
    if (!link_ || marks_file_.empty()) return;
    const auto marks = link_->verifier().highWaterMarks();
    if (marks.empty() || marks == saved_marks_) return;
    const auto r = comm::saveHighWaterMarks(marks_file_, marks);
    if (r) saved_marks_ = marks;
    else NODELET_WARN_STREAM_THROTTLE(10.0, "LcmBridge: high_water_file not saved: " << r.reason());
  }

  // Mutex held. The counts and what was refused since the last report: comm::RejectionReport.
  std::vector<diagnostic_msgs::DiagnosticStatus> statuses() {
    if (!link_) return {};
    if (!report_) report_.emplace("LcmBridge sender " + std::to_string(link_->signer().senderId()));
    const auto senders = link_->verifier().senderCounters();
    const auto& t = transport_->counters();
    std::vector<diagnostic_msgs::DiagnosticStatus> out{
        toStatus(report_->link(link_->verifierCounters(), senders,
                               {{"channel_mismatch", link_->channelMismatches()},
                                {"undecodable_lcm", t.undecodable},
                                {"received_lcm", t.received},
                                {"published", t.published},
                                {"publish_failed", t.publish_failed},
                                {"command_copies_dropped", command_intake_.copiesDropped()},
                                {"observations_refused", observations_refused_}},
                               {"channel_mismatch", "undecodable_lcm"}))};
    for (const auto& [sender, counters] : senders) out.push_back(toStatus(report_->sender(sender, counters)));
    return out;
  }

  static diagnostic_msgs::DiagnosticStatus toStatus(const comm::DiagnosticEntry& e) {
    diagnostic_msgs::DiagnosticStatus s;
    s.name = e.name;
    s.hardware_id = "lcm";
    s.level = e.warn ? diagnostic_msgs::DiagnosticStatus::WARN : diagnostic_msgs::DiagnosticStatus::OK;
    s.message = e.message;
    for (const auto& [key, value] : e.values) {
      diagnostic_msgs::KeyValue kv;
      kv.key = key;
      kv.value = std::to_string(value);
      s.values.push_back(kv);
    }
    return s;
  }

  std::mutex mutex_;
  std::string world_frame_;
  std::unique_ptr<lcm_bridge::LcmTransport> transport_;
  std::unique_ptr<lcm_bridge::SecureLink> link_;
  comm::PayloadDecoder decoder_;
  comm::Heartbeat heartbeat_;
  std::map<std::uint16_t, comm::Heartbeat> peers_;
  int command_repeats_ = 1;
  std::deque<std::pair<formation::FormationCommand, int>> repeating_;  ///< commands still to repeat, copies left
  comm::CommandIntake command_intake_;  ///< first copies forwarded, names bound to the envelope sender
  std::uint64_t observations_refused_ = 0;  ///< decoded gesture observations with a bad sender / stamp
  static constexpr int kMaxDrainPerTick = 2000;  ///< LCM messages handled per 5 ms drain
  std::string marks_file_;
  std::map<std::uint16_t, std::uint64_t> saved_marks_;
  std::optional<comm::RejectionReport> report_;  ///< /diagnostics: counts and refusals since the last report
  ros::Publisher worker_pub_, plans_pub_, params_pub_, command_pub_, observations_pub_;
  ros::Subscriber worker_sub_, plan_sub_, params_sub_, command_sub_, observation_sub_;
  ros::WallTimer drain_timer_;
  DiagnosticsPublisher diagnostics_;  ///< /diagnostics every wall second (also saves the high-water marks)
  ros::Timer heartbeat_timer_, repeat_timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::LcmBridgeNodelet, nodelet::Nodelet)

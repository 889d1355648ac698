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
// stamp); the receiver forwards only the first copy of each command id (sender, sequence) to ROS
// and counts the others. The leader's FormationState would apply a copy once anyway.
// A plan's fallback flag travels in a heartbeat sent just before the plan (status degraded,
// last_plan_sequence = the plan's sequence); the receiver marks that plan `fallback`.
// Stamps and freshness use ROS time (sim time in simulation: every process shares /clock).
// Parameters (required): ~sender_id, ~known_senders (int list: the fleet's ids, own id ignored), ~lcm_url, ~channel_prefix,
//   ~key_file (owner-only permissions), ~max_age_s, ~heartbeat_rate_hz, ~world_frame,
//   ~command_repeats (1..20), ~command_repeat_period_s.
#include <deque>
#include <map>
#include <mutex>
#include <set>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "conversions.hpp"
#include "gesture_formation/lcm_bridge/lcm_transport.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class LcmBridgeNodelet : public nodelet::Nodelet {
 public:
  ~LcmBridgeNodelet() override {
    std::lock_guard<std::mutex> lock(mutex_);
    drain_timer_.stop();
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
    params.load("max_age_s", max_age_s, 0.01, 60.0);
    params.load("heartbeat_rate_hz", heartbeat_hz, 0.1, 50.0);
    params.load("world_frame", world_frame_);
    double repeat_period_s = 0.0;
    params.load("command_repeats", command_repeats_, 1, 20);
    params.load("command_repeat_period_s", repeat_period_s, 0.01, 1.0);
    std::optional<comm::KeyRing> keys;
    if (!key_file.empty()) {
      auto k = comm::loadKeyFile(key_file);
      if (k) {
        keys.emplace(std::move(*k));
      } else {
        params.addError("key_file: " + k.reason());
      }
    }
    comm::VerifierConfig vcfg;
    for (const int s : known) {
      if (s < 0 || s > 65535) params.addError("known_senders: " + std::to_string(s) + " out of range [0, 65535]");
      else if (s != sender_id) vcfg.known_senders.push_back(static_cast<std::uint16_t>(s));  // the fleet's ids; own ignored
    }
    vcfg.own_sender_id = static_cast<std::uint16_t>(sender_id);
    vcfg.max_age_s = max_age_s;
    vcfg.max_age_s_by_type[comm::MessageType::kHeartbeat] = std::max(max_age_s, 2.0);
    if (params.ok()) {
      for (const auto& e : vcfg.validate()) params.addError("known_senders/max_age_s: " + e);
    }
    if (params.ok()) {
      auto t = lcm_bridge::LcmTransport::create(url, prefix);
      if (!t) params.addError("lcm_url: " + t.reason());
      else transport_ = std::move(*t);
    }
    std::optional<comm::Verifier> verifier;
    if (params.ok()) {
      auto v = comm::Verifier::create(vcfg, *keys);
      if (v) verifier.emplace(std::move(*v));
      else params.addError("key_file/known_senders: " + v.reason());
      if (keys->perSender() && keys->active().sender_id != sender_id) {
        params.addError("key_file: its signing key belongs to sender " + std::to_string(keys->active().sender_id) +
                        ", not to sender_id " + std::to_string(sender_id));
      }
    }
    if (!params.ok()) {
      NODELET_ERROR_STREAM("LcmBridge refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("LcmBridge loaded:\n" << params.loaded());
    if (!keys->perSender()) {
      NODELET_WARN_STREAM("LcmBridge: key_file holds a group key: any holder can speak for any sender; use per-sender "
                          "keys (tools/make_fleet_keys.sh, docs/security.md §5)");
    }
    const auto first_sequence = static_cast<std::uint64_t>(ros::WallTime::now().toNSec() / 1000);
    link_ = std::make_unique<lcm_bridge::SecureLink>(*transport_,
                                                     comm::Signer(static_cast<std::uint16_t>(sender_id), *keys, first_sequence),
                                                     std::move(*verifier), [] { return ros::Time::now().toSec(); });
    link_->setHandler([this](const comm::Envelope& e) { onEnvelope(e); });
    heartbeat_.uav_index = static_cast<std::uint16_t>(std::min(sender_id, comm::kMaxUavIndex));

    worker_pub_ = nh.advertise<gesture_formation::WorkerState>("worker_state_out", 10);
    plans_pub_ = nh.advertise<gesture_formation::PlannedTrajectory>("plans_out", 10);
    params_pub_ = nh.advertise<gesture_formation::FormationParams>("formation_params_out", 5, true);
    command_pub_ = nh.advertise<gesture_formation::FormationCommand>("formation_command_out", 20);
    worker_sub_ = nh.subscribe("worker_state_in", 5, &LcmBridgeNodelet::onWorker, this);
    plan_sub_ = nh.subscribe("plan_in", 5, &LcmBridgeNodelet::onPlan, this);
    params_sub_ = nh.subscribe("formation_params_in", 5, &LcmBridgeNodelet::onParams, this);
    command_sub_ = nh.subscribe("formation_command_in", 20, &LcmBridgeNodelet::onCommand, this);
    observations_pub_ = nh.advertise<gesture_formation::GestureObservation>("gesture_observations_out", 50);
    observation_sub_ = nh.subscribe("gesture_observation_in", 20, &LcmBridgeNodelet::onObservation, this);
    drain_timer_ = nh.createWallTimer(ros::WallDuration(0.005), [this](const ros::WallTimerEvent&) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (transport_) transport_->drain();
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
        // The sender repeats each command: forward its first copy only (ids of the last 256).
        const auto id = std::make_pair(c.id.sender, c.id.sequence);
        if (commands_seen_.count(id) != 0) {
          ++command_copies_dropped_;
          break;
        }
        commands_seen_.insert(id);
        commands_seen_order_.push_back(id);
        if (commands_seen_order_.size() > 256) {
          commands_seen_.erase(commands_seen_order_.front());
          commands_seen_order_.pop_front();
        }
        auto m = toMsg(c);
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
      NODELET_WARN_STREAM_THROTTLE(1.0, "LcmBridge: payload refused: " << decoder_.lastReason());
    }
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
  std::set<std::pair<std::string, std::uint64_t>> commands_seen_;     ///< received command ids (bounded)
  std::deque<std::pair<std::string, std::uint64_t>> commands_seen_order_;
  std::uint64_t command_copies_dropped_ = 0;  ///< repeated copies of an already forwarded command
  std::uint64_t observations_refused_ = 0;  ///< decoded gesture observations with a bad sender / stamp
  ros::Publisher worker_pub_, plans_pub_, params_pub_, command_pub_, observations_pub_;
  ros::Subscriber worker_sub_, plan_sub_, params_sub_, command_sub_, observation_sub_;
  ros::WallTimer drain_timer_;
  ros::Timer heartbeat_timer_, repeat_timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::LcmBridgeNodelet, nodelet::Nodelet)

// LcmBridge nodelet: the only code that touches LCM (lcm_bridge::SecureLink: signed envelopes with
// sender id, sequence and stamp; docs/security.md); a thin adapter between ROS topics and the link
// (topics, parameters, defaults: docs/ros.md "LcmBridge"). ROS → LCM: the share, plans (with their
// fallback flag; the heartbeat sent just before names the plan and the status), parameters, gesture observations, aborts (this
// UAV's accepted abort also with every timed heartbeat, whether or not its planner plans), single events repeated like a command
// (~command_repeats copies, comm::OutgoingRepeats: commands, the leader's acknowledgements and
// assistance state — also with every share while requested —, the ground's acknowledgement of it),
// leadership messages (docs/safety.md §1.2) and live-map changes (docs/mapping.md §8), both from UAVs
// speaking for themselves. LCM → ROS: what each envelope yields (comm::LinkInbox: first copy of each
// command / ack id, every abort and assistance copy; map updates as they come). Start-up:
// lcm_bridge::startLink; stamps in ROS time (sim time in simulation); /diagnostics at 1 Hz
// (lcm_bridge::linkDiagnostics); a throttled warning names the sender and class of each refusal.

#include <mutex>
#include <optional>
#include <type_traits>
#include <variant>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "conversions.hpp"
#include "diagnostics.hpp"
#include "leadership_conversions.hpp"
#include "gesture_formation/comm/link_inbox.hpp"
#include "gesture_formation/comm/outgoing_repeats.hpp"
#include "gesture_formation/comm/sequence_store.hpp"
#include "gesture_formation/comm/standing_messages.hpp"
#include "gesture_formation/lcm_bridge/link_diagnostics.hpp"
#include "gesture_formation/lcm_bridge/link_startup.hpp"
#include "link_params.hpp"
#include "map_update_conversions.hpp"
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
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    ParamLoader params(pnh);
    lcm_bridge::LinkStartupConfig cfg;
    double heartbeat_hz = 0.0;
    loadLinkParams(pnh, params, cfg);
    params.load("heartbeat_rate_hz", heartbeat_hz, 0.1, 50.0);
    params.load("world_frame", world_frame_);
    params.load("command_repeats", command_repeats_, 1, 20);
    params.load("command_repeat_period_s", command_repeat_period_s_, 0.01, 1.0);
    params.note(comm::describeOptional(cfg.link));
    // Every problem at once: the link's settings and key file beside the other parameters; the
    // transport and the state files only when all of those are fine (lcm_bridge/link_startup.hpp).
    std::vector<common::ConfigError> problems;
    std::optional<lcm_bridge::StartedLink> started;
    if (params.ok()) started = lcm_bridge::startLink(cfg, [] { return ros::Time::now().toSec(); }, problems);
    else problems = lcm_bridge::checkLinkStartup(cfg);
    for (const auto& e : problems) params.addError(e.key + ": " + e.message);
    if (!params.ok() || !started) {
      NODELET_ERROR_STREAM("LcmBridge refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("LcmBridge loaded:\n" << params.loaded());
    NODELET_INFO_STREAM("LcmBridge: " << lcm_bridge::describe(*started));
    if (!started->per_sender_keys) {
      NODELET_WARN_STREAM("LcmBridge: key_file holds a group key: any holder can speak for any sender; use per-sender "
                          "keys (tools/make_fleet_keys.sh, docs/security.md: Keys)");
    }
    transport_ = std::move(started->transport);
    link_ = std::move(started->link);
    marks_ = lcm_bridge::HighWaterMarkSaver(cfg.marks_file);
    link_->setHandler([this](const comm::Envelope& e) { onEnvelopeGuarded(e); });
    link_->setRejectHandler([this](const comm::VerifyResult& r, std::optional<std::uint16_t> claimed) {
      onRejected(r, claimed);
    });
    heartbeat_.uav_index = static_cast<std::uint16_t>(std::min(cfg.link.sender_id, comm::kMaxUavIndex));
    report_.emplace("LcmBridge sender " + std::to_string(cfg.link.sender_id));

    // Queues hold a burst: every peer's messages of ~1 s (several UAVs, 10–30 Hz each).
    worker_pub_ = nh.advertise<gesture_formation::WorkerState>("worker_state_out", 100);
    plans_pub_ = nh.advertise<gesture_formation::PlannedTrajectory>("plans_out", 100);
    params_pub_ = nh.advertise<gesture_formation::FormationParams>("formation_params_out", 20, true);
    command_pub_ = nh.advertise<gesture_formation::FormationCommand>("formation_command_out", 100);
    worker_sub_ = nh.subscribe("worker_state_in", 50, &LcmBridgeNodelet::onWorker, this);
    plan_sub_ = nh.subscribe("plan_in", 50, &LcmBridgeNodelet::onPlan, this);
    params_sub_ = nh.subscribe<gesture_formation::FormationParams>(
        "formation_params_in", 20, [this](const gesture_formation::FormationParams::ConstPtr& m) { sendChecked(toWire(*m), "formation parameters"); });
    observations_pub_ = nh.advertise<gesture_formation::GestureObservation>("gesture_observations_out", 200);
    observation_sub_ = nh.subscribe<gesture_formation::GestureObservation>(
        "gesture_observation_in", 100, [this](const gesture_formation::GestureObservation::ConstPtr& m) { sendChecked(toWire(*m), "gesture observation"); });
    map_update_pub_ = nh.advertise<gesture_formation::MapUpdate>("map_update_out", 20);
    map_update_sub_ = nh.subscribe<gesture_formation::MapUpdate>(
        "map_update_in", 20, [this](const gesture_formation::MapUpdate::ConstPtr& m) { sendChecked(fromMsg(*m), "map update"); });
    abort_pub_ = nh.advertise<gesture_formation::AbortCommand>("abort_out", 100);
    abort_sub_ = nh.subscribe("abort_in", 100, &LcmBridgeNodelet::onAbort, this);
    relay_sub_ = nh.subscribe("abort_relay_in", 5, &LcmBridgeNodelet::onAbortState, this);
    leadership_pub_ = nh.advertise<gesture_formation::LeadershipMessage>("leadership_out", 100);
    leadership_sub_ = nh.subscribe<gesture_formation::LeadershipMessage>(
        "leadership_in", 100, [this](const gesture_formation::LeadershipMessage::ConstPtr& m) { sendChecked(fromMsg(*m), "leadership message"); });
    // Single events, sent now and repeated like a command: commands, the leader's acknowledgements and
    // assistance state (re-sent with every worker state while requested), the ground's acknowledgement.
    command_sub_ = subscribeRepeated<gesture_formation::FormationCommand>(
        nh, "formation_command_in", 100, "command", [](const auto& m) { return fromMsg(m); });
    ack_pub_ = nh.advertise<gesture_formation::CommandAck>("command_ack_out", 50);
    ack_sub_ = subscribeRepeated<gesture_formation::CommandAck>(nh, "command_ack_in", 50, "command acknowledgement",
                                                                [](const auto& m) { return toWire(m); });
    assistance_pub_ = nh.advertise<gesture_formation::AssistanceState>("assistance_out", 20);  // every copy received
    assistance_sub_ = subscribeRepeated<gesture_formation::AssistanceState>(nh, "assistance_in", 20, "assistance",
                                                                            [](const auto& m) { return toWire(m); });
    drain_timer_ = nh.createWallTimer(ros::WallDuration(0.005), [this](const ros::WallTimerEvent&) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (transport_) transport_->drain(kMaxDrainPerTick);
    });
    diagnostics_.start(nh, 1.0, [this](double) {
      std::lock_guard<std::mutex> lock(mutex_);
      saveMarks();
      return statuses();
    });
    repeat_timer_ = nh.createTimer(ros::Duration(0.02), [this](const ros::TimerEvent&) {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const auto& p : repeats_.due(ros::Time::now().toSec())) sendPayload(p, "command (repeat)");
    });
    heartbeat_timer_ = nh.createTimer(ros::Duration(1.0 / heartbeat_hz), [this](const ros::TimerEvent&) {
      std::lock_guard<std::mutex> lock(mutex_);
      send(heartbeat_, "heartbeat");
      // This UAV's accepted abort, with every timed heartbeat (heartbeat_rate_hz): also while its
      // planner publishes nothing (stale odometry, no worker estimate, an outage).
      if (const auto& relay = standing_.withHeartbeat()) send(*relay, "abort (relay)");
    });
  }

  // Each message on `topic`, in its wire form (a refusal is logged), is sent now and repeated like a command.
  template <class Msg, class ToWire>
  ros::Subscriber subscribeRepeated(ros::NodeHandle& nh, const std::string& topic, int queue, const char* what,
                                    ToWire to_wire) {
    return nh.subscribe<Msg>(topic, queue, [this, what, to_wire](const typename Msg::ConstPtr& m) {
      sendChecked(to_wire(*m), what, command_repeats_, command_repeat_period_s_);
    });
  }
  // Sends now; a single event (copies > 1) is repeated period_s apart (comm::OutgoingRepeats).
  template <class T>
  void send(const T& m, const char* what, int copies = 1, double period_s = 0.0) {
    auto payload = comm::encodePayload(m);
    if (!payload) {
      NODELET_WARN_STREAM_THROTTLE(1.0, "LcmBridge: " << what << " not sent: " << payload.reason());
      return;
    }
    comm::OutgoingPayload p{comm::messageTypeOf(m), std::move(payload.value())};
    sendPayload(p, what);
    repeats_.add(std::move(p), copies, period_s, ros::Time::now().toSec());
  }
  void sendPayload(const comm::OutgoingPayload& p, const char* what) {
    if (!link_ || ros::Time::now().isZero()) return;
    const auto r = link_->publishPayload(p.type, p.payload);
    if (!r) NODELET_WARN_STREAM_THROTTLE(1.0, "LcmBridge: " << what << " not sent: " << r.reason());
  }

  void onWorker(const gesture_formation::WorkerState::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    heartbeat_.worker_visible = !msg->lost;
    send(toWire(*msg), "worker state");
    if (const auto assistance = standing_.withWorkerState()) send(*assistance, "assistance");
  }
  void onPlan(const gesture_formation::PlannedTrajectory::ConstPtr& msg) {
    auto plan = fromMsg(*msg);
    if (!plan) return;
    std::lock_guard<std::mutex> lock(mutex_);
    heartbeat_.status = msg->fallback ? comm::Heartbeat::Status::kDegraded : comm::Heartbeat::Status::kOk;
    heartbeat_.last_plan_sequence = msg->sequence;
    send(heartbeat_, "heartbeat");  // before the plan: this UAV's status with its newest plan
    send(comm::PlanMessage{std::move(*plan), static_cast<bool>(msg->fallback)}, "plan");
  }
  // An abort to send (the ground station's copies: the OperatorInterface repeats it).
  void onAbort(const gesture_formation::AbortCommand::ConstPtr& msg) { sendChecked(toWire(*msg), "abort"); }
  template <class T>
  void sendChecked(const common::Result<T>& m, const char* what, int copies = 1, double period_s = 0.0) {
    if (!m) {
      NODELET_WARN_STREAM_THROTTLE(1.0, "LcmBridge: " << what << " not sent: " << m.reason());
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    send(*m, what, copies, period_s);
    if constexpr (std::is_same_v<T, comm::AssistanceMessage>) standing_.assistanceSent(*m);  // re-sent while requested
  }
  // This UAV's abort state: once it accepted an abort, the command is relayed (docs/safety.md §2.8).
  void onAbortState(const gesture_formation::AbortState::ConstPtr& msg) {
    auto a = toWire(msg->command);
    std::lock_guard<std::mutex> lock(mutex_);
    standing_.abortState(msg->phase != gesture_formation::AbortState::PHASE_NONE, a ? std::optional(*a) : std::nullopt);
  }

  // Called from drain() (mutex held). An authenticated payload that the decoders let through and a
  // conversion still refuses (e.g. a time ros::Time cannot hold: the decoders refuse those) is
  // dropped with an error, never thrown into roscpp's timer, which would end the whole manager.
  void onEnvelopeGuarded(const comm::Envelope& e) {
    try {
      onEnvelope(e);
    } catch (const std::exception& ex) {
      ++conversion_failures_;
      NODELET_ERROR_STREAM_THROTTLE(1.0, "LcmBridge: from sender " << e.sender_id << ", " << comm::toString(e.type)
                                                                   << " dropped (" << conversion_failures_
                                                                   << " so far): " << ex.what());
    }
  }

  // What to hand on: comm::LinkInbox.
  void onEnvelope(const comm::Envelope& e) {
    const comm::InboxItem item = inbox_.take(e);
    if (const auto* w = std::get_if<comm::WorkerStateMessage>(&item)) {
      auto m = fromWire(*w);
      m.header.frame_id = world_frame_;
      worker_pub_.publish(m);
    } else if (const auto* p = std::get_if<comm::PlanMessage>(&item)) {
      auto m = toMsg(p->plan);
      m.header.frame_id = world_frame_;
      m.fallback = p->fallback;
      m.status = m.fallback ? "fallback" : "optimized";
      plans_pub_.publish(m);
    } else if (const auto* f = std::get_if<comm::FormationParamsMessage>(&item)) {
      auto m = toMsg(f->params, f->version);
      m.header.stamp = ros::Time(e.stamp_s);
      m.header.frame_id = world_frame_;
      params_pub_.publish(m);
    } else if (const auto* c = std::get_if<formation::FormationCommand>(&item)) {
      auto m = toMsg(*c);  // the first copy, its name bound to the sender (NAME@ID)
      m.header.stamp = ros::Time(e.stamp_s);
      command_pub_.publish(m);
    } else if (const auto* o = std::get_if<comm::GestureObservationMessage>(&item)) {
      observations_pub_.publish(fromWire(*o));
    } else if (const auto* a = std::get_if<planning::AbortCommand>(&item)) {
      abort_pub_.publish(toMsg(*a, e.sender_id));  // every copy: the UAV acts on the first it accepts
    } else if (const auto* s = std::get_if<comm::AssistanceMessage>(&item)) {
      assistance_pub_.publish(toMsg(s->state, ros::Time(e.stamp_s)));
    } else if (const auto* l = std::get_if<formation::LeadershipMessage>(&item)) {
      leadership_pub_.publish(toMsg(*l));
    } else if (const auto* k = std::get_if<comm::CommandAckMessage>(&item)) {
      auto m = fromWire(*k);
      m.header.stamp = ros::Time(e.stamp_s);
      ack_pub_.publish(m);
    } else if (const auto* u = std::get_if<comm::MapUpdate>(&item)) {
      map_update_pub_.publish(toMsg(*u));  // to the planner's live map, which checks it against its grid
    }
    if (inbox_.lastWasDecodeFailure()) link_->verifier().countDecodeFailure(e.sender_id);
    if (!inbox_.lastRefusal().empty()) {
      NODELET_WARN_STREAM_THROTTLE(1.0, "LcmBridge: from sender " << e.sender_id << ": " << inbox_.lastRefusal());
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
    if (!link_) return;
    const auto r = marks_.save(link_->verifier().highWaterMarks());
    if (!r) NODELET_WARN_STREAM_THROTTLE(10.0, "LcmBridge: high_water_file not saved: " << r.reason());
  }

  // Mutex held. The counts and what was refused since the last report (lcm_bridge::linkDiagnostics).
  std::vector<diagnostic_msgs::DiagnosticStatus> statuses() {
    if (!link_) return {};
    std::vector<diagnostic_msgs::DiagnosticStatus> out;
    for (const auto& e : lcm_bridge::linkDiagnostics(*report_, *link_, *transport_, inbox_)) out.push_back(toStatus(e));
    return out;
  }

  std::mutex mutex_;
  std::string world_frame_;
  std::unique_ptr<lcm_bridge::LcmTransport> transport_;
  std::unique_ptr<lcm_bridge::SecureLink> link_;
  comm::LinkInbox inbox_;  ///< decoding, peers' heartbeats, first command copies, refused observations
  comm::Heartbeat heartbeat_;
  std::uint64_t conversion_failures_ = 0;  ///< envelopes dropped because a conversion to ROS threw
  int command_repeats_ = 1;
  double command_repeat_period_s_ = 0.1;
  comm::OutgoingRepeats repeats_;  ///< copies of single events still to send
  comm::StandingMessages standing_;  ///< the accepted abort (relayed), the assistance state (re-sent while requested)
  /// LCM messages handled per 5 ms drain: bounded, so a flood cannot keep the mutex from heartbeats.
  static constexpr int kMaxDrainPerTick = 2000;
  lcm_bridge::HighWaterMarkSaver marks_;  ///< high_water_file, saved when the marks changed
  std::optional<comm::RejectionReport> report_;  ///< /diagnostics: counts and refusals since the last report
  ros::Publisher worker_pub_, plans_pub_, params_pub_, command_pub_, observations_pub_, abort_pub_, ack_pub_, assistance_pub_, leadership_pub_, map_update_pub_;
  ros::Subscriber worker_sub_, plan_sub_, params_sub_, command_sub_, observation_sub_, abort_sub_, relay_sub_, ack_sub_, assistance_sub_, leadership_sub_, map_update_sub_;
  ros::WallTimer drain_timer_;
  DiagnosticsPublisher diagnostics_;  ///< /diagnostics every wall second (also saves the high-water marks)
  ros::Timer heartbeat_timer_, repeat_timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::LcmBridgeNodelet, nodelet::Nodelet)

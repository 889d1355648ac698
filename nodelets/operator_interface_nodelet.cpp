// OperatorInterface nodelet: the remote operator's way in (ground station side). Commands come
// as a service (send_command: gesture_formation/SendCommand; CLI tools/gf_command.py) or a topic
// (command_in: FormationCommand, e.g. a GUI or a scheduled mission); each is checked
// (target, parameter, kind, finite amount: formation core parsers), numbered (sender
// ~sender_name, sequence from the sender's boot counter, command_sequence.hpp: a restart never reuses
// numbers, whatever the clock did) and
// published on formation_command_out (to the LcmBridge → the leader's FormationPlanner, which
// applies and clamps it).
// Abort (docs/safety.md §2.8): the service send_abort (gesture_formation/SendAbort; tools/gf_command.py
// abort) publishes one AbortCommand (source operator, the next sequence number) on abort_out — to
// the ground station's LcmBridge, which sends every copy to every UAV — ~abort_repeats times,
// ~abort_repeat_period_s apart, then once every ~abort_resend_period_s for as long as this node runs
// (clearing an abort takes restarting this node and every UAV), each copy stamped when sent (as
// gfctl simulate's AbortSender).
// Acknowledgements (docs/safety.md §2.9): the leader's CommandAck for every command it handled
// arrives on command_ack_in (the ground LcmBridge); each is logged — the operator's own commands with
// the time since sending, the worker's gesture commands as such — and republished on command_ack_out
// (tools/gf_command.py waits there for its command's). A command of its own without an
// acknowledgement within kAckTimeoutS (5 s) is reported once.
// Assistance (docs/safety.md §2.10): the leader's assistance state arrives on assistance_in (the
// ground LcmBridge; every copy); a new request is logged as a warning and every change republished
// latched on assistance_state_out (for the operator's displays); the service acknowledge_assistance
// (AcknowledgeAssistance; tools/gf_command.py ack-assist) sends the acknowledgement of the pending
// request on assistance_ack_out (to the ground LcmBridge → the leader's planner).
// Parameters (required): ~sender_name, ~uav_count, ~abort_repeats, ~abort_repeat_period_s,
// ~abort_resend_period_s; with ~mission_file (simulation; optional ~faults_file) the mission's
// abort.repeats / repeat_period_s / resend_period_s win.
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "config_sources.hpp"
#include "conversions.hpp"
#include "gesture_formation/AcknowledgeAssistance.h"
#include "gesture_formation/SendAbort.h"
#include "gesture_formation/SendCommand.h"
#include "gesture_formation/comm/outgoing_repeats.hpp"
#include "gesture_formation/formation/uav_list.hpp"
#include "command_sequence.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class OperatorInterfaceNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ParamLoader params(getPrivateNodeHandle());
    params.load("sender_name", sender_);
    params.load("uav_count", uav_count_, 1, comm::kMaxUavIndex + 1);
    if (sender_.empty() || sender_.find(' ') != std::string::npos) params.addError("sender_name: must be non-empty without spaces");
    if (sender_.size() > comm::kMaxOperatorNameBytes) {  // NAME@ID must fit the wire's name (the leader's ack)
      params.addError("sender_name: '" + sender_ + "' has " + std::to_string(sender_.size()) + " characters, at most " +
                      std::to_string(comm::kMaxOperatorNameBytes));
    }
    std::string mission_file;
    params.loadOptional("mission_file", mission_file, "");
    onboard::OnboardSettings mission;
    if (!mission_file.empty() && loadOnboard(mission_file, params, mission)) {
      abort_repeats_ = mission.replan.abort.repeats;
      abort_period_s_ = mission.replan.abort.repeat_period_s;
      abort_resend_period_s_ = mission.replan.abort.resend_period_s;
      params.note("from mission_file: abort.repeats " + std::to_string(abort_repeats_) + ", abort.repeat_period_s " +
                  std::to_string(abort_period_s_) + ", abort.resend_period_s " + std::to_string(abort_resend_period_s_));
    } else if (mission_file.empty()) {
      params.load("abort_repeats", abort_repeats_, 1, 100);
      params.load("abort_repeat_period_s", abort_period_s_, 0.01, 10.0);
      params.load("abort_resend_period_s", abort_resend_period_s_, 0.1, 60.0);
      if (abort_resend_period_s_ < abort_period_s_) {
        params.addError("abort_resend_period_s: value " + std::to_string(abort_resend_period_s_) +
                        " must be >= abort_repeat_period_s " + std::to_string(abort_period_s_));
      }
    }
    if (params.ok()) sequence_ = commandSequenceStart(params, getPrivateNodeHandle().getNamespace());
    if (!params.ok()) {
      NODELET_ERROR_STREAM("OperatorInterface refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("OperatorInterface loaded:\n" << params.loaded());
    command_pub_ = nh.advertise<gesture_formation::FormationCommand>("formation_command_out", 20);
    command_sub_ = nh.subscribe("command_in", 20, &OperatorInterfaceNodelet::onCommand, this);
    service_ = nh.advertiseService("send_command", &OperatorInterfaceNodelet::onService, this);
    abort_pub_ = nh.advertise<gesture_formation::AbortCommand>("abort_out", 20);
    abort_service_ = nh.advertiseService("send_abort", &OperatorInterfaceNodelet::onAbort, this);
    abort_timer_ = nh.createTimer(ros::Duration(abort_period_s_), &OperatorInterfaceNodelet::repeatAbort, this);
    ack_pub_ = nh.advertise<gesture_formation::CommandAck>("command_ack_out", 20);
    ack_sub_ = nh.subscribe("command_ack_in", 50, &OperatorInterfaceNodelet::onAck, this);
    ack_timer_ = nh.createTimer(ros::Duration(0.5), &OperatorInterfaceNodelet::checkAcks, this);
    assistance_state_pub_ = nh.advertise<gesture_formation::AssistanceState>("assistance_state_out", 5, true);
    assistance_ack_pub_ = nh.advertise<gesture_formation::AssistanceState>("assistance_ack_out", 20);
    assistance_sub_ = nh.subscribe("assistance_in", 50, &OperatorInterfaceNodelet::onAssistance, this);
    assistance_service_ = nh.advertiseService("acknowledge_assistance", &OperatorInterfaceNodelet::onAcknowledge, this);
  }

  void onAssistance(const gesture_formation::AssistanceState::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (assistance_ && assistance_->phase == m->phase && assistance_->requested_at == m->requested_at) return;  // a copy
    assistance_ = *m;
    assistance_state_pub_.publish(*m);
    if (m->phase == m->PHASE_REQUESTED) {
      NODELET_WARN_STREAM("OperatorInterface: ASSISTANCE REQUESTED by the worker (" << m->requested_by << ") at "
                                                                                   << m->requested_at.toSec()
                                                                                   << " s: the formation holds its views; "
                                                                                      "acknowledge with tools/gf_command.py ack-assist");
    } else if (m->phase == m->PHASE_ACKNOWLEDGED) {
      NODELET_INFO_STREAM("OperatorInterface: assistance request of " << m->requested_at.toSec() << " s acknowledged by "
                                                                      << m->acknowledged_by << " (the leader confirms)");
    }
  }
  bool onAcknowledge(gesture_formation::AcknowledgeAssistance::Request&, gesture_formation::AcknowledgeAssistance::Response& res) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!assistance_ || assistance_->phase != gesture_formation::AssistanceState::PHASE_REQUESTED) {
      res.accepted = false;
      res.message = "no request for assistance is pending";
      return true;
    }
    gesture_formation::AssistanceState ack = *assistance_;
    ack.header.stamp = ros::Time::now();
    ack.phase = gesture_formation::AssistanceState::PHASE_ACKNOWLEDGED;
    ack.acknowledged_at = ack.header.stamp;
    ack.acknowledged_by = sender_;
    assistance_ack_pub_.publish(ack);
    res.accepted = true;
    res.message = "acknowledgement sent";
    res.requested_at = ack.requested_at;
    NODELET_INFO_STREAM("OperatorInterface: acknowledging the request for assistance of " << ack.requested_at.toSec() << " s");
    return true;
  }

  // The leader's acknowledgement: ours (the name the leader saw is ours, or ours@LINK_ID over LCM) or the worker's.
  void onAck(const gesture_formation::CommandAck::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    const bool ours = m->source == "operator" && (m->sender == sender_ || m->sender.rfind(sender_ + "@", 0) == 0);
    const auto sent = ours ? unacked_.find(m->sequence) : unacked_.end();
    if (sent != unacked_.end()) {
      NODELET_INFO_STREAM("OperatorInterface: command #" << m->sequence << " acknowledged by the leader "
                                                         << (ros::Time::now() - sent->second).toSec() << " s after sending: "
                                                         << m->outcome << " (parameters version " << m->params_version << ")");
      unacked_.erase(sent);
    } else if (m->source == "gesture") {
      NODELET_INFO_STREAM("OperatorInterface: the worker's gesture command " << m->sender << "#" << m->sequence << ": "
                                                                         << m->outcome << " (parameters version "
                                                                         << m->params_version << ")");
    }
    ack_pub_.publish(*m);
  }
  void checkAcks(const ros::TimerEvent&) {
    std::lock_guard<std::mutex> lock(mutex_);
    const ros::Time now = ros::Time::now();
    for (auto it = unacked_.begin(); it != unacked_.end();) {
      if ((now - it->second).toSec() <= kAckTimeoutS) {
        ++it;
        continue;
      }
      NODELET_WARN_STREAM("OperatorInterface: command #" << it->first << " not acknowledged by the leader within "
                                                         << kAckTimeoutS << " s (lost on the link, or no leader)");
      it = unacked_.erase(it);
    }
  }

  bool onAbort(gesture_formation::SendAbort::Request&, gesture_formation::SendAbort::Response& res) {
    std::lock_guard<std::mutex> lock(mutex_);
    abort_.source = gesture_formation::AbortCommand::SOURCE_OPERATOR;
    abort_.sender = sender_;
    abort_.sequence = ++sequence_;
    abort_.link_sender = -1;
    abort_schedule_ = comm::AbortCopySchedule(abort_repeats_, abort_resend_period_s_);
    abort_schedule_.start();
    sendAbortCopy();
    res.accepted = true;
    res.sequence = abort_.sequence;
    res.copies = abort_repeats_;
    res.message = "sent";
    NODELET_WARN_STREAM("OperatorInterface: abort #" << abort_.sequence << " sent (" << abort_repeats_ << " copies, "
                                                     << abort_period_s_ << " s apart, then one every "
                                                     << abort_resend_period_s_ << " s while this node runs)");
    return true;
  }
  // Mutex held. One copy when comm::AbortCopySchedule says so, stamped now (its age at each UAV is
  // this copy's): the burst's, then one every abort_resend_period_s for as long as this node runs
  // (docs/safety.md §2.8). The timer ticks every abort_repeat_period_s.
  void sendAbortCopy() {
    if (abort_.sequence == 0) return;  // no abort sent
    const ros::Time now = ros::Time::now();
    if (!abort_schedule_.due(now.toSec())) return;
    abort_.stamp = now;
    abort_pub_.publish(abort_);
  }
  void repeatAbort(const ros::TimerEvent&) {
    std::lock_guard<std::mutex> lock(mutex_);
    sendAbortCopy();
  }

  // Checks, numbers and publishes; returns an empty string or why it was refused.
  std::string forward(gesture_formation::FormationCommand msg, std::uint64_t* sequence) {
    std::lock_guard<std::mutex> lock(mutex_);
    msg.sender = sender_;
    msg.sequence = ++sequence_;
    msg.source = "operator";
    if (msg.kind.empty()) msg.kind = "increment";
    if (msg.header.stamp.isZero()) msg.header.stamp = ros::Time::now();  // keep the sender's (SimWorld: the request's time)
    const auto cmd = fromMsg(msg);
    if (!cmd) return cmd.reason();
    const auto uavs = cmd->target.resolve(uav_count_);
    if (!uavs) return "target: " + uavs.reason();
    command_pub_.publish(msg);
    unacked_[msg.sequence] = ros::Time::now();
    if (sequence != nullptr) *sequence = msg.sequence;
    NODELET_INFO_STREAM("OperatorInterface: sent " << msg.target << "." << msg.parameter << " " << msg.kind << " "
                                                   << msg.amount << " (#" << msg.sequence << ")");
    return "";
  }

  void onCommand(const gesture_formation::FormationCommand::ConstPtr& msg) {
    const std::string why = forward(*msg, nullptr);
    if (!why.empty()) NODELET_WARN_STREAM("OperatorInterface: command refused: " << why);
  }

  bool onService(gesture_formation::SendCommand::Request& req, gesture_formation::SendCommand::Response& res) {
    gesture_formation::FormationCommand msg;
    std::string target = req.target;
    if (!target.empty() && target.front() == '[') {
      // "[0, 2]": a list of UAV indices — digits separated by commas (and spaces), closed by ']';
      // anything else ("[-1]", "[1.5]", "[1, 2") is refused, not guessed at.
      msg.target = "list";
      const auto uavs = formation::parseUavList(target);
      if (!uavs) {
        res.accepted = false;
        res.message = "target '" + target + "': expected a list of UAV indices such as [0, 2]";
        NODELET_WARN_STREAM("OperatorInterface: command refused: " << res.message);
        return true;
      }
      msg.uavs = *uavs;
    } else {
      msg.target = target;
    }
    msg.parameter = req.parameter;
    msg.kind = req.kind;
    msg.amount = req.amount;
    const std::string why = forward(msg, &res.sequence);
    res.accepted = why.empty();
    res.message = why.empty() ? "sent" : why;
    return true;
  }

  std::mutex mutex_;
  std::string sender_;
  int uav_count_ = 0;
  std::uint64_t sequence_ = 0;
  int abort_repeats_ = 1;
  double abort_period_s_ = 0.2;
  double abort_resend_period_s_ = 1.0;
  comm::AbortCopySchedule abort_schedule_{1, 1.0};  ///< when the next copy of abort_ falls due
  gesture_formation::AbortCommand abort_;
  static constexpr double kAckTimeoutS = 5.0;  ///< a command of ours unacknowledged this long is reported
  std::map<std::uint64_t, ros::Time> unacked_;  ///< our commands sent and not yet acknowledged
  std::optional<gesture_formation::AssistanceState> assistance_;  ///< the leader's last assistance state
  ros::Publisher command_pub_, abort_pub_, ack_pub_, assistance_state_pub_, assistance_ack_pub_;
  ros::Subscriber command_sub_, ack_sub_, assistance_sub_;
  ros::ServiceServer service_, abort_service_, assistance_service_;
  ros::Timer abort_timer_, ack_timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::OperatorInterfaceNodelet, nodelet::Nodelet)

// OperatorInterface nodelet: the remote operator's way in (ground station side). Commands come
// as a service (send_command: gesture_formation/SendCommand; CLI tools/gf_command.py) or a topic
// (command_in: FormationCommand, e.g. a GUI or a scheduled mission); each is checked
// (target, parameter, kind, finite amount: formation core parsers), numbered (sender
// ~sender_name, sequence from the wall clock in µs, so a restart never reuses numbers) and
// published on formation_command_out (to the LcmBridge → the leader's FormationPlanner, which
// applies and clamps it).
// Parameters (required): ~sender_name, ~uav_count.
#include <mutex>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "conversions.hpp"
#include "gesture_formation/SendCommand.h"
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
    if (!params.ok()) {
      NODELET_ERROR_STREAM("OperatorInterface refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("OperatorInterface loaded:\n" << params.loaded());
    sequence_ = static_cast<std::uint64_t>(ros::WallTime::now().toNSec() / 1000);
    command_pub_ = nh.advertise<gesture_formation::FormationCommand>("formation_command_out", 20);
    command_sub_ = nh.subscribe("command_in", 20, &OperatorInterfaceNodelet::onCommand, this);
    service_ = nh.advertiseService("send_command", &OperatorInterfaceNodelet::onService, this);
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
      // "[0, 2]": a list of UAV indices
      msg.target = "list";
      std::string digits;
      for (const char c : target.substr(1)) {
        if (std::isdigit(static_cast<unsigned char>(c))) {
          digits += c;
        } else if (!digits.empty()) {
          msg.uavs.push_back(std::stoi(digits));
          digits.clear();
        }
      }
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
  ros::Publisher command_pub_;
  ros::Subscriber command_sub_;
  ros::ServiceServer service_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::OperatorInterfaceNodelet, nodelet::Nodelet)

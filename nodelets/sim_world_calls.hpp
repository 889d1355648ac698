#pragma once
// SimWorld's faults that act through other nodes (docs/ros.md "SimWorld"), called outside its lock
// (a service call waits for the other node):
// - faults.abort: the operator's abort through the ground's OperatorInterface (send_abort: it
//   numbers the command and has the ground station's LcmBridge send its copies to every UAV);
// - faults.leader_silence (with ~leadership): at its time the radio of the UAV acting as leader dies
//   for good — its LcmBridge is unloaded from its manager (/uav<k>/manager/unload_nodelet, as
//   ros_leader_handover does by hand); a silence of finite duration cannot be undone that way and
//   is refused at start (checkSilence).
// And the leadership log: every UAV's leadership_state as SimWorld received it, written to
// leadership.csv (t_s, uav, term, leader, acting) for the hand-over's figures
// (tools/ros_handover_report.py). Thread safety: log() and write() under SimWorld's lock.
#include <cmath>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <nodelet/NodeletUnload.h>
#include <ros/ros.h>

#include "gesture_formation/LeadershipState.h"
#include "gesture_formation/SendAbort.h"
#include "gesture_formation/sim/leader_handover.hpp"

namespace gesture_formation::nodelets {

/// What falls due in one SimWorld clock step.
struct SimWorldDue {
  bool abort = false;  ///< faults.abort
  int silence = -1;    ///< faults.leader_silence: the acting UAV to silence (−1: none)
  double t_s = 0.0;
};

class SimWorldCalls {
 public:
  /// The problem of a leader_silence SimWorld cannot run (empty: none or runnable).
  static std::string checkSilence(const std::optional<sim::LeaderSilence>& silence, bool leadership) {
    if (!silence) return "";
    if (!leadership) return "faults.leader_silence: needs leadership:=true (without it no other UAV can take over)";
    if (!silence->forGood()) {
      return "faults.leader_silence.duration_s: through ROS only for good (the acting UAV's LcmBridge is unloaded), got " +
             std::to_string(silence->duration_s);
    }
    return "";
  }

  void init(ros::NodeHandle& nh) { abort_client_ = nh.serviceClient<gesture_formation::SendAbort>("send_abort"); }

  void abort() {
    gesture_formation::SendAbort srv;
    const bool sent = abort_client_.call(srv) && srv.response.accepted;
    if (!sent) ROS_ERROR_STREAM("SimWorld: faults.abort: send_abort failed" << (abort_client_.exists() ? ": " : " (no service)") << srv.response.message);
    else ROS_WARN_STREAM("SimWorld: faults.abort: the operator's abort #" << srv.response.sequence << " sent (" << srv.response.copies << " copies)");
  }

  /// UAV k's radio dies for good: its LcmBridge leaves its manager.
  static void silence(int k, double t_s) {
    const std::string uav = "/uav" + std::to_string(k);
    nodelet::NodeletUnload srv;
    srv.request.name = uav + "/lcm_bridge";
    const bool done = ros::service::call(uav + "/manager/unload_nodelet", srv) && srv.response.success;
    if (done) ROS_WARN_STREAM("SimWorld: faults.leader_silence: UAV " << k << " (acting as leader) silent for good from t = " << t_s << " s: " << srv.request.name << " unloaded");
    else ROS_ERROR_STREAM("SimWorld: faults.leader_silence: could not unload " << srv.request.name);
  }

  void log(int k, const gesture_formation::LeadershipState& m) {
    rows_.push_back({m.header.stamp.toSec(), k, m.term, m.leader, m.acting != 0});
  }
  /// leadership.csv in `dir` (nothing without a row); false when it cannot be written.
  bool write(const std::string& dir) const {
    if (rows_.empty()) return true;
    std::ofstream f(dir + "/leadership.csv");
    f << "t_s,uav,term,leader,acting\n";
    for (const auto& r : rows_) f << r.t_s << ',' << r.uav << ',' << r.term << ',' << r.leader << ',' << (r.acting ? 1 : 0) << '\n';
    return static_cast<bool>(f);
  }

 private:
  struct Row {
    double t_s;
    int uav;
    std::uint32_t term;
    int leader;
    bool acting;
  };
  ros::ServiceClient abort_client_;
  std::vector<Row> rows_;
};

}  // namespace gesture_formation::nodelets

// Leadership nodelet: this UAV's formation::Leadership (docs/safety.md §1.2) — the election and
// leases of gfctl simulate's hand-over, over the real link: its messages go to the LcmBridge
// (leadership_out → LCM, signed, to every UAV) and come back from it (leadership_in: every UAV's,
// from its own sender only). Every heartbeat_period_s / 4 it ticks (heartbeats, candidacy, timeouts)
// and publishes leadership_state (LeadershipState, latched) whenever its view changes — term, leader,
// role, acting; a lapsed lease is published stamped with the lease's end. The UAV that acts does
// the leader's work (docs/ros.md "Leader hand-over").
//
// Topics: leadership_in (LeadershipMessage), worker_state_in (WorkerState) and detection_in (its
//   own Perception's WorkerDetection): the estimate age it stands and votes with is the fresher of
//   now − last_fused and now − its camera's last detection (none: +inf) → leadership_out
//   (LeadershipMessage), leadership_state (LeadershipState, latched).
// Parameters (all required): ~uav_index, and formation::leadershipFields() by their last key
//   segment: ~uav_count, ~heartbeat_period_s, ~lease_s, ~silence_limit_s, ~candidacy_stagger_s,
//   ~election_timeout_s, ~clock_drift, ~estimate_tolerance_s (config/ros/nodelets.yaml `leadership`).
//   Optional ~start: mission (term 1, UAV 0 leads), restart (a member that lost its term and vote:
//   quiet for the promise time, Leadership::Start::kRestart — e.g. a UAV whose computer rebooted
//   mid-mission) or auto (default): restart when this launch (~launch_id, the launch file's
//   $(anon ...)) already started it once — the manager respawned or the nodelet was reloaded — else
//   mission. Without the quiet restart a member could vote twice in one term.
#include <cmath>
#include <limits>
#include <mutex>
#include <optional>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "gesture_formation/WorkerDetection.h"
#include "gesture_formation/WorkerState.h"
#include "leadership_conversions.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class LeadershipNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ParamLoader params(getPrivateNodeHandle());
    formation::LeadershipConfig cfg;
    params.loadFields(formation::leadershipFields(), cfg);
    params.load("uav_index", uav_index_, 0, comm::kMaxUavIndex);
    std::string start;
    params.loadOptional("start", start, "auto");
    if (start != "auto" && start != "mission" && start != "restart") params.addError("start: must be mission, restart or auto, got '" + start + "'");
    if (params.ok()) {
      for (const auto& e : cfg.validate()) params.addError(e);  // the cross-field rules, naming the key
      if (uav_index_ >= cfg.uav_count) params.addError("uav_index: must be < uav_count (" + std::to_string(cfg.uav_count) + ")");
    }
    if (!params.ok()) {
      NODELET_ERROR_STREAM("Leadership refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("Leadership (UAV " << uav_index_ << ") loaded:\n" << params.loaded());
    lead_.emplace(cfg, uav_index_, startKind(getPrivateNodeHandle(), start), now());
    out_pub_ = nh.advertise<gesture_formation::LeadershipMessage>("leadership_out", 50);
    state_pub_ = nh.advertise<gesture_formation::LeadershipState>("leadership_state", 5, true);
    publishState(now());
    in_sub_ = nh.subscribe("leadership_in", 100, &LeadershipNodelet::onMessage, this);
    worker_sub_ = nh.subscribe<gesture_formation::WorkerState>(
        "worker_state_in", 5, [this](const gesture_formation::WorkerState::ConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          last_fused_s_ = m->last_fused.toSec();
        });
    // Its own camera's detections (every UAV with a camera): a follower that sees the worker
    // brings that freshness to an election (its estimator fuses this camera once it leads).
    detection_sub_ = nh.subscribe<gesture_formation::WorkerDetection>(
        "detection_in", 5, [this](const gesture_formation::WorkerDetection::ConstPtr& m) {
          if (!m->detected) return;
          std::lock_guard<std::mutex> lock(mutex_);
          last_seen_s_ = std::max(last_seen_s_.value_or(-1e300), m->header.stamp.toSec());
        });
    timer_ = nh.createTimer(ros::Duration(cfg.heartbeat_period_s / 4.0), [this](const ros::TimerEvent&) {
      std::lock_guard<std::mutex> lock(mutex_);
      const double t = now();
      send(lead_->tick(t, estimateAge(t)));
      update(t);
    });
  }

  /// ~start / ~launch_id (see the file comment); marks this launch as started.
  formation::Leadership::Start startKind(ros::NodeHandle& pnh, const std::string& start) {
    std::string launch_id, started_in;
    pnh.param<std::string>("launch_id", launch_id, "");
    pnh.param<std::string>("started_in_launch", started_in, "");
    const bool again = start == "restart" || (start == "auto" && !launch_id.empty() && started_in == launch_id);
    if (!launch_id.empty()) pnh.setParam("started_in_launch", launch_id);
    NODELET_INFO_STREAM("Leadership UAV " << uav_index_ << ": " << (again ? "restart: quiet for the promise time" : "mission start"));
    return again ? formation::Leadership::Start::kRestart : formation::Leadership::Start::kMissionStart;
  }

  static double now() { return ros::Time::now().toSec(); }
  /// The freshest worker evidence this UAV would lead with: its worker state's last fusion or its
  /// own camera's last detection (docs/safety.md §1.2).
  double estimateAge(double t) const {
    double age = std::numeric_limits<double>::infinity();
    if (last_fused_s_) age = std::max(0.0, t - *last_fused_s_);
    if (last_seen_s_) age = std::min(age, std::max(0.0, t - *last_seen_s_));
    return age;
  }

  void onMessage(const gesture_formation::LeadershipMessage::ConstPtr& msg) {
    auto m = fromMsg(*msg);
    if (!m) {
      NODELET_WARN_STREAM_THROTTLE(1.0, "Leadership: message dropped: " << m.reason());
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (m->from == uav_index_) return;  // its own, echoed
    const double t = now();
    send(lead_->receive(t, *m, estimateAge(t)));
    update(t);
  }

  void send(const std::vector<formation::LeadershipMessage>& out) {
    for (const auto& m : out) out_pub_.publish(toMsg(m));
  }

  /// Publishes the state when the view changed; a lapsed lease is stamped with its end (the end
  /// known while it acted: a leader deposed by a newer term has none left, it stops now). While it
  /// acts, a one-shot timer at the lease's end publishes the stop then — not at the next tick, up to
  /// a quarter heartbeat later, while its successor may already act.
  void update(double t) {
    const bool acting = lead_->acting(t);
    if (acting) armLeaseEnd(lead_->leaseUntil(), t);
    if (acting == acting_ && lead_->term() == term_ && lead_->leader() == leader_ && lead_->role() == role_) return;
    const double stamp = (acting_ && !acting && lease_end_ <= t) ? lease_end_ : t;
    if (acting != acting_) {
      NODELET_WARN_STREAM("Leadership UAV " << uav_index_ << ": " << (acting ? "acts as leader" : "no longer acts")
                                            << " (term " << lead_->term() << ", t = " << stamp << " s)");
    }
    publishState(stamp);
  }
  void armLeaseEnd(double lease_until, double t) {
    if (lease_until == lease_end_ && lease_timer_.isValid()) return;
    lease_end_ = lease_until;
    if (!std::isfinite(lease_until)) return;
    lease_timer_ = getNodeHandle().createTimer(
        ros::Duration(std::max(lease_until - t, 1e-4) + 1e-4),
        [this](const ros::TimerEvent&) {
          std::lock_guard<std::mutex> lock(mutex_);
          update(now());
        },
        true);
  }
  void publishState(double stamp) {
    acting_ = lead_->acting(stamp);
    term_ = lead_->term();
    leader_ = lead_->leader();
    role_ = lead_->role();
    state_pub_.publish(toStateMsg(*lead_, acting_, ros::Time(std::max(stamp, 0.0))));
  }

  std::mutex mutex_;
  int uav_index_ = 0;
  std::optional<formation::Leadership> lead_;
  std::optional<double> last_fused_s_;  ///< the last worker state's last fusion (none: no estimate)
  std::optional<double> last_seen_s_;   ///< its own camera's last detection of the worker (none: never)
  bool acting_ = false;
  double lease_end_ = -std::numeric_limits<double>::infinity();  ///< the lease's end while it acted
  ros::Timer lease_timer_;                                          ///< one-shot at lease_end_
  std::uint32_t term_ = 0;
  int leader_ = -2;
  formation::LeadershipRole role_ = formation::LeadershipRole::kFollower;
  ros::Publisher out_pub_, state_pub_;
  ros::Subscriber in_sub_, worker_sub_, detection_sub_;
  ros::Timer timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::LeadershipNodelet, nodelet::Nodelet)

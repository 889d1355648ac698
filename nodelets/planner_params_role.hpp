#pragma once
// The FormationPlanner's parameter role on ROS (onboard::ParamsOwnership; docs/safety.md §1.2, §2.9,
// §2.10): the owner's — the leader by index, or with ~leadership the UAV acting as leader — commands
// in (formation_command_in), parameters out (formation_params_out, latched, re-sent at
// ~params_rate_hz), an acknowledgement per command handled (command_ack_out) and the assistance latch
// (assistance_in → assistance_state_out); every other UAV's parameters in (formation_params_in); with
// ~leadership its own LeadershipState (leadership_state_in). A leader whose lease lapses keeps the
// commands that reach it meanwhile and applies them if it resumes in the same term within
// max_command_age_s of their sending (ParamsOwnership::keepsCommand), and the assistance requests and
// acknowledgements that reached it likewise. The leader by index (no ~leadership) keeps its parameters,
// their version, the ids it applied and the assistance latch in ~params_state_file (optional; default
// $ROS_HOME/gesture_formation/formation_params_uav0) after every applied command and latch change,
// named by the ROS run and the launch (/run_id, ~launch_id — a master kept up across missions keeps its
// run id): restarted in the same launch (a crashed or reloaded nodelet, a respawned manager) it
// continues from them instead of the config's — whose version-0 parameters the followers would
// otherwise take, losing every adjustment of the mission and a pending request for assistance
// (docs/safety.md §2.4). A record of another run, or one that does not fit the formation, is not used
// (WARN naming why). Every callback takes the nodelet's mutex.
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <ros/ros.h>

#include "conversions.hpp"
#include "gesture_formation/LeadershipState.h"
#include "gesture_formation/comm/sequence_store.hpp"
#include "gesture_formation/onboard/formation_params_role.hpp"

namespace gesture_formation::nodelets {

/// Writes the newest text handed to it, in order, on a thread of its own: the durable write (two
/// fsyncs, up to tens of milliseconds on an SD card) stays out of the planner's lock. What is pending
/// when it is destroyed is written first.
class LatestFileWriter {
 public:
  ~LatestFileWriter() {
    {
      std::lock_guard<std::mutex> lock(m_);
      stop_ = true;
    }
    cv_.notify_one();
    if (thread_.joinable()) thread_.join();
  }
  void post(const std::string& path, std::string text) {
    {
      std::lock_guard<std::mutex> lock(m_);
      pending_ = std::make_pair(path, std::move(text));
      if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
    }
    cv_.notify_one();
  }

 private:
  void run() {
    std::unique_lock<std::mutex> lock(m_);
    for (;;) {
      cv_.wait(lock, [this] { return stop_ || pending_; });
      if (!pending_) return;  // stopped, nothing left
      const auto [path, text] = std::move(*pending_);
      pending_.reset();
      lock.unlock();
      const auto w = comm::writeStateFile(path, text);
      if (!w) ROS_WARN_STREAM_THROTTLE(5.0, "FormationPlanner: parameters not kept for a restart: " << w.reason());
      lock.lock();
    }
  }
  std::mutex m_;
  std::condition_variable cv_;
  std::optional<std::pair<std::string, std::string>> pending_;
  bool stop_ = false;
  std::thread thread_;
};

class PlannerParamsRole {
 public:
  /// Creates the ownership and the topics of this UAV's role. `mutex` must outlive this.
  void setUp(ros::NodeHandle& nh, const ros::NodeHandle& pnh, std::mutex& mutex, const formation::FormationConfig& formation, int uav_index,
             bool leadership, double params_rate_hz, double max_command_age_s, const std::string& world_frame) {
    mutex_ = &mutex;
    uav_index_ = uav_index;
    max_command_age_s_ = max_command_age_s;
    world_frame_ = world_frame;
    own_.emplace(formation, uav_index, leadership);  // the config was validated by its loader
    if (uav_index == formation::kLeader && !leadership) resumeRecord(pnh);
    if (uav_index == formation::kLeader || leadership) {
      params_pub_ = nh.advertise<gesture_formation::FormationParams>("formation_params_out", 5, true);
      command_sub_ = nh.subscribe("formation_command_in", 20, &PlannerParamsRole::onCommand, this);
      ack_pub_ = nh.advertise<gesture_formation::CommandAck>("command_ack_out", 20);
      assistance_pub_ = nh.advertise<gesture_formation::AssistanceState>("assistance_state_out", 5, true);
      if (own_->owns()) assistance_pub_.publish(toMsg(own_->role().assistance().state(), ros::Time::now()));
      assistance_sub_ = nh.subscribe("assistance_in", 20, &PlannerParamsRole::onAssistance, this);
      params_timer_ = nh.createTimer(ros::Duration(1.0 / params_rate_hz), [this](const ros::TimerEvent&) {
        std::lock_guard<std::mutex> lock(*mutex_);
        if (own_->owns()) publishParams();
      });
    }
    if (uav_index != formation::kLeader || leadership) params_sub_ = nh.subscribe("formation_params_in", 5, &PlannerParamsRole::onParams, this);
    if (leadership) leadership_sub_ = nh.subscribe("leadership_state_in", 5, &PlannerParamsRole::onLeadership, this);
  }

  /// The ownership (the caller holds the mutex).
  const onboard::ParamsOwnership& own() const { return *own_; }

 private:
  // This UAV's leadership view (~leadership): starting to act, it takes the parameters over; resuming
  // in the same term, it applies the commands kept while its lease had lapsed.
  void onLeadership(const gesture_formation::LeadershipState::ConstPtr& msg) {
    if (msg->uav_index != uav_index_) return;
    std::lock_guard<std::mutex> lock(*mutex_);
    using Change = onboard::ParamsOwnership::Change;
    const auto change = own_->setActing(msg->acting, msg->header.stamp.toSec(), msg->leader, msg->term);  // also the slot flown
    if (change == Change::kResumed) {
      const double now = ros::Time::now().toSec();
      std::size_t applied = 0, commands = 0;
      // In the order they arrived, as gfctl simulate: a request for assistance before a gesture
      // command holds against it, an acknowledgement before it lets it through.
      for (const auto& k : kept_) {
        if (k.assistance) {
          handleAssistance(*k.assistance);
          continue;
        }
        ++commands;
        if (now - k.command->header.stamp.toSec() > max_command_age_s_) continue;
        applyCommand(*k.command);
        ++applied;
      }
      if (commands > 0) {
        ROS_WARN_STREAM("FormationPlanner UAV " << uav_index_ << ": acts as leader again (term " << msg->term << "): " << applied
                                                << " of " << commands << " commands kept since its lease lapsed applied");
      }
    }
    const bool keeping = own_->keepsCommand(ros::Time::now().toSec());  // lapsed in the term it acted in
    if (change == Change::kResumed || change == Change::kStarted || (!own_->owns() && !keeping)) {
      // applied above, or its predecessor's, or a newer term's (they may be another leader's)
      kept_.clear();
    }
    if (change == Change::kNone || change == Change::kResumed) return;
    const bool started = change == Change::kStarted;
    ROS_WARN_STREAM("FormationPlanner UAV " << uav_index_ << (started ? ": acts as leader (term " : ": no longer acts as leader (term ")
                                            << msg->term
                                            << (started ? ") from t = " + std::to_string(own_->tookOverS()) + " s: parameters version " +
                                                              std::to_string(own_->version()) + " taken over; commands sent from now on applied"
                                                        : "): parameters from the leader from now on; commands kept until it resumes"));
    if (!started) return;
    publishParams();
    assistance_pub_.publish(toMsg(own_->role().assistance().state(), ros::Time::now()));
  }

  void onParams(const gesture_formation::FormationParams::ConstPtr& msg) {
    auto p = fromMsg(*msg);
    std::lock_guard<std::mutex> lock(*mutex_);
    const auto r = p ? own_->receive(*p, msg->version) : common::Result<bool>::fail(p.reason());
    if (!r) ROS_WARN_STREAM_THROTTLE(1.0, "FormationPlanner: formation parameters dropped: " << r.reason());
  }

  void onCommand(const gesture_formation::FormationCommand::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(*mutex_);
    const double stamp = msg->header.stamp.toSec();
    if (own_->keepsCommand(stamp)) kept_.push_back(Kept{msg, nullptr});  // its lease lapsed: applied if it resumes in this term
    if (own_->takesCommand(stamp)) applyCommand(*msg);
  }

  // The leader by index: its record of this run, if any, instead of the config's parameters.
  void resumeRecord(const ros::NodeHandle& pnh) {
    pnh.param<std::string>("params_state_file", state_file_, comm::defaultStateDirectory() + "/formation_params_uav0");
    std::string launch_id;
    pnh.param<std::string>("launch_id", launch_id, "");
    if (!ros::param::get("/run_id", run_) || run_.empty()) {
      ROS_WARN_STREAM("FormationPlanner: no /run_id: the parameters are not kept for a restart");
      run_.clear();
      return;
    }
    if (!launch_id.empty()) run_ += "@" + launch_id;
    for (char& c : run_) {
      if (c < 0x21 || c > 0x7e) c = '_';  // one word of the record's line
    }
    comm::ensureStateDirectory(comm::defaultStateDirectory(), {state_file_});
    bool exists = false;
    const auto text = comm::readStateFile(state_file_, exists);
    if (!exists && text) return;  // the first start of this machine
    const auto record = text ? onboard::parseParamsRecord(*text) : common::Result<onboard::ParamsRecord>::fail(text.reason());
    if (!record) {
      ROS_WARN_STREAM("FormationPlanner: " << state_file_ << " not used (" << record.reason() << "): the config's parameters");
    } else if (record->run != run_) {
      ROS_WARN_STREAM("FormationPlanner: the kept parameters are of another run or launch (" << record->run << ", this is " << run_
                                                                                      << "): the config's parameters");
    } else if (const auto resumed = own_->resume(*record); !resumed) {
      ROS_WARN_STREAM("FormationPlanner: the kept parameters of this run not used (" << resumed.reason() << "): the config's parameters");
    } else {
      ROS_WARN_STREAM("FormationPlanner: restarted in run " << run_ << ": continues from parameters version "
                                                            << own_->version() << " (" << state_file_ << ")");
    }
  }
  void keepRecord() {
    if (!run_.empty()) writer_.post(state_file_, onboard::formatParamsRecord(own_->role().record(run_)));
  }

  void applyCommand(const gesture_formation::FormationCommand& msg) {
    const std::uint64_t before = own_->version();
    const auto& r = own_->role().apply(fromMsg(msg), describe(msg), msg.source, msg.header.stamp.toSec());
    if (own_->version() != before) keepRecord();  // the leader by index only (run_ empty otherwise)
    ROS_INFO_STREAM("FormationPlanner: command " << r.text << " → " << r.outcome);
    publishParams();
    ack_pub_.publish(toAck(msg, r.status, r.outcome, own_->version(), ros::Time::now()));  // to the operator
  }

  // The worker's request (GestureCommander) or the operator's acknowledgement (over LCM) → the latch.
  void onAssistance(const gesture_formation::AssistanceState::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(*mutex_);
    if (own_->keepsCommand(ros::Time::now().toSec())) kept_.push_back(Kept{nullptr, m});  // its lease lapsed: on resuming
    if (own_->owns()) handleAssistance(*m);  // ~leadership: the acting UAV's latch
  }
  void handleAssistance(const gesture_formation::AssistanceState& m) {
    auto state = fromMsg(m);
    auto& latch = own_->role().assistance();
    if (!state || !latch.receive(*state)) return;
    keepRecord();  // a pending request survives a restart
    ROS_WARN_STREAM("FormationPlanner: assistance " << formation::toString(latch.state().phase) << " (requested at "
                                                    << latch.state().requested_s << " s by " << latch.state().requested_by
                                                    << "; the worker's gestures are refused while requested)");
    assistance_pub_.publish(toMsg(latch.state(), ros::Time::now()));
  }

  void publishParams() {
    auto m = toMsg(own_->role(), ros::Time::now(), world_frame_);
    m.version = own_->version();
    params_pub_.publish(m);
  }

  std::mutex* mutex_ = nullptr;
  int uav_index_ = 0;
  std::string state_file_, run_;  ///< the leader by index: where its record is kept, the ROS run (empty: none kept)
  LatestFileWriter writer_;        ///< the record's writes, off the planner's lock
  double max_command_age_s_ = 5.0;
  std::string world_frame_;
  std::optional<onboard::ParamsOwnership> own_;
  /// A command or an assistance message that reached it while its lease lapsed (one of the two set).
  struct Kept {
    gesture_formation::FormationCommand::ConstPtr command;
    gesture_formation::AssistanceState::ConstPtr assistance;
  };
  std::vector<Kept> kept_;  ///< in the order they arrived
  ros::Publisher params_pub_, ack_pub_, assistance_pub_;
  ros::Subscriber command_sub_, params_sub_, assistance_sub_, leadership_sub_;
  ros::Timer params_timer_;
};

}  // namespace gesture_formation::nodelets

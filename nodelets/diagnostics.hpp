#pragma once
// A nodelet's health on /diagnostics (diagnostic_msgs/DiagnosticArray, one array per report,
// wall-clock period so that it reports also while sim time stands still): the nodelet gives a
// function that builds its statuses from the counters it keeps; Health makes one status.
#include <functional>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>

#include "gesture_formation/comm/rejection_report.hpp"

namespace gesture_formation::nodelets {

/// \brief One status: OK / WARN / ERROR with a message and named values.
class Health {
 public:
  Health(std::string name, std::string hardware_id) {
    status_.name = std::move(name);
    status_.hardware_id = std::move(hardware_id);
    status_.level = diagnostic_msgs::DiagnosticStatus::OK;
    status_.message = "ok";
  }
  /// \brief Raises the level to `level` with `message`; a condition no more severe than the
  /// current one changes nothing (the first of the most severe conditions is the message).
  Health& raise(std::uint8_t level, const std::string& message) {
    if (level > status_.level) {
      status_.level = level;
      status_.message = message;
    }
    return *this;
  }
  Health& warn(bool condition, const std::string& message) {
    return condition ? raise(diagnostic_msgs::DiagnosticStatus::WARN, message) : *this;
  }
  Health& error(bool condition, const std::string& message) {
    return condition ? raise(diagnostic_msgs::DiagnosticStatus::ERROR, message) : *this;
  }
  template <class T>
  Health& value(const std::string& key, const T& v) {
    diagnostic_msgs::KeyValue kv;
    kv.key = key;
    if constexpr (std::is_same_v<T, std::string> || std::is_same_v<T, const char*>) kv.value = v;
    else kv.value = std::to_string(v);
    status_.values.push_back(kv);
    return *this;
  }
  const diagnostic_msgs::DiagnosticStatus& status() const { return status_; }

 private:
  diagnostic_msgs::DiagnosticStatus status_;
};

/// \brief Publishes `collect(since_s)` on /diagnostics every `period_s` of wall time; since_s:
/// wall seconds since the previous report (period_s for the first), for rates.
class DiagnosticsPublisher {
 public:
  using Collect = std::function<std::vector<diagnostic_msgs::DiagnosticStatus>(double since_s)>;
  void start(ros::NodeHandle& nh, double period_s, Collect collect) {
    collect_ = std::move(collect);
    pub_ = nh.advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 10);
    timer_ = nh.createWallTimer(ros::WallDuration(period_s), [this, period_s](const ros::WallTimerEvent&) {
      const ros::WallTime now = ros::WallTime::now();
      const double since_s = last_.isZero() ? period_s : (now - last_).toSec();
      last_ = now;
      diagnostic_msgs::DiagnosticArray array;
      array.header.stamp = ros::Time::now();
      array.status = collect_(since_s);
      pub_.publish(array);
    });
  }
  void stop() { timer_.stop(); }

 private:
  Collect collect_;
  ros::WallTime last_;
  ros::Publisher pub_;
  ros::WallTimer timer_;
};

/// A link's diagnostic entry (comm::RejectionReport) as a DiagnosticStatus (hardware "lcm").
inline diagnostic_msgs::DiagnosticStatus toStatus(const comm::DiagnosticEntry& e) {
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

}  // namespace gesture_formation::nodelets

#include "gesture_formation/sim/abort_drill.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "gesture_formation/common/csv.hpp"

namespace gesture_formation::sim {

void readAbortEvent(common::ConfigReader& r, const std::string& key, std::optional<AbortEvent>& out) {
  if (!r.has(key)) return;
  const std::string k = key + ".";
  AbortEvent e;
  if (!r.has(k + "t_s")) r.addError(k + "t_s", "missing (required)");
  r.readDouble(k + "t_s", e.t_s, common::Range::nonNegative());
  std::string source = "operator";
  r.readString(k + "source", source, {"operator", "gesture"});
  e.source = source == "gesture" ? planning::AbortSource::kGesture : planning::AbortSource::kOperator;
  out = e;
}

planning::AbortCommand AbortSender::command() const {
  planning::AbortCommand c;
  c.id = formation::CommandId{"operator-abort", 1};
  c.source = planning::AbortSource::kOperator;
  c.sent_s = event_ ? event_->t_s : 0.0;
  return c;
}

double AbortSender::dueAt(int k) const {
  if (k < repeats_) return event_->t_s + k * period_s_;
  return event_->t_s + (repeats_ - 1) * period_s_ + (k - repeats_ + 1) * resend_period_s_;
}

std::vector<planning::AbortCommand> AbortSender::due(double t_s) {
  std::vector<planning::AbortCommand> out;
  if (!event_ || event_->source != planning::AbortSource::kOperator) return out;
  while (dueAt(sent_) <= t_s + 1e-9) {
    planning::AbortCommand c = command();
    c.sent_s = dueAt(sent_);  // each copy is stamped when it is sent
    out.push_back(c);
    ++sent_;
  }
  return out;
}

double AbortSummary::time_to_settle_max_s() const {
  double worst = 0.0;
  for (const auto& u : uavs) {
    if (!std::isfinite(u.settled_s)) return std::numeric_limits<double>::quiet_NaN();
    worst = std::max(worst, u.settled_s - issued_s);
  }
  return worst;
}

AbortRecorder::AbortRecorder(const AbortEvent& event, int uav_count,
                             std::function<double(const Eigen::Vector3d&)> obstacle_distance)
    : obstacle_distance_(std::move(obstacle_distance)) {
  summary_.issued_s = event.t_s;
  summary_.source = planning::toString(event.source);
  summary_.uavs.resize(static_cast<std::size_t>(std::max(0, uav_count)));
}

void AbortRecorder::accepted(int uav, double t_s) {
  UavAbortRecord& u = summary_.uavs.at(static_cast<std::size_t>(uav));
  if (!std::isfinite(u.accepted_s)) u.accepted_s = t_s;
}

void AbortRecorder::phase(int uav, double t_s, planning::AbortPhase phase) {
  UavAbortRecord& u = summary_.uavs.at(static_cast<std::size_t>(uav));
  u.phase = planning::toString(phase);
  if (phase != planning::AbortPhase::kRetreat && phase != planning::AbortPhase::kNoGoal &&
      !std::isfinite(u.retreat_reached_s)) {
    u.retreat_reached_s = t_s;
  }
  if (planning::settled(phase) && !std::isfinite(u.settled_s)) u.settled_s = t_s;
}

void AbortRecorder::sample(double t_s, const std::vector<Eigen::Vector3d>& p, const Eigen::Vector3d& worker_world) {
  if (t_s < summary_.issued_s) return;
  const std::size_t n = std::min(p.size(), summary_.uavs.size());
  for (std::size_t i = 0; i < n; ++i) {
    UavAbortRecord& u = summary_.uavs[i];
    u.min_worker_distance_m = std::min(u.min_worker_distance_m, (p[i] - worker_world).norm());
    u.min_obstacle_distance_m = std::min(u.min_obstacle_distance_m, obstacle_distance_(p[i]));
    for (std::size_t j = 0; j < n; ++j) {
      if (j != i) u.min_uav_distance_m = std::min(u.min_uav_distance_m, (p[i] - p[j]).norm());
    }
  }
}

std::string abortJson(const AbortSummary& s, int indent) {
  const std::string in(static_cast<std::size_t>(indent), ' '), in2 = in + "  ", in3 = in2 + "  ";
  const auto num = [](double v) { return std::isfinite(v) ? common::formatDouble(v) : std::string("null"); };
  std::ostringstream os;
  os << "{\n" << in2 << "\"issued_s\": " << num(s.issued_s) << ",\n";
  os << in2 << "\"source\": \"" << s.source << "\",\n";
  os << in2 << "\"time_to_settle_max_s\": " << num(s.time_to_settle_max_s()) << ",\n";
  os << in2 << "\"uavs\": [";
  for (std::size_t i = 0; i < s.uavs.size(); ++i) {
    const UavAbortRecord& u = s.uavs[i];
    os << (i ? ",\n" : "\n") << in3 << "{\"uav\": " << i << ", \"accepted_s\": " << num(u.accepted_s)
       << ", \"retreat_reached_s\": " << num(u.retreat_reached_s) << ", \"settled_s\": " << num(u.settled_s)
       << ", \"phase\": \"" << u.phase << "\", \"min_worker_distance_m\": " << num(u.min_worker_distance_m)
       << ", \"min_obstacle_distance_m\": " << num(u.min_obstacle_distance_m)
       << ", \"min_uav_distance_m\": " << num(u.min_uav_distance_m) << "}";
  }
  os << "\n" << in2 << "]\n" << in << "}";
  return os.str();
}

}  // namespace gesture_formation::sim

#include "gesture_formation/sim/leader_handover.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "gesture_formation/common/csv.hpp"

namespace gesture_formation::sim {

using common::Range;
using formation::LeadershipMessage;

void readLeaderSilence(common::ConfigReader& r, const std::string& key, std::optional<LeaderSilence>& out) {
  if (!r.has(key)) return;
  const std::string k = key + ".";
  LeaderSilence s;
  if (!r.has(k + "t_s")) r.addError(k + "t_s", "missing (required: when the leader goes silent)");
  r.readDouble(k + "t_s", s.t_s, Range::nonNegative());
  if (r.has(k + "duration_s")) {
    double d = 0.0;
    r.readDouble(k + "duration_s", d, Range::positive());
    if (std::isfinite(d) && d > 0.0) s.duration_s = d;
  }
  out = s;
}

void readLeadership(common::ConfigReader& r, const std::string& mission_prefix, int uav_count,
                    formation::LeadershipConfig& out) {
  out.uav_count = uav_count;
  formation::leadershipFields().readFields(r, mission_prefix, out);
  if (out.uav_count != uav_count) {
    r.addError(mission_prefix + "leadership.uav_count",
               std::to_string(out.uav_count) + " differs from the mission's " + std::to_string(uav_count) +
                   " UAVs (leave it out: the mission's count is used)");
    out.uav_count = uav_count;
  }
  if (!formation::leadershipFields().rangeProblems(out).empty()) return;  // readFields reported them
  for (const auto& e : out.problems()) r.addError(mission_prefix + e.key, e.message);
}

// --------------------------------------------------------------------------------------

LeadershipNet::LeadershipNet(const formation::LeadershipConfig& config, const LinkConfig& link,
                             std::vector<std::mt19937_64> rngs, double step_s) {
  const int n = config.uav_count;
  const double t0 = -kWarmupS;
  for (int i = 0; i < n; ++i) {
    members_.push_back(std::make_unique<formation::Leadership>(config, i, formation::Leadership::Start::kMissionStart, t0));
  }
  for (auto& rng : rngs) links_.push_back(std::make_unique<Link<LeadershipMessage>>(link, rng));
  const std::vector<double> ages(static_cast<std::size_t>(n), std::numeric_limits<double>::infinity());
  const std::vector<bool> up(static_cast<std::size_t>(n), true);
  const long steps = std::lround(kWarmupS / step_s);
  for (long k = 0; k < steps; ++k) step(t0 + static_cast<double>(k) * step_s, ages, up);
}

Link<LeadershipMessage>& LeadershipNet::link(int from, int to) {
  const int n = count();
  return *links_[static_cast<std::size_t>(from * (n - 1) + (to < from ? to : to - 1))];
}

void LeadershipNet::send(double t_s, int from, const std::vector<LeadershipMessage>& out,
                         const std::vector<bool>& radio_up) {
  if (!radio_up[static_cast<std::size_t>(from)]) return;  // a dead radio sends nothing
  for (const LeadershipMessage& m : out) {
    for (int to = 0; to < count(); ++to) {
      if (to != from && (m.to == LeadershipMessage::kBroadcast || m.to == to)) link(from, to).send(t_s, m);
    }
  }
}

void LeadershipNet::step(double t_s, const std::vector<double>& estimate_age_s, const std::vector<bool>& radio_up) {
  const int n = count();
  for (int to = 0; to < n; ++to) {
    for (int from = 0; from < n; ++from) {
      if (from == to) continue;
      for (const LeadershipMessage& m : link(from, to).receive(t_s)) {
        if (!radio_up[static_cast<std::size_t>(to)]) continue;  // arrives at a dead radio: lost
        send(t_s, to, members_[static_cast<std::size_t>(to)]->receive(t_s, m, estimate_age_s[static_cast<std::size_t>(to)]),
             radio_up);
      }
    }
  }
  for (int i = 0; i < n; ++i) {
    send(t_s, i, members_[static_cast<std::size_t>(i)]->tick(t_s, estimate_age_s[static_cast<std::size_t>(i)]), radio_up);
  }
}

LinkCounters LeadershipNet::counters() const {
  LinkCounters c;
  for (const auto& l : links_) {
    const LinkCounters k = l->counters();
    c.sent += k.sent;
    c.lost += k.lost;
    c.duplicated += k.duplicated;
    c.reordered += k.reordered;
    c.delivered += k.delivered;
  }
  return c;
}

// --------------------------------------------------------------------------------------

void HandoverRecorder::sample(double t_s, const std::vector<bool>& acting) {
  int who = -1, count = 0;
  for (std::size_t i = 0; i < acting.size(); ++i) {
    if (!acting[i]) continue;
    ++count;
    if (who < 0) who = static_cast<int>(i);
  }
  s_.max_acting = std::max(s_.max_acting, count);
  if (count > 1) ++s_.steps_two_acting;
  if (s_.silenced_uav >= 0) {
    if (acting[static_cast<std::size_t>(s_.silenced_uav)]) s_.silenced_last_acting_s = t_s;
    if (s_.new_leader < 0 && t_s >= s_.silent_from_s && who >= 0 && who != s_.silenced_uav) {
      s_.new_leader = who;
      s_.new_leader_s = t_s;
      s_.handover_s = t_s - s_.silent_from_s;
    }
  }
  if (who != current_) {
    if (!s_.leaders.empty()) s_.leaders.back().to_s = t_s;
    s_.leaders.push_back(LeaderInterval{t_s, t_s, who});
    current_ = who;
  }
  acting_ = acting;
}

void HandoverRecorder::silenced(int uav, double t_s, const LeaderSilence& silence) {
  s_.silenced_uav = uav;
  s_.silent_from_s = t_s;
  s_.silent_to_s = silence.forGood() ? std::numeric_limits<double>::infinity() : silence.t_s + silence.duration_s;
}

HandoverSummary HandoverRecorder::finish(double t_end_s, const std::vector<std::pair<double, bool>>& requests,
                                         const LeadershipNet& net) const {
  HandoverSummary s = s_;
  if (!s.leaders.empty()) s.leaders.back().to_s = t_end_s;
  for (int i = 0; i < net.count(); ++i) s.elections_won += net.member(i).counters().elections_won;
  const LinkCounters c = net.counters();
  s.leadership_messages_sent = c.sent;
  s.leadership_messages_lost = c.lost;
  if (std::isfinite(s.new_leader_s)) {
    for (const auto& [sent_s, applied] : requests) {
      if (sent_s < s.new_leader_s) continue;
      ++s.requests_after;
      if (applied) ++s.requests_after_applied;
    }
  }
  return s;
}

std::string handoverJson(const HandoverSummary& s, int indent) {
  const std::string in(static_cast<std::size_t>(indent), ' '), in2 = in + "  ", in3 = in2 + "  ";
  const auto num = [](double v) { return std::isfinite(v) ? common::formatDouble(v) : std::string("null"); };
  std::ostringstream os;
  os << "{\n" << in2 << "\"max_acting\": " << s.max_acting << ",\n";
  os << in2 << "\"steps_two_acting\": " << s.steps_two_acting << ",\n";
  os << in2 << "\"elections_won\": " << s.elections_won << ",\n";
  os << in2 << "\"leadership_messages_sent\": " << s.leadership_messages_sent << ",\n";
  os << in2 << "\"leadership_messages_lost\": " << s.leadership_messages_lost << ",\n";
  os << in2 << "\"silenced_uav\": " << s.silenced_uav << ",\n";
  os << in2 << "\"silent_from_s\": " << num(s.silent_from_s) << ",\n";
  os << in2 << "\"silent_to_s\": "
     << (s.silent_to_s == std::numeric_limits<double>::infinity() ? std::string("\"for_good\"") : num(s.silent_to_s))
     << ",\n";
  os << in2 << "\"silenced_last_acting_s\": " << num(s.silenced_last_acting_s) << ",\n";
  os << in2 << "\"new_leader\": " << s.new_leader << ",\n";
  os << in2 << "\"new_leader_s\": " << num(s.new_leader_s) << ",\n";
  os << in2 << "\"handover_s\": " << num(s.handover_s) << ",\n";
  os << in2 << "\"requests_after\": " << s.requests_after << ",\n";
  os << in2 << "\"requests_after_applied\": " << s.requests_after_applied << ",\n";
  os << in2 << "\"leaders\": [";
  for (std::size_t i = 0; i < s.leaders.size(); ++i) {
    const LeaderInterval& l = s.leaders[i];
    os << (i ? ",\n" : "\n") << in3 << "{\"uav\": " << l.uav << ", \"from_s\": " << num(l.from_s)
       << ", \"to_s\": " << num(l.to_s) << "}";
  }
  os << "\n" << in2 << "]\n" << in << "}";
  return os.str();
}

}  // namespace gesture_formation::sim

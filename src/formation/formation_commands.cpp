#include "gesture_formation/formation/formation_commands.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "gesture_formation/common/format_number.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"

namespace gesture_formation::formation {

const char* parameterName(Parameter p) {
  switch (p) {
    case Parameter::kBeta: return "beta_deg";
    case Parameter::kGamma: return "gamma_deg";
    case Parameter::kDistance: return "distance_m";
  }
  return "?";
}

const char* toString(CommandSource s) { return s == CommandSource::kOperator ? "operator" : "gesture"; }

std::string CommandOutcome::describe() const {
  std::string text = toString(status);
  if (!reason.empty()) text += ": " + reason;
  for (const auto& c : changes) {
    if (c.clamped) text += " (clamped by " + c.clamp_rule + ")";
  }
  return text;
}

const char* toString(CommandStatus s) {
  switch (s) {
    case CommandStatus::kApplied: return "applied";
    case CommandStatus::kDuplicate: return "duplicate";
    case CommandStatus::kRejected: return "rejected";
  }
  return "?";
}

common::Result<std::vector<UavIndex>> CommandTarget::resolve(int uav_count) const {
  using R = common::Result<std::vector<UavIndex>>;
  std::vector<UavIndex> out;
  switch (group) {
    case TargetGroup::kLeader: out.push_back(kLeader); break;
    case TargetGroup::kFollowers:
      for (UavIndex u = 1; u < uav_count; ++u) out.push_back(u);
      if (out.empty()) return R::fail("target 'followers': the formation has no followers");
      break;
    case TargetGroup::kAll:
      for (UavIndex u = 0; u < uav_count; ++u) out.push_back(u);
      break;
    case TargetGroup::kList:
      if (uavs.empty()) return R::fail("empty list of target UAVs");
      for (const UavIndex u : uavs) {
        if (u < 0 || u >= uav_count) {
          return R::fail("unknown UAV " + std::to_string(u) + " (the formation has the leader and " +
                         std::to_string(uav_count - 1) + " followers)");
        }
        out.push_back(u);
      }
      std::sort(out.begin(), out.end());
      out.erase(std::unique(out.begin(), out.end()), out.end());
      break;
  }
  return R::ok(out);
}

std::string CommandTarget::describe() const {
  switch (group) {
    case TargetGroup::kLeader: return "leader";
    case TargetGroup::kFollowers: return "followers";
    case TargetGroup::kAll: return "all";
    case TargetGroup::kList: break;
  }
  if (uavs.size() == 1 && uavs[0] >= 1) return "follower" + std::to_string(uavs[0]);
  std::string s = "uavs{";
  for (std::size_t i = 0; i < uavs.size(); ++i) s += (i ? "," : "") + uavLabel(uavs[i]);
  return s + "}";
}

common::Result<std::pair<CommandTarget, Parameter>> parseParameterPath(const std::string& path) {
  using R = common::Result<std::pair<CommandTarget, Parameter>>;
  const auto dot = path.find('.');
  if (dot == std::string::npos) {
    return R::fail("parameter '" + path + "' must be <leader|followers|all|followerN>.<beta_deg|gamma_deg|distance_m>");
  }
  const std::string t = path.substr(0, dot);
  const std::string p = path.substr(dot + 1);
  Parameter parameter;
  if (p == "beta_deg") {
    parameter = Parameter::kBeta;
  } else if (p == "gamma_deg") {
    parameter = Parameter::kGamma;
  } else if (p == "distance_m") {
    parameter = Parameter::kDistance;
  } else {
    return R::fail("unknown parameter '" + p + "' in '" + path + "' (beta_deg, gamma_deg or distance_m)");
  }
  CommandTarget target;
  if (t == "leader") {
    target = CommandTarget::leader();
  } else if (t == "followers") {
    target = CommandTarget::followers();
  } else if (t == "all") {
    target = CommandTarget::all();
  } else if (t.rfind("follower", 0) == 0 && t.size() > 8 && t.size() <= 12 &&
             t.find_first_not_of("0123456789", 8) == std::string::npos && t[8] != '0') {
    target = CommandTarget::list({std::atoi(t.c_str() + 8)});
  } else {
    return R::fail("unknown target '" + t + "' in '" + path + "' (leader, followers, all or followerN, N >= 1)");
  }
  return R::ok({target, parameter});
}

const common::FieldTable<DuplicateWindowConfig>& duplicateWindowFields() {
  using C = DuplicateWindowConfig;
  static const common::FieldTable<DuplicateWindowConfig> t{{
      {"duplicates.window_per_sender", common::Range::atLeast(1), [](C& c) { return &c.window_per_sender; }},
      {"duplicates.max_senders", common::Range::atLeast(1), [](C& c) { return &c.max_senders; }},
  }};
  return t;
}

std::vector<common::ConfigError> DuplicateWindowConfig::problems() const {
  return duplicateWindowFields().rangeProblems(*this);
}

std::vector<std::string> DuplicateWindowConfig::validate() const { return common::problemLines(problems()); }

DuplicateWindow::Check DuplicateWindow::check(const CommandId& id) const {
  for (const Sender& s : senders_) {
    if (s.name != id.sender) continue;
    if (std::find(s.sequences.begin(), s.sequences.end(), id.sequence) != s.sequences.end()) return Check::kDuplicate;
    if (static_cast<int>(s.sequences.size()) >= config_.window_per_sender &&
        id.sequence < *std::min_element(s.sequences.begin(), s.sequences.end())) {
      return Check::kStale;
    }
    return Check::kNew;
  }
  return Check::kNew;
}

void DuplicateWindow::record(const CommandId& id) {
  auto it = std::find_if(senders_.begin(), senders_.end(), [&](const Sender& s) { return s.name == id.sender; });
  Sender sender;
  if (it != senders_.end()) {
    sender = std::move(*it);
    senders_.erase(it);
  } else {
    sender.name = id.sender;
    if (static_cast<int>(senders_.size()) >= config_.max_senders) senders_.pop_front();
  }
  sender.sequences.push_back(id.sequence);
  while (static_cast<int>(sender.sequences.size()) > config_.window_per_sender) sender.sequences.pop_front();
  senders_.push_back(std::move(sender));
}

common::Result<FormationState> FormationState::create(const FormationParams& params, const FormationLimits& limits,
                                                      const DuplicateWindowConfig& duplicates) {
  std::vector<std::string> e = limits.validate();
  for (auto& s : validateParams(params, limits)) e.push_back(s);
  for (auto& s : duplicates.validate()) e.push_back(s);
  if (!e.empty()) {
    std::string reason;
    for (const auto& s : e) reason += s + "\n";
    return common::Result<FormationState>::fail(reason);
  }
  return common::Result<FormationState>::ok(FormationState(params, limits, duplicates));
}

double FormationState::clampValue(UavIndex uav, Parameter parameter, double requested, std::string& rule) const {
  rule.clear();
  if (parameter == Parameter::kBeta) return wrapDeg(requested);
  double lo = 0.0, hi = 0.0;
  std::string lo_rule, hi_rule;
  if (parameter == Parameter::kDistance) {
    lo = limits_.distanceFloorM();
    lo_rule = limits_.distance_min_m >= limits_.safety_distance_m ? "limits.distance_min_m" : "limits.safety_distance_m";
    hi = limits_.distance_max_m;
    hi_rule = "limits.distance_max_m";
  } else if (uav == kLeader) {
    // The leader's γ_L is its elevation, and shifts every follower's elevation γ_L + γ_i.
    lo = limits_.gamma_min_deg;
    hi = limits_.gamma_max_deg;
    lo_rule = "limits.gamma_min_deg";
    hi_rule = "limits.gamma_max_deg";
    for (std::size_t i = 0; i < params_.followers.size(); ++i) {
      const double g = params_.followers[i].gamma_deg;
      const std::string who = " (elevation of follower " + std::to_string(i + 1) + ")";
      if (limits_.gamma_min_deg - g > lo) {
        lo = limits_.gamma_min_deg - g;
        lo_rule = "limits.gamma_min_deg" + who;
      }
      if (limits_.gamma_max_deg - g < hi) {
        hi = limits_.gamma_max_deg - g;
        hi_rule = "limits.gamma_max_deg" + who;
      }
    }
  } else {
    lo = limits_.gamma_min_deg - params_.leader.gamma_deg;
    hi = limits_.gamma_max_deg - params_.leader.gamma_deg;
    lo_rule = "limits.gamma_min_deg (elevation leader.gamma_deg + gamma_deg)";
    hi_rule = "limits.gamma_max_deg (elevation leader.gamma_deg + gamma_deg)";
  }
  if (requested < lo) {
    rule = lo_rule;
    return lo;
  }
  if (requested > hi) {
    rule = hi_rule;
    return hi;
  }
  return requested;
}

std::optional<SlotPair> closestSlots(const FormationParams& params) {
  // The reference positions around a worker at the origin facing +x, the leader at its desired
  // heading and pitch: their distances depend on the parameters only.
  std::vector<Eigen::Vector3d> p;
  const UavReference leader = leaderReference(Eigen::Vector3d::Zero(), 0.0, params.leader);
  p.push_back(leader.p_world);
  for (const UavObservation& f : params.followers) {
    p.push_back(followerReference(Eigen::Vector3d::Zero(), leader.heading_rad, leader.pitch_rad, f).p_world);
  }
  std::optional<SlotPair> best;
  for (std::size_t a = 0; a < p.size(); ++a) {
    for (std::size_t b = a + 1; b < p.size(); ++b) {
      const double d = (p[a] - p[b]).norm();
      if (!best || d < best->distance_m) best = SlotPair{static_cast<int>(a), static_cast<int>(b), d};
    }
  }
  return best;
}

CommandOutcome FormationState::apply(const FormationCommand& command) {
  CommandOutcome out;
  const std::string id = command.id.sender + "/" + std::to_string(command.id.sequence);
  if (!std::isfinite(command.amount)) {
    out.reason = "command " + id + ": amount must be finite, got " + std::to_string(command.amount);
    return out;
  }
  if (command.id.sender.empty()) {
    out.reason = "command " + id + ": empty sender";
    return out;
  }
  if (command.parameter != Parameter::kBeta && command.parameter != Parameter::kGamma &&
      command.parameter != Parameter::kDistance) {
    out.reason = "command " + id + ": unknown parameter";
    return out;
  }
  if (command.kind != CommandKind::kIncrement && command.kind != CommandKind::kSet) {
    out.reason = "command " + id + ": unknown kind";
    return out;
  }
  const auto targets = command.target.resolve(params_.uavCount());
  if (!targets) {
    out.reason = "command " + id + ": " + targets.reason();
    return out;
  }
  switch (duplicates_.check(command.id)) {
    case DuplicateWindow::Check::kDuplicate:
      out.status = CommandStatus::kDuplicate;
      out.reason = "command " + id + " was already applied";
      return out;
    case DuplicateWindow::Check::kStale:
      out.reason = "command " + id + " is older than the remembered window of sender '" + command.id.sender +
                   "' (cannot tell it from a duplicate)";
      return out;
    case DuplicateWindow::Check::kNew: break;
  }
  const FormationParams before = params_;
  for (const UavIndex u : *targets) {
    UavObservation& o = params_.uav(u);
    double& q = command.parameter == Parameter::kBeta    ? o.beta_deg
                : command.parameter == Parameter::kGamma ? o.gamma_deg
                                                         : o.distance_m;
    ParameterChange c;
    c.uav = u;
    c.parameter = command.parameter;
    c.before = q;
    c.requested = command.kind == CommandKind::kIncrement ? q + command.amount : command.amount;
    c.applied = clampValue(u, command.parameter, c.requested, c.clamp_rule);
    c.clamped = !c.clamp_rule.empty();
    q = c.applied;
    out.changes.push_back(std::move(c));
  }
  // Two slots closer than Γ_dis cannot both be flown (the planner keeps the UAVs Γ_dis apart, so
  // neither reaches its view; a group 'set' of β puts both followers on one point): refused,
  // nothing changed — unless they were closer already and the command moves them apart.
  const double min_separation_m = limits_.safety_distance_m;
  const auto closest = closestSlots(params_);
  if (closest && closest->distance_m < min_separation_m) {
    const auto before_pair = closestSlots(before);
    const bool worse = !before_pair || closest->distance_m < before_pair->distance_m - 1e-9;
    if (worse) {
      params_ = before;
      out.changes.clear();
      std::ostringstream os;
      os << "command " << id << " would put the slots of UAV " << closest->a << " and UAV " << closest->b << " "
         << common::formatNumber(closest->distance_m) << " m apart, less than limits.safety_distance_m ("
         << common::formatNumber(min_separation_m) << " m, Gamma_dis)";
      out.reason = os.str();
      return out;
    }
  }
  duplicates_.record(command.id);
  out.status = CommandStatus::kApplied;
  return out;
}

common::Result<CommandTarget> parseTarget(const std::string& text) {
  using R = common::Result<CommandTarget>;
  if (text == "all") return R::ok(CommandTarget::all());
  if (text == "leader") return R::ok(CommandTarget::leader());
  if (text == "followers") return R::ok(CommandTarget::followers());
  if (text.rfind("follower", 0) == 0 && text.size() > 8) {
    const std::string n = text.substr(8);
    if (n.find_first_not_of("0123456789") == std::string::npos && n.size() < 4) {
      const int i = std::stoi(n);
      if (i >= 1) return R::ok(CommandTarget::list({i}));
    }
  }
  return R::fail("target must be all | leader | followers | follower<i> | a list of UAV indices, got '" + text + "'");
}

}  // namespace gesture_formation::formation

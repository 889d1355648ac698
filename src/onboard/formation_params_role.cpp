#include "gesture_formation/onboard/formation_params_role.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <utility>

namespace gesture_formation::onboard {

FormationParamsRole::FormationParamsRole(const formation::FormationConfig& config, int uav_index)
    : params_(config.params) {
  if (uav_index != formation::kLeader) return;
  auto st = formation::FormationState::create(config.params, config.limits, config.duplicates);
  if (st) state_.emplace(std::move(*st));
}

const CommandRecord& FormationParamsRole::apply(const common::Result<formation::FormationCommand>& command,
                                                std::string text, std::string source, double stamp_s) {
  last_ = CommandRecord{std::move(text), "", std::move(source), stamp_s, "", {}};
  if (!state_) {
    last_.outcome = "rejected: not the leader";
    last_.status = formation::toString(formation::CommandStatus::kRejected);
  } else if (!command) {
    last_.outcome = "rejected: " + command.reason();
    last_.status = formation::toString(formation::CommandStatus::kRejected);
  } else if (const auto held = assistance_.refusal(command->source)) {
    last_.outcome = "rejected: " + *held;
    last_.status = formation::toString(formation::CommandStatus::kRejected);
  } else {
    const auto out = state_->apply(*command);
    last_.outcome = out.describe();
    last_.status = formation::toString(out.status);
    if (out.status == formation::CommandStatus::kApplied) {
      ++version_;
      params_ = state_->params();
      for (const auto& c : out.changes) last_.uavs.push_back(c.uav);
      applied_.push_back(command->id);
      if (applied_.size() > kMaxRecordedCommands) applied_.pop_front();
    }
  }
  return last_;
}

common::Result<bool> FormationParamsRole::resume(const ParamsRecord& record, const formation::FormationConfig& config) {
  using R = common::Result<bool>;
  if (!state_) return R::fail("not the leader: a follower takes the leader's parameters");
  if (record.params.uavCount() != params_.uavCount()) {
    return R::fail("a record for " + std::to_string(record.params.uavCount()) + " UAVs, the formation has " +
                   std::to_string(params_.uavCount()));
  }
  auto st = formation::FormationState::create(record.params, config.limits, config.duplicates);
  if (!st) return R::fail("its parameters are outside the limits: " + st.reason());
  for (const auto& id : record.applied) st->rememberApplied(id);
  state_.emplace(std::move(*st));
  params_ = record.params;
  version_ = record.version;
  applied_.assign(record.applied.begin(), record.applied.end());
  while (applied_.size() > kMaxRecordedCommands) applied_.pop_front();
  assistance_.restore(record.assistance);
  return R::ok(true);
}

ParamsRecord FormationParamsRole::record(const std::string& run) const {
  return ParamsRecord{run, version_, params_, std::vector<formation::CommandId>(applied_.begin(), applied_.end()),
                      assistance_.state()};
}

namespace {
/// Printable ASCII without spaces (as the wire's sender names): one word of a record's line.
bool oneWord(const std::string& s) {
  if (s.empty() || s == "-") return false;
  for (const char c : s) {
    if (c < 0x21 || c > 0x7e) return false;
  }
  return true;
}
}  // namespace

std::string formatParamsRecord(const ParamsRecord& r) {
  std::ostringstream os;
  os.precision(17);
  os << "gesture_formation_params 1\nrun " << r.run << "\nversion " << r.version << "\n";
  for (int u = 0; u < r.params.uavCount(); ++u) {
    const formation::UavObservation& o = r.params.uav(u);
    os << "uav " << u << ' ' << o.beta_deg << ' ' << o.gamma_deg << ' ' << o.distance_m << "\n";
  }
  for (const auto& id : r.applied) {  // a name the line cannot hold is left out (its copies were the link's to drop)
    if (oneWord(id.sender)) os << "applied " << id.sender << ' ' << id.sequence << "\n";
  }
  const formation::AssistanceState& a = r.assistance;
  os << "assistance " << formation::toString(a.phase) << ' ' << a.requested_s << ' ' << a.acknowledged_s << ' '
     << (oneWord(a.requested_by) ? a.requested_by : "-") << ' ' << (oneWord(a.acknowledged_by) ? a.acknowledged_by : "-")
     << "\n";
  return os.str();
}

namespace {
/// Digits only (istream would take "-1" into an unsigned as its maximum), within 64 bits.
bool readUnsigned(std::istream& in, std::uint64_t& out) {
  std::string word;
  if (!(in >> word) || word.empty() || word.size() > 20 || word.find_first_not_of("0123456789") != std::string::npos) return false;
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(word.c_str(), &end, 10);
  if (errno == ERANGE || end != word.c_str() + word.size()) return false;
  out = static_cast<std::uint64_t>(v);
  return true;
}
}  // namespace

common::Result<ParamsRecord> parseParamsRecord(const std::string& text) {
  using R = common::Result<ParamsRecord>;
  std::istringstream in(text);
  std::string line;
  ParamsRecord r;
  int line_no = 0, uavs = 0;
  bool has_run = false, has_version = false;
  auto bad = [&](const std::string& what) { return R::fail("line " + std::to_string(line_no) + ": " + what + " ('" + line + "')"); };
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream f(line);
    std::string key, extra;
    f >> key;
    if (line_no == 1) {
      int format = 0;
      if (key != "gesture_formation_params" || !(f >> format) || format != 1 || (f >> extra)) return bad("not a parameter record of format 1");
      continue;
    }
    if (key == "run") {
      if (!(f >> r.run) || (f >> extra)) return bad("run: one word expected");
      has_run = true;
    } else if (key == "version") {
      if (!readUnsigned(f, r.version) || (f >> extra)) return bad("version: an unsigned integer expected");
      has_version = true;
    } else if (key == "uav") {
      int u = -1;
      formation::UavObservation o;
      if (!(f >> u >> o.beta_deg >> o.gamma_deg >> o.distance_m) || (f >> extra)) return bad("uav: index, beta_deg, gamma_deg, distance_m expected");
      if (u != uavs) return bad("uav " + std::to_string(u) + " out of order (expected " + std::to_string(uavs) + ")");
      if (!std::isfinite(o.beta_deg) || !std::isfinite(o.gamma_deg) || !std::isfinite(o.distance_m)) return bad("uav: values must be finite");
      if (u == 0) {
        r.params.leader = o;
        r.params.followers.clear();
      } else {
        r.params.followers.push_back(o);
      }
      ++uavs;
    } else if (key == "applied") {
      formation::CommandId id;
      if (!(f >> id.sender) || !readUnsigned(f, id.sequence) || (f >> extra)) return bad("applied: sender and sequence expected");
      if (r.applied.size() == kMaxRecordedCommands) return bad("more than " + std::to_string(kMaxRecordedCommands) + " applied ids");
      r.applied.push_back(id);
    } else if (key == "assistance") {
      std::string phase, by, ack_by;
      formation::AssistanceState& a = r.assistance;
      if (!(f >> phase >> a.requested_s >> a.acknowledged_s >> by >> ack_by) || (f >> extra)) {
        return bad("assistance: phase, requested_s, acknowledged_s, requested_by, acknowledged_by expected");
      }
      if (phase == "none") a.phase = formation::AssistancePhase::kNone;
      else if (phase == "requested") a.phase = formation::AssistancePhase::kRequested;
      else if (phase == "acknowledged") a.phase = formation::AssistancePhase::kAcknowledged;
      else return bad("assistance: phase '" + phase + "' is not none | requested | acknowledged");
      if (!std::isfinite(a.requested_s) || !std::isfinite(a.acknowledged_s)) return bad("assistance: times must be finite");
      a.requested_by = by == "-" ? "" : by;
      a.acknowledged_by = ack_by == "-" ? "" : ack_by;
    } else if (!key.empty()) {
      return bad("unknown key '" + key + "'");
    }
  }
  if (line_no == 0) return R::fail("empty record");
  if (!has_run || !has_version || uavs == 0) return R::fail("incomplete record: run, version and the leader's uav line are required");
  return R::ok(std::move(r));
}

common::Result<bool> FormationParamsRole::receive(const formation::FormationParams& params, std::uint64_t version) {
  if (params.uavCount() != params_.uavCount()) {
    return common::Result<bool>::fail("formation parameters for " + std::to_string(params.uavCount()) +
                                      " UAVs, the formation has " + std::to_string(params_.uavCount()));
  }
  params_ = params;
  version_ = version;
  return common::Result<bool>::ok(true);
}

ParamsOwnership::ParamsOwnership(const formation::FormationConfig& config, int uav_index, bool follow_leadership)
    : config_(config), uav_index_(uav_index), follow_(follow_leadership) {
  role_.emplace(config, uav_index);
}

ParamsOwnership::Change ParamsOwnership::setActing(bool acting, double t_s, int leader, std::uint32_t term) {
  if (!follow_) return Change::kNone;
  leader_ = leader;
  term_ = term;
  if (!acting && leader >= 0 && leader != uav_index_) other_leader_seen_ = true;
  if (acting == acting_) return Change::kNone;
  acting_ = acting;
  if (!acting_) return Change::kStopped;
  if (term != 0 && term == acted_term_) return Change::kResumed;  // nobody else acted since
  // Elected again in a newer term with no other leader seen since it last acted (none sent
  // parameters either): it was the last owner — its role stays, with the assistance latch (a
  // pending request is not dropped), the duplicate window and the version; as gfctl simulate,
  // where a take-over happens only when another UAV acts.
  const bool still_the_owner = acted_term_ != 0 && !other_leader_seen_;
  acted_term_ = term;
  other_leader_seen_ = false;
  if (still_the_owner) return Change::kStarted;
  formation::FormationConfig cfg = config_;
  cfg.params = role_->params();
  base_version_ = version();
  role_.emplace(cfg, formation::kLeader);
  took_over_s_ = t_s;
  return Change::kStarted;
}

int ParamsOwnership::slot() const {
  if (!follow_) return -1;
  if (acting_) return formation::kLeader;
  return uav_index_ == formation::kLeader && leader_ > formation::kLeader ? leader_ : -1;
}

int ParamsOwnership::leaderIndex() const {
  if (!follow_) return formation::kLeader;
  if (acting_) return uav_index_;
  return leader_ >= 0 ? leader_ : formation::kLeader;
}

common::Result<bool> ParamsOwnership::resume(const ParamsRecord& record) {
  if (follow_) return common::Result<bool>::fail("following the leadership: the parameters come from the acting leader");
  return role_->resume(record, config_);
}

common::Result<bool> ParamsOwnership::receive(const formation::FormationParams& params, std::uint64_t version) {
  if (owns()) return common::Result<bool>::ok(false);  // the owner's own parameters are the formation's
  // Lapsed in the term it acted in: nobody else can own them in this term — a late copy of an
  // earlier owner's must not overwrite the parameters it resumes with.
  if (keepsCommand(took_over_s_)) return common::Result<bool>::ok(false);
  other_leader_seen_ = true;  // another UAV owned the parameters
  base_version_ = 0;                                    // the received version is the formation's
  return role_->receive(params, version);
}

}  // namespace gesture_formation::onboard

#include "gesture_formation/onboard/formation_params_role.hpp"

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
    }
  }
  return last_;
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

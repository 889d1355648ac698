#pragma once
/// \file
/// \brief A UAV's part in the formation's parameters (docs/formation.md §6–7, the FormationPlanner's
/// state), ROS-free: the leader owns them (formation::FormationState applies and clamps every
/// command, each applied command bumps the version, the last command and its outcome are kept for
/// the operator); a follower holds the parameters it last received from the leader, refusing a set
/// for another number of UAVs. While the worker's request for assistance is pending
/// (formation::AssistanceLatch) the leader refuses the worker's gesture commands.
/// Thread safety: none (the caller's lock).

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/formation/assistance.hpp"
#include "gesture_formation/formation/formation_commands.hpp"
#include "gesture_formation/formation/formation_config.hpp"

namespace gesture_formation::onboard {

/// \brief What a fixed leader keeps on disk to resume after a restart of its planner in the same
/// run (docs/safety.md §2.4): the parameters, their version, the ids of the commands it applied
/// last (a copy still on the link stays a duplicate) and the assistance latch (a pending request
/// stays pending). `run` names the run (ROS: /run_id and the launch's id) — a record of another run
/// is not resumed. Text: formatParamsRecord / parseParamsRecord.
struct ParamsRecord {
  std::string run;
  std::uint64_t version = 0;
  formation::FormationParams params;
  std::vector<formation::CommandId> applied;  ///< oldest first, ≤ kMaxRecordedCommands
  formation::AssistanceState assistance;
};
constexpr std::size_t kMaxRecordedCommands = 64;
/// \brief Lines: `gesture_formation_params 1`, `run <id>`, `version <n>`, one `uav <i> <beta_deg>
/// <gamma_deg> <distance_m>` per UAV from 0 (the leader), one `applied <sender> <sequence>` per id
/// (names of printable ASCII without spaces; another is left out), `assistance <phase> <requested_s>
/// <acknowledged_s> <requested_by> <acknowledged_by>` (a name '-' when empty or not one word).
std::string formatParamsRecord(const ParamsRecord& record);
/// \brief Fails naming the line and what is wrong (every number finite, UAVs 0..n−1 in order, ≥ 1).
common::Result<ParamsRecord> parseParamsRecord(const std::string& text);

/// \brief The last command the leader handled (FormationParams.last_* in ROS).
struct CommandRecord {
  std::string text;     ///< what was asked, as the caller described it (source, sender#sequence, change)
  std::string outcome;  ///< formation::CommandOutcome::describe(), or "rejected: <why>" for a bad command
  std::string source;   ///< "gesture" | "operator"
  double stamp_s = 0.0; ///< when it was sent
  std::string status;   ///< formation::toString(CommandStatus)
  std::vector<int> uavs;  ///< the UAVs whose parameters changed
};

class FormationParamsRole {
 public:
  /// \brief The leader (uav_index 0) owns `config`'s parameters; a follower starts with them and
  /// takes the leader's. `config` must be valid (its loader checked it).
  FormationParamsRole(const formation::FormationConfig& config, int uav_index);

  bool leader() const { return state_.has_value(); }
  /// \brief The leader: applies `command` (or records why it could not be parsed) and returns the record.
  const CommandRecord& apply(const common::Result<formation::FormationCommand>& command, std::string text,
                             std::string source, double stamp_s);
  /// \brief A follower: the leader's parameters; refused (nothing changes) naming the UAV count.
  common::Result<bool> receive(const formation::FormationParams& params, std::uint64_t version);

  /// \brief The leader: continues from `record` (its parameters, version and applied ids), as
  /// checked against `config`'s limits; refused naming why (nothing changes) for a follower or
  /// parameters outside the limits or for another number of UAVs.
  common::Result<bool> resume(const ParamsRecord& record, const formation::FormationConfig& config);
  /// \brief The leader's state to keep (resume), named `run`.
  ParamsRecord record(const std::string& run) const;

  const formation::FormationParams& params() const { return params_; }
  /// \brief The leader: the version of its parameters (applied commands); a follower: the version received.
  std::uint64_t version() const { return version_; }
  const CommandRecord& last() const { return last_; }
  /// \brief The leader's assistance latch (docs/safety.md §2.10).
  formation::AssistanceLatch& assistance() { return assistance_; }
  const formation::AssistanceLatch& assistance() const { return assistance_; }

 private:
  formation::FormationParams params_;
  std::optional<formation::FormationState> state_;
  std::uint64_t version_ = 0;
  CommandRecord last_;
  formation::AssistanceLatch assistance_;
  std::deque<formation::CommandId> applied_;  ///< the last kMaxRecordedCommands applied, oldest first
};

/// \brief Who owns the formation's parameters (the FormationPlanner's role): the leader by index,
/// or — following the leadership (docs/safety.md §1.2, the FormationPlanner's ~leadership) — the UAV
/// while it acts as leader. A UAV that starts acting takes the parameters it holds (the last ones
/// received) over with their version and from then on applies only the commands sent since it took
/// over (older ones were its predecessor's, whose effect the parameters carry); while it does not
/// act it takes the parameters it receives. A leader whose lease lapses and that acts again *in the
/// same term* resumes (nobody else can have acted: a new leader needs a newer term): it keeps its
/// role, and the commands that reached it in between (keepsCommand) are its to apply then — under
/// a lossy link the lease lapses for a fraction of a second many times a mission (docs/safety.md
/// §1.2), and a command arriving in such a gap was dropped. Thread safety: none (the caller's lock).
class ParamsOwnership {
 public:
  enum class Change { kNone, kStarted, kStopped, kResumed };

  /// `config` must be valid (its loader checked it).
  ParamsOwnership(const formation::FormationConfig& config, int uav_index, bool follow_leadership);

  /// This UAV owns the parameters now.
  bool owns() const { return follow_ ? acting_ : uav_index_ == formation::kLeader; }
  /// \brief Following the leadership: this UAV's acting state (its own LeadershipState) at `t_s`
  /// and the leader of its term as far as it knows (`leader`, −1: none). Starting to act, the role
  /// becomes the leader's from the parameters held, version carried on.
  /// `term`: its leadership term (0: not known — never resumes). Acting again in the term in which
  /// it last acted is kResumed: the role, its parameters and the take-over time are kept. Acting
  /// in a newer term with no other leader seen since (nor parameters received) is kStarted with
  /// the role kept too (its assistance latch, duplicate window and version).
  Change setActing(bool acting, double t_s, int leader = -1, std::uint32_t term = 0);
  /// \brief The formation slot this UAV flies (planning::ReplanInputs::slot), as gfctl simulate's
  /// hand-over assigns it: the acting leader flies the leader's (0); UAV 0, no longer acting,
  /// the slot its successor left (the successor's index; −1 before one is known: its own); every
  /// other UAV its own (−1). Not following the leadership: −1.
  int slot() const;
  /// \brief Whose plan is the leader's (planning::ReplanInputs::leader_index): this UAV while it
  /// acts, else the leader it knows (UAV 0 before one is known or without the leadership).
  int leaderIndex() const;
  /// \brief A command sent at `stamp_s` is this UAV's to apply.
  bool takesCommand(double stamp_s) const { return owns() && (!follow_ || stamp_s >= took_over_s_); }
  /// \brief A command sent at `stamp_s` reached this UAV while its lease has lapsed in the term in
  /// which it acts: keep it, to apply when it resumes (setActing → kResumed) if still fresh.
  bool keepsCommand(double stamp_s) const {
    return follow_ && !acting_ && acted_term_ != 0 && term_ == acted_term_ && stamp_s >= took_over_s_;
  }
  /// \brief The owner's parameters as received; ignored (ok(false)) while this UAV owns them or
  /// its lease has lapsed in the term it acted in (a late copy of an earlier owner's).
  common::Result<bool> receive(const formation::FormationParams& params, std::uint64_t version);
  /// \brief The leader by index (not following the leadership), restarted in the same run: continues
  /// from `record` (FormationParamsRole::resume); refused naming why for any other UAV.
  common::Result<bool> resume(const ParamsRecord& record);
  /// The parameters' version: the one taken over plus this UAV's own applied commands.
  std::uint64_t version() const { return base_version_ + role_->version(); }
  double tookOverS() const { return took_over_s_; }
  FormationParamsRole& role() { return *role_; }
  const FormationParamsRole& role() const { return *role_; }

 private:
  formation::FormationConfig config_;
  std::optional<FormationParamsRole> role_;
  int uav_index_ = 0;
  bool follow_ = false, acting_ = false;
  int leader_ = -1;                 ///< the leader of this UAV's term as it knows it (−1: none)
  std::uint64_t base_version_ = 0;  ///< the version taken over (0: the role's own)
  double took_over_s_ = 0.0;        ///< when this UAV last started acting
  std::uint32_t term_ = 0;          ///< its leadership term now (0: not known)
  std::uint32_t acted_term_ = 0;    ///< the term in which it last acted (0: none known)
  bool other_leader_seen_ = false;  ///< since it last acted, another UAV led or sent parameters
};

}  // namespace gesture_formation::onboard

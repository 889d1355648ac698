#pragma once
/// \file
/// \brief View-adaptation commands of the formation (docs/design.md §4 "each command adds an
/// increment q ← q + i_q, clamped to configured limits"; docs/formation.md §4): increment or
/// set one parameter (β, γ, d) of one UAV, a subset, or all; from the operator or from a
/// gesture; with an id so that a command delivered twice is applied once.
///
/// Semantics (docs/formation.md §4):
/// - A command is checked as a whole first; a rejected command (unknown UAV, non-finite
///   amount, empty target list, stale id) changes nothing and says why.
/// - An accepted command is applied to its UAVs in ascending index order (leader first),
///   each against the state left by the previous one, and each value is clamped to the
///   limits (FormationLimits). Every change is reported; clamped ones with the requested
///   and the applied value and the rule that clamped it.
/// - β: new = wrap(β + i) or wrap(value), to (−180, 180]; never clamped.
/// - γ: clamped so that every UAV's elevation stays in [gamma_min_deg, gamma_max_deg]: the
///   leader's γ_L bounds the followers' γ_L + γ_i too, a follower's γ_i only its own.
/// - d: clamped to [max(distance_min_m, safety_distance_m), distance_max_m].
/// - Ids: (sender, sequence). An id already applied is a duplicate (nothing changes). Only
///   applied commands are remembered: the `window_per_sender` most recent sequence numbers of
///   each of at most `max_senders` senders (least recently heard sender forgotten first). A
///   sequence number older than every remembered one of a full window is rejected as stale
///   (it cannot be told from a late duplicate).
/// Thread safety: none; one FormationState per thread (the nodelet guards it with a mutex).

#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/formation/formation_params.hpp"

namespace gesture_formation::formation {

/// \brief The adaptive parameter a command changes.
enum class Parameter { kBeta, kGamma, kDistance };

/// \brief "beta_deg", "gamma_deg", "distance_m" (the YAML / CSV names with their units).
const char* parameterName(Parameter p);

/// \brief Who sent a command.
enum class CommandSource { kOperator, kGesture };
const char* toString(CommandSource s);

/// \brief Which UAVs a command addresses.
enum class TargetGroup {
  kLeader,     ///< the leader only ("leader")
  kFollowers,  ///< every follower ("followers")
  kAll,        ///< every UAV ("all")
  kList,       ///< the UAVs in CommandTarget::uavs ("follower2", or a subset from the operator)
};

/// \brief The UAVs a command addresses.
struct CommandTarget {
  TargetGroup group = TargetGroup::kLeader;
  std::vector<UavIndex> uavs;  ///< kList only: UAV indices (0 = leader), any order, no duplicates needed

  static CommandTarget leader() { return {TargetGroup::kLeader, {}}; }
  static CommandTarget followers() { return {TargetGroup::kFollowers, {}}; }
  static CommandTarget all() { return {TargetGroup::kAll, {}}; }
  static CommandTarget list(std::vector<UavIndex> uavs) { return {TargetGroup::kList, std::move(uavs)}; }

  /// \brief The addressed UAV indices for a formation of `uav_count` UAVs, ascending and
  /// unique; fails naming the first unknown UAV or an empty list.
  common::Result<std::vector<UavIndex>> resolve(int uav_count) const;
  /// \brief "leader", "followers", "all", "follower2", or "uavs{L,2}".
  std::string describe() const;
};

/// \brief Parses a parameter path `<target>.<parameter>`: target ∈ leader | followers | all |
/// follower<i> (i ≥ 1, the CSV label), parameter ∈ beta_deg | gamma_deg | distance_m.
common::Result<std::pair<CommandTarget, Parameter>> parseParameterPath(const std::string& path);

/// \brief Identifies a command: sender name and a per-sender sequence number.
struct CommandId {
  std::string sender;          ///< e.g. "operator", "gesture", "gcs1"
  std::uint64_t sequence = 0;  ///< increases per sender
};

/// \brief Whether a command adds to the parameter or sets it.
enum class CommandKind { kIncrement, kSet };

/// \brief One view-adaptation request.
struct FormationCommand {
  CommandId id;
  CommandSource source = CommandSource::kOperator;
  CommandTarget target;
  Parameter parameter = Parameter::kBeta;
  CommandKind kind = CommandKind::kIncrement;
  double amount = 0.0;  ///< increment or new value, in the parameter's unit ([deg] for β, γ; [m] for d)
};

/// \brief What a command did to one parameter of one UAV.
struct ParameterChange {
  UavIndex uav = kLeader;
  Parameter parameter = Parameter::kBeta;
  double before = 0.0;     ///< value before the command
  double requested = 0.0;  ///< before + increment, or the set value (β: unwrapped)
  double applied = 0.0;    ///< value now held (wrapped / clamped)
  bool clamped = false;    ///< applied ≠ requested because of a limit (β wrapping is not clamping)
  std::string clamp_rule;  ///< the limit that clamped it, e.g. "limits.distance_min_m" (empty if not clamped)
};

/// \brief Two UAVs' reference positions (slots) and their distance [m].
struct SlotPair {
  int a = 0, b = 0;  ///< UAV indices (0 = leader), a < b
  double distance_m = 0.0;
};
/// \brief The two closest slots of `params` (empty with one UAV): the references around a worker
/// at the origin, the leader at its desired heading and pitch — their distances depend on the
/// parameters only. FormationState::apply refuses a command that brings two slots closer than
/// limits.safety_distance_m (Γ_dis) unless they were closer already and it moves them apart.
std::optional<SlotPair> closestSlots(const FormationParams& params);

enum class CommandStatus {
  kApplied,    ///< changes holds one entry per addressed UAV
  kDuplicate,  ///< id already applied; nothing changed
  kRejected,   ///< reason says why; nothing changed
};
const char* toString(CommandStatus s);

/// \brief The outcome of FormationState::apply.
struct CommandOutcome {
  CommandStatus status = CommandStatus::kRejected;
  std::string reason;                    ///< why rejected / duplicate; empty when applied
  std::vector<ParameterChange> changes;  ///< applied commands only, ascending UAV index
  bool anyClamped() const {
    for (const auto& c : changes) {
      if (c.clamped) return true;
    }
    return false;
  }
  /// One line for operators and logs: the status, ": reason" when there is one, and
  /// " (clamped by <rule>)" per clamped change (FormationParams.last_outcome).
  std::string describe() const;
};

/// \brief Bounds of the duplicate-id memory.
struct DuplicateWindowConfig {
  int window_per_sender = 64;  ///< sequence numbers remembered per sender, ≥ 1
  int max_senders = 16;        ///< senders remembered, ≥ 1
  std::vector<std::string> validate() const;
  /// \brief The same problems, typed {key, message} (keys `duplicates.*`).
  std::vector<common::ConfigError> problems() const;
};

/// \brief DuplicateWindowConfig's numbers (keys `duplicates.*`) with their ranges: the only place
/// they are written, used by validate() and by the YAML reader.
const common::FieldTable<DuplicateWindowConfig>& duplicateWindowFields();

/// \brief Bounded memory of applied command ids (see the file comment).
class DuplicateWindow {
 public:
  enum class Check { kNew, kDuplicate, kStale };
  explicit DuplicateWindow(const DuplicateWindowConfig& config = {}) : config_(config) {}
  Check check(const CommandId& id) const;
  /// \brief Remembers an applied id (evicting the oldest sequence / least recent sender).
  void record(const CommandId& id);

 private:
  struct Sender {
    std::string name;
    std::deque<std::uint64_t> sequences;  ///< most recent last; size ≤ window_per_sender
  };
  DuplicateWindowConfig config_;
  std::deque<Sender> senders_;  ///< most recently heard last; size ≤ max_senders
};

/// \brief The formation's current parameters, changed only by commands.
class FormationState {
 public:
  /// \brief Fails listing every problem when params violate limits or a config is invalid.
  static common::Result<FormationState> create(const FormationParams& params, const FormationLimits& limits,
                                               const DuplicateWindowConfig& duplicates = {});

  /// \brief Applies a command (see the file comment). Never throws on bad input.
  CommandOutcome apply(const FormationCommand& command);
  /// \brief Remembers `id` as applied (a state resumed after a restart: its copies stay duplicates).
  void rememberApplied(const CommandId& id) { duplicates_.record(id); }

  const FormationParams& params() const { return params_; }
  const FormationLimits& limits() const { return limits_; }

 private:
  FormationState(const FormationParams& params, const FormationLimits& limits, const DuplicateWindowConfig& dup)
      : params_(params), limits_(limits), duplicates_(dup) {}
  /// Clamps a requested value of `parameter` of `uav` against the current state.
  double clampValue(UavIndex uav, Parameter parameter, double requested, std::string& rule) const;

  FormationParams params_;
  FormationLimits limits_;
  DuplicateWindow duplicates_;
};

/// \brief Parses a command target by name: all | leader | followers | follower<i> (i ≥ 1).
/// Fails naming the accepted forms and the text.
common::Result<CommandTarget> parseTarget(const std::string& text);

}  // namespace gesture_formation::formation

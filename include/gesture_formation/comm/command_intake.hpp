#pragma once
/// \file
/// \brief Formation commands as a receiving LcmBridge takes them in (docs/security.md §2):
/// the first copy of each command forwarded, the sender's repeats dropped, and the command's
/// sender name bound to the envelope's authenticated sender id. ROS-free, not thread-safe (the
/// caller's lock).
///
/// Binding: the name inside a command is payload, chosen by whoever holds a key that may send
/// commands. A command forwarded from envelope sender S carries the name `NAME@S`, so the ids
/// the leader's FormationState remembers (name, sequence) belong to one key: a ground station
/// cannot apply, pre-empt or shadow another one's command ids by writing its name.

#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <tuple>

#include "gesture_formation/formation/formation_commands.hpp"

namespace gesture_formation::comm {

class CommandIntake {
 public:
  /// Command ids remembered per envelope sender (the copies of one command arrive within
  /// command_repeats × command_repeat_period_s, far fewer).
  static constexpr std::size_t kRememberedPerSender = 256;

  /// \brief The command to forward for this copy received from `envelope_sender` (its name
  /// bound as `NAME@ID`), or nullopt when a copy of it was already forwarded.
  std::optional<formation::FormationCommand> accept(std::uint16_t envelope_sender, formation::FormationCommand command);

  /// \brief `name@sender`: the name a command from `sender` is forwarded with.
  static std::string boundName(const std::string& name, std::uint16_t sender);

  std::uint64_t copiesDropped() const { return copies_dropped_; }

 private:
  using Id = std::tuple<std::uint16_t, std::string, std::uint64_t>;  ///< envelope sender, name, sequence
  std::set<Id> seen_;
  std::map<std::uint16_t, std::deque<Id>> order_;  ///< per envelope sender, oldest first
  std::uint64_t copies_dropped_ = 0;
};

}  // namespace gesture_formation::comm

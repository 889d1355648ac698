#pragma once
/// \file
/// \brief The worker's request for assistance (docs/safety.md §2.10), ROS-free: a latch the leader
/// keeps with the formation's parameters. A request (the worker's {event: assist_requested}
/// gesture) holds the views steady — the worker's own gesture commands are refused, the
/// operator's pass — until the operator acknowledges it; a later request latches again.
/// Thread safety: none (the caller's lock).

#include <cstdint>
#include <optional>
#include <string>

#include "gesture_formation/formation/formation_commands.hpp"

namespace gesture_formation::formation {

enum class AssistancePhase : std::uint8_t { kNone = 0, kRequested = 1, kAcknowledged = 2 };

inline const char* toString(AssistancePhase p) {
  switch (p) {
    case AssistancePhase::kNone: return "none";
    case AssistancePhase::kRequested: return "requested";
    case AssistancePhase::kAcknowledged: return "acknowledged";
  }
  return "?";
}

/// \brief Where the latest request stands.
struct AssistanceState {
  AssistancePhase phase = AssistancePhase::kNone;
  double requested_s = 0.0;     ///< when it was requested (the gesture filter's fire time)
  std::string requested_by;     ///< who asked (e.g. "gesture")
  double acknowledged_s = 0.0;  ///< when the operator acknowledged it (phase kAcknowledged)
  std::string acknowledged_by;  ///< the operator's sender name
};

class AssistanceLatch {
 public:
  /// \brief A request at t_s: latches (true) unless one is already pending (false: the first one's
  /// time is kept — the worker repeating the gesture does not restart it).
  bool request(double t_s, std::string by) {
    if (state_.phase == AssistancePhase::kRequested) return false;
    state_ = AssistanceState{AssistancePhase::kRequested, t_s, std::move(by), 0.0, ""};
    return true;
  }
  /// \brief The operator's acknowledgement of the request made at `requested_s` (an acknowledgement
  /// of an older request, or with none pending, changes nothing: false).
  bool acknowledge(double requested_s, double t_s, std::string by) {
    if (state_.phase != AssistancePhase::kRequested || requested_s != state_.requested_s) return false;
    state_.phase = AssistancePhase::kAcknowledged;
    state_.acknowledged_s = t_s;
    state_.acknowledged_by = std::move(by);
    return true;
  }
  /// \brief A state as it arrives from elsewhere (the worker's request from the gesture commander,
  /// the operator's acknowledgement over the link): a request latches, an acknowledgement
  /// acknowledges the request it names, phase none changes nothing. True when the latch changed.
  bool receive(const AssistanceState& s) {
    switch (s.phase) {
      case AssistancePhase::kRequested: return request(s.requested_s, s.requested_by);
      case AssistancePhase::kAcknowledged: return acknowledge(s.requested_s, s.acknowledged_s, s.acknowledged_by);
      case AssistancePhase::kNone: return false;
    }
    return false;
  }
  /// \brief Why a command of `source` must be refused now (nullopt: it may be applied): while a
  /// request is pending the views are held — the worker's gestures are refused, the operator's pass.
  std::optional<std::string> refusal(CommandSource source) const {
    if (state_.phase != AssistancePhase::kRequested || source == CommandSource::kOperator) return std::nullopt;
    return "assistance requested at " + std::to_string(state_.requested_s) +
           " s: the views are held until the operator acknowledges";
  }
  const AssistanceState& state() const { return state_; }
  /// \brief Takes `s` as it was kept (a leader restarted in the same run: onboard::ParamsRecord).
  void restore(const AssistanceState& s) { state_ = s; }

 private:
  AssistanceState state_;
};

}  // namespace gesture_formation::formation

#pragma once
/// \file
/// \brief What a UAV's link keeps sending on its own (docs/safety.md §2.8, §2.10): the abort this
/// UAV accepted — relayed with every timed heartbeat for the rest of the mission, whether or not
/// its planner plans — and its last assistance state, re-sent with every worker state while a
/// request is pending. The send policy of the LcmBridge nodelet, kept here so that it is tested
/// without ROS. Thread safety: none (the bridge's lock).

#include <optional>

#include "gesture_formation/comm/payloads.hpp"

namespace gesture_formation::comm {

class StandingMessages {
 public:
  /// \brief This UAV's abort state: once an abort is accepted (`accepted`), it is relayed from then
  /// on; the first accepted command stays (a UAV acts on one abort).
  void abortState(bool accepted, const std::optional<AbortMessage>& command) {
    if (accepted && command && !relay_) relay_ = *command;
  }
  /// \brief An assistance state this UAV sent (the leader's, or the ground's acknowledgement).
  void assistanceSent(const AssistanceMessage& m) { assistance_ = m; }

  /// \brief To send with every timed heartbeat: the accepted abort, if any.
  const std::optional<AbortMessage>& withHeartbeat() const { return relay_; }
  /// \brief To send with every worker state: the assistance state while its request is pending.
  std::optional<AssistanceMessage> withWorkerState() const {
    if (assistance_ && assistance_->state.phase == formation::AssistancePhase::kRequested) return assistance_;
    return std::nullopt;
  }

 private:
  std::optional<AbortMessage> relay_;
  std::optional<AssistanceMessage> assistance_;
};

}  // namespace gesture_formation::comm

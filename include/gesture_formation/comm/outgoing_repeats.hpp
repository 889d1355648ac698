#pragma once
/// \file
/// \brief The copies of single-event messages still to send (formation commands, aborts): a lost
/// datagram must not lose a request (docs/safety.md §5), so the sender sends each such payload
/// `copies` times, `period_s` apart — each copy in a new envelope (new sequence and stamp) — and
/// the receivers act on the first copy. ROS-free.
/// Thread safety: none (the caller's lock).

#include <cstdint>
#include <deque>
#include <utility>
#include <vector>

#include "gesture_formation/comm/envelope.hpp"

namespace gesture_formation::comm {

/// \brief An encoded payload with its envelope type.
struct OutgoingPayload {
  MessageType type = MessageType::kHeartbeat;
  std::vector<std::uint8_t> payload;
};

class OutgoingRepeats {
 public:
  /// \brief Schedules `copies` − 1 more copies of `payload` (the caller sent the first at now_s),
  /// `period_s` apart. copies ≤ 1: nothing to repeat.
  void add(OutgoingPayload payload, int copies, double period_s, double now_s);
  /// \brief The copies due at or before now_s, oldest first, each returned once.
  std::vector<OutgoingPayload> due(double now_s);
  std::size_t pending() const { return pending_.size(); }

 private:
  struct Pending {
    OutgoingPayload payload;
    int left = 0;
    double period_s = 0.0;
    double next_s = 0.0;
  };
  std::deque<Pending> pending_;
};

}  // namespace gesture_formation::comm

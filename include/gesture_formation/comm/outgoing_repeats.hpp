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

/// \brief When the ground station sends the copies of its abort (docs/safety.md §2.8): a burst of
/// `repeats` copies, one per tick of its timer (`repeat_period_s` apart), then one every
/// `resend_period_s` for as long as it runs — a UAV out of reach for the whole burst (a link outage,
/// a reboot) still gets it when it is back. A resend falls on the first tick at or after its time,
/// on schedule (no drift), or from now after a stall. When the clock went back (the next resend
/// more than one resend period ahead: a simulation restarted, a bag looped) a copy goes out at once
/// and the schedule restarts from now — it would otherwise pause until the clock caught up.
class AbortCopySchedule {
 public:
  AbortCopySchedule(int repeats, double resend_period_s) : repeats_(repeats), resend_period_s_(resend_period_s) {}
  /// \brief A new abort: its burst starts; the first copy is due at the next call of due().
  void start() {
    copies_left_ = repeats_ > 0 ? repeats_ : 1;
    started_ = true;
  }
  /// \brief Whether a copy is to be sent at now_s (a tick of the timer, or start's first copy);
  /// each true is one copy sent.
  bool due(double now_s);
  bool started() const { return started_; }
  /// \brief When the next resend falls due (after the burst) [s].
  double nextResendS() const { return resend_at_s_; }

 private:
  int repeats_ = 1;
  double resend_period_s_ = 1.0;
  bool started_ = false;
  int copies_left_ = 0;      ///< burst copies still to send
  double resend_at_s_ = 0.0;  ///< after the burst: when the next copy falls due
};

}  // namespace gesture_formation::comm

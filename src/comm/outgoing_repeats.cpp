#include "gesture_formation/comm/outgoing_repeats.hpp"

namespace gesture_formation::comm {

void OutgoingRepeats::add(OutgoingPayload payload, int copies, double period_s, double now_s) {
  if (copies <= 1) return;
  pending_.push_back(Pending{std::move(payload), copies - 1, period_s, now_s + period_s});
}

std::vector<OutgoingPayload> OutgoingRepeats::due(double now_s) {
  std::vector<OutgoingPayload> out;
  for (auto it = pending_.begin(); it != pending_.end();) {
    if (it->next_s <= now_s + 1e-9) {
      out.push_back(it->payload);
      it->next_s += it->period_s;
      if (--it->left == 0) {
        it = pending_.erase(it);
        continue;
      }
    }
    ++it;
  }
  return out;
}

bool AbortCopySchedule::due(double now_s) {
  if (!started_) return false;
  if (copies_left_ > 0) {
    if (--copies_left_ == 0) resend_at_s_ = now_s + resend_period_s_;
    return true;
  }
  const bool clock_went_back = resend_at_s_ > now_s + resend_period_s_;
  if (now_s < resend_at_s_ && !clock_went_back) return false;
  resend_at_s_ += resend_period_s_;  // on schedule, not from this tick
  if (resend_at_s_ <= now_s || clock_went_back) resend_at_s_ = now_s + resend_period_s_;  // after a stall or a jump back
  return true;
}

}  // namespace gesture_formation::comm

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

}  // namespace gesture_formation::comm

#include "gesture_formation/comm/fault_channel.hpp"

namespace gesture_formation::comm {

const common::FieldTable<FaultChannelConfig>& faultChannelFields() {
  using common::Range;
  using C = FaultChannelConfig;
  static const common::FieldTable<C> t{{
      {"delay_s", Range::nonNegative(), [](C& c) { return &c.delay_s; }},
      {"jitter_s", Range::nonNegative(), [](C& c) { return &c.jitter_s; }},
      {"loss", Range::closed(0.0, 1.0), [](C& c) { return &c.loss_probability; }},
      {"duplicate", Range::closed(0.0, 1.0), [](C& c) { return &c.duplicate_probability; }},
      {"reorder", Range::closed(0.0, 1.0), [](C& c) { return &c.reorder_probability; }},
      {"reorder_extra_delay_s", Range::nonNegative(), [](C& c) { return &c.reorder_extra_delay_s; }},
  }};
  return t;
}

std::vector<std::string> FaultChannelConfig::validate() const {
  auto e = faultChannelFields().rangeProblems(*this);
  if (!common::Range::nonNegative().contains(duplicate_extra_delay_s)) {
    e.push_back({"duplicate_extra_delay_s", common::rangeProblem(common::Range::nonNegative(), duplicate_extra_delay_s)});
  }
  return common::problemLines(e);
}

}  // namespace gesture_formation::comm

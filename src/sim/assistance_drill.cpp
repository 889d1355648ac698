#include "gesture_formation/sim/assistance_drill.hpp"

#include <cmath>
#include <sstream>

#include "gesture_formation/common/csv.hpp"

namespace gesture_formation::sim {

using common::ConfigReader;
using common::Range;

void readAssistanceAcks(ConfigReader& r, const std::string& key, std::vector<double>& out) {
  if (!r.has(key)) return;
  r.readDoubleList(key, out, 0, 1000, Range::nonNegative());
  for (std::size_t i = 1; i < out.size(); ++i) {
    if (out[i] < out[i - 1]) {
      std::ostringstream os;
      os << "must be in time order: " << out[i] << " s after " << out[i - 1] << " s";
      r.addError(key + "[" + std::to_string(i) + "]", os.str());
    }
  }
}

void AssistanceDrill::request(double t_s) {
  if (latch_.request(t_s, "gesture")) {
    summary_.requested_s.push_back(t_s);
  } else {
    ++summary_.repeats_while_pending;
  }
}

void AssistanceDrill::acknowledgeDue(double t_s) {
  for (; next_ack_ < acks_s_.size() && acks_s_[next_ack_] <= t_s + 1e-9; ++next_ack_) {
    if (latch_.acknowledge(latch_.state().requested_s, t_s, "operator")) {
      summary_.acknowledged_s.push_back(t_s);
    } else {
      ++summary_.acks_without_request;
    }
  }
}

std::optional<std::string> AssistanceDrill::refusal(formation::CommandSource source) {
  std::optional<std::string> why = latch_.refusal(source);
  if (why) {
    ++summary_.gesture_commands_refused;
  } else if (pending()) {
    ++summary_.operator_commands_while_pending;
  }
  return why;
}

void AssistanceDrill::leaderChanged() {
  if (pending()) ++summary_.requests_lost_at_handover;
  latch_ = formation::AssistanceLatch{};
}

std::optional<AssistanceSummary> AssistanceDrill::summary() const {
  if (summary_.requested_s.empty() && acks_s_.empty()) return std::nullopt;
  AssistanceSummary s = summary_;
  s.pending_at_end = pending();
  return s;
}

std::string assistanceJson(const AssistanceSummary& s, int indent) {
  const std::string in(static_cast<std::size_t>(indent), ' '), in2 = in + "  ";
  const auto list = [](const std::vector<double>& v) {
    std::string out = "[";
    for (std::size_t i = 0; i < v.size(); ++i) {
      out += (i ? ", " : "") + (std::isfinite(v[i]) ? common::formatDouble(v[i]) : std::string("null"));
    }
    return out + "]";
  };
  std::ostringstream os;
  os << "{\n" << in2 << "\"requested_s\": " << list(s.requested_s) << ",\n";
  os << in2 << "\"acknowledged_s\": " << list(s.acknowledged_s) << ",\n";
  os << in2 << "\"repeats_while_pending\": " << s.repeats_while_pending << ",\n";
  os << in2 << "\"acks_without_request\": " << s.acks_without_request << ",\n";
  os << in2 << "\"gesture_commands_refused\": " << s.gesture_commands_refused << ",\n";
  os << in2 << "\"operator_commands_while_pending\": " << s.operator_commands_while_pending << ",\n";
  os << in2 << "\"requests_lost_at_handover\": " << s.requests_lost_at_handover << ",\n";
  os << in2 << "\"pending_at_end\": " << (s.pending_at_end ? "true" : "false") << "\n" << in << "}";
  return os.str();
}

}  // namespace gesture_formation::sim

#include "gesture_formation/comm/rejection_report.hpp"

#include <algorithm>

namespace gesture_formation::comm {

DiagnosticEntry RejectionReport::entry(const std::string& name, std::uint64_t refused, std::uint64_t& last,
                                       const char* what) const {
  DiagnosticEntry e;
  e.name = prefix_ + ": " + name;
  e.warn = refused > last;
  e.message = e.warn ? std::to_string(refused - last) + " refused in the last second" + what
                     : "no refusals in the last second";
  last = refused;
  return e;
}

DiagnosticEntry RejectionReport::link(const VerifierCounters& counters,
                                      const std::map<std::uint16_t, SenderCounters>& senders,
                                      const std::vector<std::pair<std::string, std::uint64_t>>& extra,
                                      const std::vector<std::string>& extra_refusals) {
  std::uint64_t decode_failures = 0;
  for (const auto& [id, sc] : senders) decode_failures += sc.decode_failures;
  std::uint64_t refused = counters.rejected() + decode_failures;
  for (const auto& [key, value] : extra) {
    if (std::find(extra_refusals.begin(), extra_refusals.end(), key) != extra_refusals.end()) refused += value;
  }
  DiagnosticEntry e = entry("link", refused, last_link_refused_, "");
  for (std::size_t v = 0; v < kVerdictCount; ++v) e.values.emplace_back(toString(static_cast<Verdict>(v)), counters.by_verdict[v]);
  e.values.emplace_back("decode_failure", decode_failures);
  e.values.insert(e.values.end(), extra.begin(), extra.end());
  return e;
}

DiagnosticEntry RejectionReport::sender(std::uint16_t sender, const SenderCounters& counters) {
  std::uint64_t refused = counters.decode_failures;
  std::vector<std::pair<std::string, std::uint64_t>> values;
  for (std::size_t v = 0; v < kVerdictCount; ++v) {
    const auto verdict = static_cast<Verdict>(v);
    if (verdict == Verdict::kOwnMessage) continue;
    values.emplace_back(toString(verdict), counters.by_verdict[v]);
    if (verdict != Verdict::kAccepted) refused += counters.by_verdict[v];
  }
  values.emplace_back("decode_failure", counters.decode_failures);
  DiagnosticEntry e = entry("from sender " + std::to_string(sender), refused, last_sender_refused_[sender],
                            " (claimed sender id)");
  e.values = std::move(values);
  return e;
}

}  // namespace gesture_formation::comm

#pragma once
/// \file
/// \brief The link's health as diagnostics (docs/security.md §6): per verdict counts of the
/// whole link and of every claimed sender, and whether anything was refused since the previous
/// report. ROS-free: the LcmBridge nodelet converts each entry to a diagnostic_msgs status.
/// Not thread-safe (the caller's lock).

#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "gesture_formation/comm/verifier.hpp"

namespace gesture_formation::comm {

/// \brief One diagnostic status: a name, warn or ok, a message and named counts.
struct DiagnosticEntry {
  std::string name;
  bool warn = false;  ///< something was refused since the previous report
  std::string message;
  std::vector<std::pair<std::string, std::uint64_t>> values;
};

/// \brief Turns the verifier's cumulative counters into per-report entries, remembering the
/// totals of the previous report to say what was refused since.
class RejectionReport {
 public:
  /// \param prefix the entries' name prefix, e.g. "LcmBridge sender 1".
  explicit RejectionReport(std::string prefix) : prefix_(std::move(prefix)) {}

  /// \brief The whole link: every verdict, the decode failures summed over the senders, and
  /// `extra` counts (transport and bridge counters) of which those named in `extra_refusals`
  /// also count as refusals.
  DiagnosticEntry link(const VerifierCounters& counters, const std::map<std::uint16_t, SenderCounters>& senders,
                       const std::vector<std::pair<std::string, std::uint64_t>>& extra,
                       const std::vector<std::string>& extra_refusals);
  /// \brief One claimed sender: every verdict but the own-message one, and its decode failures.
  DiagnosticEntry sender(std::uint16_t sender, const SenderCounters& counters);

 private:
  DiagnosticEntry entry(const std::string& name, std::uint64_t refused, std::uint64_t& last, const char* what) const;

  std::string prefix_;
  std::uint64_t last_link_refused_ = 0;
  std::map<std::uint16_t, std::uint64_t> last_sender_refused_;
};

}  // namespace gesture_formation::comm

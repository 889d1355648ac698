#pragma once
/// \file
/// \brief The simulator's side of the worker's assistance request (docs/safety.md §2.10,
/// docs/simulation.md §3): the operator's scripted acknowledgements (`mission.assistance_acks_s`),
/// the acting leader's formation::AssistanceLatch — the one the ROS leader's FormationPlanner keeps —
/// fed by a recognised gesture mapped to {event: assist_requested}, and the metrics (metrics.json
/// `assistance`). While a request is pending the leader refuses the worker's gesture commands and
/// applies the operator's, as onboard. Thread safety: value type; one per mission.

#include <optional>
#include <string>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/formation/assistance.hpp"

namespace gesture_formation::sim {

/// \brief Reads `mission.assistance_acks_s` at `key`: the times (s, ≥ 0, ascending) at which the
/// operator's acknowledgement of the pending request reaches the acting leader. Absent: none.
/// Problems recorded in `r`, each naming its key and value.
void readAssistanceAcks(common::ConfigReader& r, const std::string& key, std::vector<double>& out);

/// \brief metrics.json `assistance` (present when a request was made or an acknowledgement scripted).
struct AssistanceSummary {
  std::vector<double> requested_s;     ///< each latched request (a repeat while pending is not one)
  std::vector<double> acknowledged_s;  ///< each acknowledgement that released a request
  int repeats_while_pending = 0;       ///< assist gestures fired while one was pending (kept its time)
  int acks_without_request = 0;        ///< scripted acknowledgements with nothing pending (ignored)
  int gesture_commands_refused = 0;    ///< the worker's commands refused while pending
  int operator_commands_while_pending = 0;  ///< operator commands that reached the leader while pending
  int requests_lost_at_handover = 0;   ///< pending when another UAV took the leadership over
  bool pending_at_end = false;
};

/// \brief The acting leader's latch and the operator's scripted acknowledgements.
class AssistanceDrill {
 public:
  explicit AssistanceDrill(std::vector<double> acks_s) : acks_s_(std::move(acks_s)) {}
  /// \brief The leader's pipeline recognised {event: assist_requested} at t_s.
  void request(double t_s);
  /// \brief Acknowledgements due by t_s: each releases the request pending then (the operator
  /// acknowledges the request it was alerted of, named by its time).
  void acknowledgeDue(double t_s);
  /// \brief Why a command from `source` must be refused now (counted), nullopt: apply it.
  std::optional<std::string> refusal(formation::CommandSource source);
  /// \brief Another UAV took the leadership over: a pending request is lost with the old leader
  /// (the latch is the leader's, docs/safety.md §2.10, "Limits").
  void leaderChanged();
  bool pending() const { return latch_.state().phase == formation::AssistancePhase::kRequested; }
  /// \brief The summary, or nullopt when the mission had neither a request nor a scripted acknowledgement.
  std::optional<AssistanceSummary> summary() const;

 private:
  std::vector<double> acks_s_;
  std::size_t next_ack_ = 0;
  formation::AssistanceLatch latch_;
  AssistanceSummary summary_;
};

/// \brief The summary as a JSON object (non-finite → null), indented by `indent`.
std::string assistanceJson(const AssistanceSummary& summary, int indent);

}  // namespace gesture_formation::sim

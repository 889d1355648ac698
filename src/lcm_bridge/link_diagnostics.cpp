#include "gesture_formation/lcm_bridge/link_diagnostics.hpp"

namespace gesture_formation::lcm_bridge {

std::vector<comm::DiagnosticEntry> linkDiagnostics(comm::RejectionReport& report, SecureLink& link,
                                                   const LcmTransport& transport, const comm::LinkInbox& inbox) {
  const auto senders = link.verifier().senderCounters();
  const auto& t = transport.counters();
  std::vector<comm::DiagnosticEntry> out{report.link(link.verifierCounters(), senders,
                                                     {{"channel_mismatch", link.channelMismatches()},
                                                      {"undecodable_lcm", t.undecodable},
                                                      {"received_lcm", t.received},
                                                      {"published", t.published},
                                                      {"publish_failed", t.publish_failed},
                                                      {"command_copies_dropped", inbox.commandCopiesDropped()},
                                                      {"observations_refused", inbox.observationsRefused()},
                                                      {"plans_refused", inbox.plansRefused()},
                                                      {"leadership_refused", inbox.leadershipRefused()},
                                                      {"map_updates_refused", inbox.mapUpdatesRefused()}},
                                                     {"channel_mismatch", "undecodable_lcm"})};
  for (const auto& [sender, counters] : senders) out.push_back(report.sender(sender, counters));
  return out;
}

}  // namespace gesture_formation::lcm_bridge

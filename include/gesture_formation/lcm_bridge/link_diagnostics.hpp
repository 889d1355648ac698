#pragma once
/// \file
/// \brief A node's link on /diagnostics (the LcmBridge's statuses), ROS-free: one entry for the
/// link — every verifier verdict, the transport's counts, the receive side's (comm::LinkInbox)
/// dropped command copies and refused observations — and one per known sender, each with what
/// was refused since the last report (comm::RejectionReport). Library `gesture_formation_lcm`.
/// Thread safety: none (the caller's lock).

#include <vector>

#include "gesture_formation/comm/link_inbox.hpp"
#include "gesture_formation/comm/rejection_report.hpp"
#include "gesture_formation/lcm_bridge/lcm_transport.hpp"

namespace gesture_formation::lcm_bridge {

/// \brief The link's entry, then one per sender (`report` remembers what it reported last).
std::vector<comm::DiagnosticEntry> linkDiagnostics(comm::RejectionReport& report, SecureLink& link,
                                                   const LcmTransport& transport, const comm::LinkInbox& inbox);

}  // namespace gesture_formation::lcm_bridge

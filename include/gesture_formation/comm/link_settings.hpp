#pragma once
/// \file
/// \brief The receiving side of an inter-UAV link as configured (the LcmBridge's parameters,
/// docs/security.md §4, §7) turned into a VerifierConfig, with every problem found at once: each
/// field, the sender lists, and the verifier's own rules between fields run whatever else is
/// wrong, so a user sees the whole list on the first start. ROS-free.

#include <optional>
#include <string>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/comm/key_ring.hpp"
#include "gesture_formation/comm/verifier.hpp"

namespace gesture_formation::comm {

/// \brief The link's settings as a node is given them (integers not yet checked).
struct LinkSettings {
  int sender_id = 0;                    ///< this node, [0, 65535]
  std::vector<int> known_senders;       ///< the fleet's ids (own id ignored)
  double max_age_s = 1.0;               ///< age limit of every type without its own
  double command_max_age_s = 5.0;       ///< formation commands, (0, 60]
  int recv_buf_bytes = 4194304;         ///< UDP receive buffer to ask for, ≥ 65536
  double max_rate_hz = 400.0;           ///< per-sender verification budget
  double burst = 200.0;
  /// Who may send formation commands / parameters / abort commands (absent: any known sender);
  /// command acknowledgements (MessageType::kCommandAck) come from the params_senders.
  std::optional<std::vector<int>> command_senders, params_senders, abort_senders;
};

/// \brief The VerifierConfig of `s` (heartbeats: at least 2 s of age; formation and abort commands:
/// command_max_age_s), and in `problems` everything wrong with it, keyed by parameter name.
VerifierConfig verifierConfigOf(const LinkSettings& s, std::vector<common::ConfigError>& problems);

/// \brief A problem when a per-sender key ring's signing key is not `sender_id`'s (empty: fine).
std::optional<common::ConfigError> keyRingOwnerProblem(const KeyRing& keys, int sender_id);

/// \brief The optional settings as one line (a node's "loaded" report): ages, buffer, budget and
/// how many ids each sender list holds.
std::string describeOptional(const LinkSettings& s);
/// \brief `url` with recv_buf_size=bytes added for udpm:// URLs that do not set it.
std::string withReceiveBuffer(const std::string& url, int bytes);

}  // namespace gesture_formation::comm

#pragma once
/// \file
/// \brief Starting a node's authenticated link (the LcmBridge's start-up, docs/security.md §4, §5),
/// ROS-free: the link's settings checked (comm::verifierConfigOf), the key file loaded and matched
/// to this sender, the LCM transport opened, the boot counter advanced (the high bits of this
/// sender's sequence numbers), the receiver's high-water marks restored and the verifier built.
/// Every problem is reported at once where the steps allow it (settings and key file together;
/// the transport, the state files and the verifier only when those were fine), each keyed by the
/// parameter that caused it. Library `gesture_formation_lcm`.
/// Thread safety: startLink is reentrant; HighWaterMarkSaver has no locking (the caller's lock).

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gesture_formation/comm/link_settings.hpp"
#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/lcm_bridge/lcm_transport.hpp"

namespace gesture_formation::lcm_bridge {

/// \brief What a node's link is started from (the LcmBridge's parameters).
struct LinkStartupConfig {
  comm::LinkSettings link;       ///< sender id, fleet, ages, budgets, who may send what
  std::string lcm_url;           ///< e.g. udpm://239.255.76.67:7667?ttl=0 (receive buffer added)
  std::string channel_prefix;    ///< e.g. GF_
  std::string key_file;          ///< owner-only key file (comm::loadKeyFile); empty: a problem
  std::string state_dir;         ///< created 0700 when a state file lives in it (comm::ensureStateDirectory)
  std::string sequence_file;     ///< the boot counter (comm::advanceBootCounter)
  std::string marks_file;        ///< the high-water marks (comm::loadHighWaterMarks)
};

/// \brief A started link: the transport, the link over it, and what start-up found.
struct StartedLink {
  std::unique_ptr<LcmTransport> transport;  ///< must outlive `link` (destroy link first)
  std::unique_ptr<SecureLink> link;
  std::uint32_t boot = 0;                   ///< this start's boot counter
  std::uint64_t first_sequence = 0;         ///< comm::firstSequenceOfBoot(boot)
  std::size_t restored_marks = 0;           ///< senders whose high-water mark was restored
  bool per_sender_keys = false;             ///< false: a group key (any holder can speak for any sender)
};

/// \brief The problems of `config`'s settings and key file, without opening or writing anything
/// (what a node reports beside its other parameter problems before it refuses to start).
std::vector<common::ConfigError> checkLinkStartup(const LinkStartupConfig& config);

/// \brief Starts the link of `config` (see the file comment); `clock` stamps and ages envelopes.
/// Empty on any problem, each appended to `problems` keyed by its parameter (key_file, lcm_url,
/// sequence_file, high_water_file, known_senders, …).
std::optional<StartedLink> startLink(const LinkStartupConfig& config, SecureLink::Clock clock,
                                     std::vector<common::ConfigError>& problems);

/// \brief "boot B (sequence numbers from S), restored high-water marks of K sender(s)".
std::string describe(const StartedLink& link);

/// \brief Saves a verifier's high-water marks to a file when they changed since the last save.
class HighWaterMarkSaver {
 public:
  explicit HighWaterMarkSaver(std::string path = "") : path_(std::move(path)) {}
  /// \brief Writes `marks` when non-empty and different from the last saved; fails naming the file.
  common::Result<bool> save(const std::map<std::uint16_t, std::uint64_t>& marks);

 private:
  std::string path_;
  std::map<std::uint16_t, std::uint64_t> saved_;
};

}  // namespace gesture_formation::lcm_bridge

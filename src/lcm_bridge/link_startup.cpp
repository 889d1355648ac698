#include "gesture_formation/lcm_bridge/link_startup.hpp"

#include <utility>

#include "gesture_formation/comm/key_ring.hpp"
#include "gesture_formation/comm/sequence_store.hpp"
#include "gesture_formation/comm/verifier.hpp"

namespace gesture_formation::lcm_bridge {

namespace {

/// The keys of `config`, checked against its sender id; problems keyed key_file.
std::optional<comm::KeyRing> loadKeys(const LinkStartupConfig& config, std::vector<common::ConfigError>& problems) {
  if (config.key_file.empty()) {
    problems.push_back({"key_file", "missing (required)"});
    return std::nullopt;
  }
  auto keys = comm::loadKeyFile(config.key_file);
  if (!keys) {
    problems.push_back({"key_file", keys.reason()});
    return std::nullopt;
  }
  if (const auto e = comm::keyRingOwnerProblem(*keys, config.link.sender_id)) {
    problems.push_back(*e);
    return std::nullopt;
  }
  return std::move(*keys);
}

}  // namespace

std::vector<common::ConfigError> checkLinkStartup(const LinkStartupConfig& config) {
  std::vector<common::ConfigError> problems;
  comm::verifierConfigOf(config.link, problems);
  loadKeys(config, problems);
  return problems;
}

std::optional<StartedLink> startLink(const LinkStartupConfig& config, SecureLink::Clock clock,
                                     std::vector<common::ConfigError>& problems) {
  const std::size_t before = problems.size();
  const comm::VerifierConfig vcfg = comm::verifierConfigOf(config.link, problems);
  std::optional<comm::KeyRing> keys = loadKeys(config, problems);
  if (problems.size() != before) return std::nullopt;

  StartedLink out;
  auto transport = LcmTransport::create(comm::withReceiveBuffer(config.lcm_url, config.link.recv_buf_bytes),
                                        config.channel_prefix);
  if (!transport) {
    problems.push_back({"lcm_url", transport.reason()});
    return std::nullopt;
  }
  out.transport = std::move(*transport);

  comm::ensureStateDirectory(config.state_dir, {config.sequence_file, config.marks_file});
  auto boot = comm::advanceBootCounter(config.sequence_file);
  if (!boot) problems.push_back({"sequence_file", boot.reason()});
  auto marks = comm::loadHighWaterMarks(config.marks_file);
  if (!marks) problems.push_back({"high_water_file", marks.reason()});
  if (problems.size() != before) return std::nullopt;

  out.per_sender_keys = keys->perSender();
  auto verifier = comm::Verifier::create(vcfg, *keys);
  if (!verifier) {
    problems.push_back({"key_file/known_senders", verifier.reason()});
    return std::nullopt;
  }
  verifier->restoreHighWaterMarks(marks.value());
  out.boot = boot.value();
  out.first_sequence = comm::firstSequenceOfBoot(out.boot);
  out.restored_marks = marks.value().size();
  out.link = std::make_unique<SecureLink>(
      *out.transport, comm::Signer(static_cast<std::uint16_t>(config.link.sender_id), *keys, out.first_sequence),
      std::move(*verifier), std::move(clock));
  return out;
}

std::string describe(const StartedLink& link) {
  return "boot " + std::to_string(link.boot) + " (sequence numbers from " + std::to_string(link.first_sequence) +
         "), restored high-water marks of " + std::to_string(link.restored_marks) + " sender(s)";
}

common::Result<bool> HighWaterMarkSaver::save(const std::map<std::uint16_t, std::uint64_t>& marks) {
  if (path_.empty() || marks.empty() || marks == saved_) return common::Result<bool>::ok(false);
  auto r = comm::saveHighWaterMarks(path_, marks);
  if (!r) return r;
  saved_ = marks;
  return common::Result<bool>::ok(true);
}

}  // namespace gesture_formation::lcm_bridge

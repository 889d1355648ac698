#pragma once
/// \file
/// \brief LCM glue for authenticated envelopes (library `gesture_formation_lcm`, not part of
/// the core): LcmTransport moves sealed envelope bytes over an lcm::LCM URL, one channel per
/// message type; SecureLink adds the comm::Signer / comm::Verifier on top. This header does
/// not include LCM headers (pimpl), so users need no LCM include paths.
///
/// URLs: `memq://` (in-process, tests), `udpm://239.255.76.67:7667?ttl=0` (multicast, kept
/// on this host by ttl=0 and a private network namespace; docs/security.md §7).
/// Thread safety: none; publish and handle from one thread (LCM's handle thread), or guard.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gesture_formation/comm/envelope.hpp"
#include "gesture_formation/comm/payloads.hpp"
#include "gesture_formation/comm/signer.hpp"
#include "gesture_formation/comm/verifier.hpp"
#include "gesture_formation/common/result.hpp"

namespace gesture_formation::lcm_bridge {

/// \brief The channel of a message type: prefix + HEARTBEAT | WORKER_STATE |
/// PLANNED_TRAJECTORY | FORMATION_PARAMS | FORMATION_COMMAND | GESTURE_OBSERVATION | ABORT_COMMAND.
std::string channelName(comm::MessageType type, const std::string& prefix);
/// \brief The message type a channel carries, or nothing for foreign channels.
std::optional<comm::MessageType> channelType(const std::string& channel, const std::string& prefix);

/// \brief LCM encoding of gf_lcm::envelope_t (fingerprint, length, bytes). Empty when
/// `sealed` is larger than comm::kMaxEnvelopeBytes.
std::vector<std::uint8_t> encodeLcmEnvelope(const std::vector<std::uint8_t>& sealed);
/// \brief Decodes gf_lcm::envelope_t. The length is checked against the buffer and
/// comm::kMaxEnvelopeBytes before lcm-gen's decoder runs (it would resize to any length).
/// `sealed` is written only on success.
bool decodeLcmEnvelope(const void* data, std::size_t size, std::vector<std::uint8_t>& sealed);

/// \brief One LCM short message (one UDP datagram of an udpm:// URL): "LC02", a 32-bit
/// sequence number, the channel name ending in a NUL byte, then the message bytes.
struct LcmDatagram {
  std::string channel;
  const std::uint8_t* data = nullptr;  ///< into the datagram
  std::size_t size = 0;
};
/// \brief Parses an LCM short-message datagram; false for anything else (fragments of messages
/// larger than ~64 kB, which our envelopes never are, foreign or garbage datagrams).
bool parseLcmDatagram(const std::uint8_t* data, std::size_t size, LcmDatagram& out);

/// \brief Publishes and receives envelope bytes on the per-type channels. With a udpm:// URL
/// it publishes through LCM but receives on a multicast socket of its own, read in batches
/// (recvmmsg) with the cheap checks — LCM datagram, our channel, envelope length — before any
/// copy: under a flood of datagrams the legitimate ones are not lost behind LCM's per-message
/// receive thread, queue and notification pipe (docs/security.md, floods). memq:// uses LCM.
class LcmTransport {
 public:
  /// Called for every well-formed gf_lcm::envelope_t on one of our channels.
  using Handler = std::function<void(comm::MessageType channel_type, const std::vector<std::uint8_t>& sealed)>;

  struct Counters {
    std::uint64_t published = 0;
    std::uint64_t publish_failed = 0;
    std::uint64_t received = 0;
    std::uint64_t undecodable = 0;  ///< not a gf_lcm::envelope_t (bad fingerprint / length)
  };

  /// \brief Opens the LCM instance; fails naming the URL.
  static common::Result<std::unique_ptr<LcmTransport>> create(const std::string& url,
                                                              const std::string& channel_prefix = "GF_");
  ~LcmTransport();
  LcmTransport(const LcmTransport&) = delete;
  LcmTransport& operator=(const LcmTransport&) = delete;

  /// \brief Publishes sealed bytes on the channel of `type`. False on an LCM error or oversize.
  bool publish(comm::MessageType type, const std::vector<std::uint8_t>& sealed);
  /// \brief Subscribes to all message channels (replaces a previous handler).
  void setHandler(Handler handler);
  /// \brief Dispatches at most one pending LCM message, waiting up to timeout_ms.
  /// Returns > 0 when one was handled, 0 on timeout, < 0 on error.
  int handle(int timeout_ms);
  /// \brief Handles the messages already queued (non-blocking), at most `max_messages`, so a
  /// flood cannot hold the caller forever; returns how many.
  int drain(int max_messages = std::numeric_limits<int>::max());
  const Counters& counters() const { return counters_; }
  const std::string& prefix() const { return prefix_; }

 private:
  struct Impl;
  LcmTransport(std::unique_ptr<Impl> impl, std::string prefix);
  std::unique_ptr<Impl> impl_;
  std::string prefix_;
  Handler handler_;
  Counters counters_;
  friend struct Impl;
};

/// \brief Authenticated messaging over an LcmTransport: seals on publish, verifies on
/// receive (docs/security.md), checks that each envelope arrived on its type's channel.
class SecureLink {
 public:
  using EnvelopeHandler = std::function<void(const comm::Envelope&)>;
  /// Called with every refused envelope (not our own echoes) and the sender id it claims,
  /// when the datagram was well-formed enough to carry one.
  using RejectHandler = std::function<void(const comm::VerifyResult&, std::optional<std::uint16_t> claimed_sender)>;
  using Clock = std::function<double()>;  ///< now [s], same clock as the stamps

  /// `transport` must outlive the link.
  /// Installs itself as the transport's handler.
  SecureLink(LcmTransport& transport, comm::Signer signer, comm::Verifier verifier, Clock clock);
  SecureLink(const SecureLink&) = delete;  // the transport's handler points here
  SecureLink& operator=(const SecureLink&) = delete;

  /// \brief Encodes, seals (stamp = clock()) and publishes a payload; returns the sequence used.
  template <class T>
  common::Result<std::uint64_t> publish(const T& message) {
    auto payload = comm::encodePayload(message);
    if (!payload) return common::Result<std::uint64_t>::fail(payload.reason());
    return publishPayload(comm::messageTypeOf(message), payload.value());
  }
  common::Result<std::uint64_t> publishPayload(comm::MessageType type, const std::vector<std::uint8_t>& payload);

  /// \brief Called with every accepted envelope (payload still to decode: comm::PayloadDecoder).
  void setHandler(EnvelopeHandler handler) { handler_ = std::move(handler); }
  void setRejectHandler(RejectHandler handler) { reject_handler_ = std::move(handler); }

  const comm::VerifierCounters& verifierCounters() const { return verifier_.counters(); }
  std::uint64_t channelMismatches() const { return channel_mismatch_; }
  comm::Signer& signer() { return signer_; }
  comm::Verifier& verifier() { return verifier_; }

 private:
  void onSealed(comm::MessageType channel_type, const std::vector<std::uint8_t>& sealed);

  LcmTransport& transport_;
  comm::Signer signer_;
  comm::Verifier verifier_;
  Clock clock_;
  EnvelopeHandler handler_;
  RejectHandler reject_handler_;
  std::uint64_t channel_mismatch_ = 0;
};

}  // namespace gesture_formation::lcm_bridge

#pragma once
/// \file
/// \brief The authenticated envelope every inter-UAV message travels in (docs/security.md §3).
///
/// Wire layout, all integers big-endian (network order), doubles IEEE-754 binary64 big-endian:
/// ```
/// offset size field
///      0    2 magic 'G' 'F' (0x47 0x46)
///      2    1 version: 1 = group HMAC tag (32 B), 2 = per-sender Ed25519 signature (64 B)
///      3    1 message type (MessageType, 1..11)
///      4    2 sender id
///      6    1 key id (which pre-shared key made the tag)
///      7    1 flags (reserved, must be 0)
///      8    8 sequence number (per sender, strictly increasing over all types)
///     16    8 stamp [s] (sender clock; finite)
///     24    4 payload length N ≤ kMaxPayloadBytes
///     28    N payload (MessageType-specific, payloads.hpp)
///   28+N    T tag over bytes 0 .. 28+N−1: version 1 HMAC-SHA256(group key[key id]) (T = 32),
///             version 2 Ed25519(sender's secret key[key id]) (T = 64)
/// ```
/// Total size = 28 + N + T bytes; the length field must match the datagram size exactly.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "gesture_formation/comm/ed25519.hpp"
#include "gesture_formation/comm/hmac.hpp"
#include "gesture_formation/common/result.hpp"

namespace gesture_formation::comm {

constexpr std::uint8_t kMagic0 = 0x47;  // 'G'
constexpr std::uint8_t kMagic1 = 0x46;  // 'F'
/// Version 1: tag = HMAC-SHA256 with a group key (any key holder can claim any sender id).
constexpr std::uint8_t kEnvelopeVersion = 1;
constexpr std::uint8_t kEnvelopeVersionHmac = 1;
/// Version 2: tag = Ed25519 signature with the sender's own key (docs/security.md §5).
constexpr std::uint8_t kEnvelopeVersionEd25519 = 2;
constexpr std::size_t kHeaderBytes = 28;
/// Largest tag of any version [bytes].
constexpr std::size_t kMaxTagBytes = kEd25519SignatureBytes;
/// \brief Tag length of an envelope version [bytes]; 0 for an unknown version.
constexpr std::size_t tagBytes(std::uint8_t version) {
  return version == kEnvelopeVersionHmac ? kTagBytes : version == kEnvelopeVersionEd25519 ? kEd25519SignatureBytes : 0;
}
/// Absolute times on the wire (envelope stamps and the payloads' times, s: since the epoch onboard,
/// since the start in simulation) lie in [0, kMaxWireTimeS): what a ROS time holds (2^32 s), with
/// margin. Encoders and decoders refuse any other, naming the field — a receiver turns them into
/// ros::Time, which throws outside that range.
constexpr double kMaxWireTimeS = 4.0e9;
inline bool isWireTime(double t_s) { return t_s >= 0.0 && t_s < kMaxWireTimeS; }
/// Largest payload [bytes]: fits a planned trajectory of kMaxTrajectorySamples samples and
/// stays below LCM's 64 KiB single-datagram limit with the header and tag.
constexpr std::size_t kMaxPayloadBytes = 60000;
/// Smallest envelope of any version (version 1, empty payload) [bytes].
constexpr std::size_t kMinEnvelopeBytes = kHeaderBytes + kTagBytes;
/// Largest envelope of any version (version 2, largest payload) [bytes].
constexpr std::size_t kMaxEnvelopeBytes = kHeaderBytes + kMaxPayloadBytes + kMaxTagBytes;

/// \brief What a payload holds (payloads.hpp). Values are wire constants: never renumber.
enum class MessageType : std::uint8_t {
  kHeartbeat = 1,
  kWorkerState = 2,
  kPlannedTrajectory = 3,
  kFormationParams = 4,
  kFormationCommand = 5,
  kGestureObservation = 6,
  kAbortCommand = 7,
  kCommandAck = 8,
  kAssistance = 9,
  kLeadership = 10,
  kMapUpdate = 11,  ///< comm/map_update.hpp
};
constexpr std::uint8_t kMinMessageType = 1;
constexpr std::uint8_t kMaxMessageType = 11;
/// \brief "heartbeat", "worker_state", "planned_trajectory", "formation_params", "formation_command",
/// "gesture_observation", "abort_command", "command_ack", "assistance", "leadership", "map_update".
const char* toString(MessageType type);
bool isKnownMessageType(std::uint8_t value);

/// \brief The header fields of an envelope (what the tag authenticates besides the payload).
struct EnvelopeHeader {
  std::uint8_t version = kEnvelopeVersionHmac;  ///< set by the sealing function / parser
  MessageType type = MessageType::kHeartbeat;
  std::uint16_t sender_id = 0;
  std::uint8_t key_id = 0;
  std::uint64_t sequence = 0;
  double stamp_s = 0.0;
};

/// \brief A decoded (and, from Verifier, authenticated) envelope.
struct Envelope : EnvelopeHeader {
  std::vector<std::uint8_t> payload;
};

/// \brief Why bytes are not a well-formed envelope (checked before authentication).
enum class EnvelopeError {
  kNone,
  kTruncated,       ///< shorter than header + tag, or than the length field says
  kOversize,        ///< larger than kMaxEnvelopeBytes or payload length > kMaxPayloadBytes
  kBadMagic,
  kBadVersion,
  kBadType,
  kBadFlags,
  kLengthMismatch,  ///< longer than the length field says (trailing bytes)
  kBadStamp,        ///< stamp not a wire time (isWireTime: finite, in [0, kMaxWireTimeS))
};
const char* toString(EnvelopeError e);

/// \brief A structurally valid envelope, borrowing the input buffer (not yet authenticated).
struct EnvelopeView : EnvelopeHeader {
  const std::uint8_t* payload = nullptr;
  std::size_t payload_bytes = 0;
  const std::uint8_t* signed_bytes = nullptr;  ///< header + payload (what the tag covers)
  std::size_t signed_size = 0;
  const std::uint8_t* tag = nullptr;           ///< tagBytes(version) bytes
};

/// \brief Checks the structure (sizes, magic, version, type, flags, length, stamp) and fills
/// `view`; `view` is untouched on error. Never reads outside [data, data + size).
EnvelopeError parseEnvelope(const std::uint8_t* data, std::size_t size, EnvelopeView& view);

/// \brief Version 1: serialises and tags an envelope with the group HMAC `key` (whose id must
/// be envelope.key_id; envelope.version is ignored).
/// Fails on a payload above kMaxPayloadBytes, a non-finite stamp, an unknown type, or an
/// OpenSSL failure. Signer is the normal way in; this is the primitive.
common::Result<std::vector<std::uint8_t>> sealEnvelope(const Envelope& envelope, const std::uint8_t* key,
                                                       std::size_t key_bytes);

/// \brief Version 2: serialises and signs an envelope with the sender's Ed25519 secret `seed`
/// (kEd25519SeedBytes; its id must be envelope.key_id). Same failures as sealEnvelope.
common::Result<std::vector<std::uint8_t>> sealEnvelopeEd25519(const Envelope& envelope, const std::uint8_t* seed);

}  // namespace gesture_formation::comm

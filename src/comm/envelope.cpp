#include "gesture_formation/comm/envelope.hpp"

#include <cmath>
#include <string>

#include "gesture_formation/comm/byte_io.hpp"

namespace gesture_formation::comm {

const char* toString(MessageType type) {
  switch (type) {
    case MessageType::kHeartbeat: return "heartbeat";
    case MessageType::kWorkerState: return "worker_state";
    case MessageType::kPlannedTrajectory: return "planned_trajectory";
    case MessageType::kFormationParams: return "formation_params";
    case MessageType::kFormationCommand: return "formation_command";
    case MessageType::kGestureObservation: return "gesture_observation";
  }
  return "unknown";
}

bool isKnownMessageType(std::uint8_t value) { return value >= kMinMessageType && value <= kMaxMessageType; }

const char* toString(EnvelopeError e) {
  switch (e) {
    case EnvelopeError::kNone: return "none";
    case EnvelopeError::kTruncated: return "truncated";
    case EnvelopeError::kOversize: return "oversize";
    case EnvelopeError::kBadMagic: return "bad magic";
    case EnvelopeError::kBadVersion: return "bad version";
    case EnvelopeError::kBadType: return "bad message type";
    case EnvelopeError::kBadFlags: return "reserved flags set";
    case EnvelopeError::kLengthMismatch: return "length field does not match size";
    case EnvelopeError::kBadStamp: return "stamp not finite";
  }
  return "unknown";
}

EnvelopeError parseEnvelope(const std::uint8_t* data, std::size_t size, EnvelopeView& view) {
  if (data == nullptr || size < kMinEnvelopeBytes) return EnvelopeError::kTruncated;
  if (size > kMaxEnvelopeBytes) return EnvelopeError::kOversize;
  ByteReader r(data, size);
  std::uint8_t m0 = 0, m1 = 0, version = 0, type = 0, key_id = 0, flags = 0;
  std::uint16_t sender = 0;
  std::uint64_t sequence = 0;
  double stamp = 0.0;
  std::uint32_t length = 0;
  // size ≥ kMinEnvelopeBytes > kHeaderBytes: these reads cannot fail.
  r.u8(m0);
  r.u8(m1);
  r.u8(version);
  r.u8(type);
  r.u16(sender);
  r.u8(key_id);
  r.u8(flags);
  r.u64(sequence);
  r.f64(stamp);
  r.u32(length);
  if (r.failed()) return EnvelopeError::kTruncated;
  if (m0 != kMagic0 || m1 != kMagic1) return EnvelopeError::kBadMagic;
  if (version != kEnvelopeVersion) return EnvelopeError::kBadVersion;
  if (!isKnownMessageType(type)) return EnvelopeError::kBadType;
  if (flags != 0) return EnvelopeError::kBadFlags;
  if (length > kMaxPayloadBytes) return EnvelopeError::kOversize;
  const std::size_t expected = kHeaderBytes + static_cast<std::size_t>(length) + kTagBytes;
  if (size < expected) return EnvelopeError::kTruncated;
  if (size > expected) return EnvelopeError::kLengthMismatch;
  if (!std::isfinite(stamp)) return EnvelopeError::kBadStamp;

  view.type = static_cast<MessageType>(type);
  view.sender_id = sender;
  view.key_id = key_id;
  view.sequence = sequence;
  view.stamp_s = stamp;
  view.payload = data + kHeaderBytes;
  view.payload_bytes = length;
  view.signed_bytes = data;
  view.signed_size = kHeaderBytes + length;
  view.tag = data + kHeaderBytes + length;
  return EnvelopeError::kNone;
}

common::Result<std::vector<std::uint8_t>> sealEnvelope(const Envelope& envelope, const std::uint8_t* key,
                                                       std::size_t key_bytes) {
  using R = common::Result<std::vector<std::uint8_t>>;
  if (envelope.payload.size() > kMaxPayloadBytes) {
    return R::fail("payload of " + std::to_string(envelope.payload.size()) + " bytes exceeds " +
                   std::to_string(kMaxPayloadBytes));
  }
  if (!std::isfinite(envelope.stamp_s)) return R::fail("stamp_s is not finite");
  if (!isKnownMessageType(static_cast<std::uint8_t>(envelope.type))) return R::fail("unknown message type");
  if (key == nullptr || key_bytes == 0) return R::fail("no key");
  ByteWriter w;
  w.u8(kMagic0);
  w.u8(kMagic1);
  w.u8(kEnvelopeVersion);
  w.u8(static_cast<std::uint8_t>(envelope.type));
  w.u16(envelope.sender_id);
  w.u8(envelope.key_id);
  w.u8(0);
  w.u64(envelope.sequence);
  w.f64(envelope.stamp_s);
  w.u32(static_cast<std::uint32_t>(envelope.payload.size()));
  w.bytes(envelope.payload.data(), envelope.payload.size());
  Tag tag{};
  if (!hmacSha256(key, key_bytes, w.buffer().data(), w.size(), tag)) return R::fail("HMAC-SHA256 failed (OpenSSL)");
  w.bytes(tag.data(), tag.size());
  return R::ok(w.release());
}

}  // namespace gesture_formation::comm

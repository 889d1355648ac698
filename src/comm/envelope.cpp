#include "gesture_formation/comm/envelope.hpp"
#include "gesture_formation/comm/wire_time.hpp"

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
    case MessageType::kAbortCommand: return "abort_command";
    case MessageType::kCommandAck: return "command_ack";
    case MessageType::kAssistance: return "assistance";
    case MessageType::kLeadership: return "leadership";
    case MessageType::kMapUpdate: return "map_update";
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
    case EnvelopeError::kBadStamp: return "stamp not a time in [0, 4e9) s";
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
  const std::size_t tag_bytes = tagBytes(version);
  if (tag_bytes == 0) return EnvelopeError::kBadVersion;
  if (!isKnownMessageType(type)) return EnvelopeError::kBadType;
  if (flags != 0) return EnvelopeError::kBadFlags;
  if (length > kMaxPayloadBytes) return EnvelopeError::kOversize;
  const std::size_t expected = kHeaderBytes + static_cast<std::size_t>(length) + tag_bytes;
  if (size < expected) return EnvelopeError::kTruncated;
  if (size > expected) return EnvelopeError::kLengthMismatch;
  if (!isWireTime(stamp)) return EnvelopeError::kBadStamp;

  view.version = version;
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

namespace {

using SealResult = common::Result<std::vector<std::uint8_t>>;

/// Checks the fields and writes header + payload (what the tag covers) with `version`.
SealResult serialiseSigned(const Envelope& envelope, std::uint8_t version) {
  if (envelope.payload.size() > kMaxPayloadBytes) {
    return SealResult::fail("payload of " + std::to_string(envelope.payload.size()) + " bytes exceeds " +
                            std::to_string(kMaxPayloadBytes));
  }
  if (const std::string e = wireTimeProblem(envelope.stamp_s, "stamp_s"); !e.empty()) return SealResult::fail(e);
  if (!isKnownMessageType(static_cast<std::uint8_t>(envelope.type))) return SealResult::fail("unknown message type");
  ByteWriter w;
  w.u8(kMagic0);
  w.u8(kMagic1);
  w.u8(version);
  w.u8(static_cast<std::uint8_t>(envelope.type));
  w.u16(envelope.sender_id);
  w.u8(envelope.key_id);
  w.u8(0);
  w.u64(envelope.sequence);
  w.f64(envelope.stamp_s);
  w.u32(static_cast<std::uint32_t>(envelope.payload.size()));
  w.bytes(envelope.payload.data(), envelope.payload.size());
  return SealResult::ok(w.release());
}

}  // namespace

SealResult sealEnvelope(const Envelope& envelope, const std::uint8_t* key, std::size_t key_bytes) {
  if (key == nullptr || key_bytes == 0) return SealResult::fail("no key");
  SealResult bytes = serialiseSigned(envelope, kEnvelopeVersionHmac);
  if (!bytes) return bytes;
  std::vector<std::uint8_t> out = std::move(bytes.value());
  Tag tag{};
  if (!hmacSha256(key, key_bytes, out.data(), out.size(), tag)) return SealResult::fail("HMAC-SHA256 failed (OpenSSL)");
  out.insert(out.end(), tag.begin(), tag.end());
  return SealResult::ok(std::move(out));
}

SealResult sealEnvelopeEd25519(const Envelope& envelope, const std::uint8_t* seed) {
  if (seed == nullptr) return SealResult::fail("no key");
  SealResult bytes = serialiseSigned(envelope, kEnvelopeVersionEd25519);
  if (!bytes) return bytes;
  std::vector<std::uint8_t> out = std::move(bytes.value());
  Signature signature{};
  if (!ed25519Sign(seed, out.data(), out.size(), signature)) return SealResult::fail("Ed25519 signing failed (OpenSSL)");
  out.insert(out.end(), signature.begin(), signature.end());
  return SealResult::ok(std::move(out));
}

std::string wireTimeProblem(double t_s, const std::string& field) {
  if (isWireTime(t_s)) return "";
  return field + " must be a time in [0, 4e9) s, got " + std::to_string(t_s);
}

}  // namespace gesture_formation::comm

#pragma once
/// \file
/// \brief The sending half of authenticated messaging: stamps, numbers and tags envelopes
/// with this node's sender id and the key ring's active key (docs/security.md §3–5): a group
/// ring gives version-1 envelopes (HMAC-SHA256), a per-sender ring version-2 envelopes
/// (Ed25519 with this node's signing key, which must belong to its sender id).
///
/// Sequence numbers are strictly increasing over all message types of one sender. A node
/// that restarts must not reuse numbers its peers have seen (they would be refused as
/// replays): start from a value above anything sent before — e.g. the wall clock in
/// microseconds (`first_sequence`), or a persisted counter. Thread safety: none; one Signer
/// per sending thread (the bridge guards it with its publish mutex).

#include <cstdint>
#include <utility>
#include <vector>

#include "gesture_formation/comm/envelope.hpp"
#include "gesture_formation/comm/key_ring.hpp"
#include "gesture_formation/common/result.hpp"

namespace gesture_formation::comm {

class Signer {
 public:
  /// \brief `first_sequence`: the number of the first envelope (≥ 1 recommended; see the file comment).
  Signer(std::uint16_t sender_id, KeyRing keys, std::uint64_t first_sequence = 1)
      : sender_id_(sender_id), keys_(std::move(keys)), next_sequence_(first_sequence) {}

  /// \brief Serialises and tags one envelope; the sequence advances only on success.
  /// Fails on an oversize payload, a non-finite stamp, sequence exhaustion, or an active
  /// signing key of another sender id.
  common::Result<std::vector<std::uint8_t>> seal(MessageType type, const std::vector<std::uint8_t>& payload,
                                                 double stamp_s);

  /// \brief Replaces the keys (rotation); the sequence continues.
  void setKeys(KeyRing keys) { keys_ = std::move(keys); }
  const KeyRing& keys() const { return keys_; }
  std::uint16_t senderId() const { return sender_id_; }
  std::uint64_t nextSequence() const { return next_sequence_; }

 private:
  std::uint16_t sender_id_;
  KeyRing keys_;
  std::uint64_t next_sequence_;
  bool exhausted_ = false;
};

}  // namespace gesture_formation::comm

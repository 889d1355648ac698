#include "gesture_formation/comm/signer.hpp"

#include <limits>
#include <string>

namespace gesture_formation::comm {

common::Result<std::vector<std::uint8_t>> Signer::seal(MessageType type, const std::vector<std::uint8_t>& payload,
                                                       double stamp_s) {
  if (exhausted_) {
    return common::Result<std::vector<std::uint8_t>>::fail("sequence numbers exhausted; restart with new keys");
  }
  Envelope e;
  e.type = type;
  e.sender_id = sender_id_;
  e.key_id = keys_.activeId();
  e.sequence = next_sequence_;
  e.stamp_s = stamp_s;
  e.payload = payload;
  const KeyEntry& key = keys_.active();
  if (key.kind == KeyKind::kSigning && key.sender_id != sender_id_) {
    return common::Result<std::vector<std::uint8_t>>::fail(
        "the active signing key " + std::to_string(key.id) + " belongs to sender " + std::to_string(key.sender_id) +
        ", not to this node's sender id " + std::to_string(sender_id_));
  }
  auto sealed = key.kind == KeyKind::kSigning ? sealEnvelopeEd25519(e, key.key.data())
                                              : sealEnvelope(e, key.key.data(), key.key.size());
  if (sealed) {
    if (next_sequence_ == std::numeric_limits<std::uint64_t>::max()) {
      exhausted_ = true;
    } else {
      ++next_sequence_;
    }
  }
  return sealed;
}

}  // namespace gesture_formation::comm

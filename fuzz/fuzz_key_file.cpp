// The key-file parser on arbitrary text. Invariants: a parsed ring is consistent (its
// active key exists and is a group or signing key, group/signing ids are unique, at most
// kMaxKeys of them and kMaxVerifyingKeys verifying keys, never group keys mixed with
// per-sender keys, signing keys of one sender whose public key matches the seed), and errors
// never echo key material (checked for the fixed key below).
#include <string>

#include "fuzz_common.hpp"
#include "gesture_formation/comm/key_ring.hpp"

using namespace gesture_formation::comm;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto ring = parseKeyFileText(text, "fuzz.key");
  if (!ring) {
    GF_FUZZ_ASSERT(ring.reason().rfind("fuzz.key", 0) == 0);
    GF_FUZZ_ASSERT(ring.reason().find("c0ffee00c0ffee00c0ffee00") == std::string::npos);
    return 0;
  }
  GF_FUZZ_ASSERT(!ring->keys().empty());
  GF_FUZZ_ASSERT(ring->find(ring->activeId()) != nullptr && ring->active().kind != KeyKind::kVerifying);
  std::size_t own = 0, verifying = 0, group = 0;
  for (const KeyEntry& k : ring->keys()) {
    if (k.kind == KeyKind::kVerifying) {
      ++verifying;
      GF_FUZZ_ASSERT(ring->findVerifying(k.sender_id, k.id) == &k);
      continue;
    }
    ++own;
    group += k.kind == KeyKind::kGroupHmac;
    GF_FUZZ_ASSERT(ring->find(k.id) == &k);
    if (k.kind == KeyKind::kSigning) {
      GF_FUZZ_ASSERT(k.sender_id == ring->active().sender_id);
      PublicKey pub{};
      GF_FUZZ_ASSERT(ed25519PublicFromSeed(k.key.data(), pub) && pub == k.public_key);
    }
  }
  GF_FUZZ_ASSERT(own >= 1 && own <= kMaxKeys && verifying <= kMaxVerifyingKeys);
  GF_FUZZ_ASSERT(group == 0 || group == ring->keys().size());
  GF_FUZZ_ASSERT(ring->perSender() == (group == 0));
  return 0;
}

// The key-file parser on arbitrary text. Invariants: a parsed ring is consistent (its
// active key exists, ids are unique, at most kMaxKeys), and errors never echo key material
// (checked for the fixed key below).
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
  GF_FUZZ_ASSERT(!ring->keys().empty() && ring->keys().size() <= kMaxKeys);
  GF_FUZZ_ASSERT(ring->find(ring->activeId()) != nullptr);
  for (const KeyEntry& k : ring->keys()) GF_FUZZ_ASSERT(ring->find(k.id) == &k);
  return 0;
}

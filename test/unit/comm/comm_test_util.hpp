#pragma once
// Helpers shared by the comm tests (not a test file itself: no test_ prefix).

#include <array>
#include <cstdint>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "gesture_formation/comm/key_ring.hpp"

namespace gesture_formation::comm::testing {

inline std::array<std::uint8_t, kKeyBytes> keyBytes(std::uint8_t fill) {
  std::array<std::uint8_t, kKeyBytes> k{};
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<std::uint8_t>(fill + 7 * i);
  return k;
}

inline KeyEntry keyEntry(std::uint8_t id, std::uint8_t fill, double accept_until_s = std::numeric_limits<double>::infinity()) {
  KeyEntry e;
  e.id = id;
  e.key = SecretKey(keyBytes(fill));
  e.accept_until_s = accept_until_s;
  return e;
}

inline KeyRing ring(std::vector<KeyEntry> keys, std::uint8_t active) {
  auto r = KeyRing::create(std::move(keys), active);
  if (!r) throw std::runtime_error(r.reason());
  return r.value();
}

/// This node's Ed25519 signing key `id` for `sender` from a seed pattern.
inline KeyEntry signingEntry(std::uint8_t id, std::uint16_t sender, std::uint8_t fill) {
  auto e = signingKey(id, sender, keyBytes(fill));
  if (!e) throw std::runtime_error(e.reason());
  return e.value();
}

/// A per-sender ring: `own`'s signing key (seed fill own_fill) + the verifying keys of
/// `peers` (sender id → seed fill), key id 1 each.
inline KeyRing perSenderRing(std::uint16_t own, std::uint8_t own_fill,
                             const std::vector<std::pair<std::uint16_t, std::uint8_t>>& peers) {
  std::vector<KeyEntry> keys{signingEntry(1, own, own_fill)};
  for (const auto& [sender, fill] : peers) keys.push_back(verifyingKeyOf(signingEntry(1, sender, fill)));
  return ring(std::move(keys), 1);
}

inline std::vector<std::uint8_t> randomBytes(std::mt19937_64& rng, std::size_t n) {
  std::vector<std::uint8_t> v(n);
  std::uint64_t bits = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i % 8 == 0) bits = rng();
    v[i] = static_cast<std::uint8_t>(bits >> (8 * (i % 8)));
  }
  return v;
}

}  // namespace gesture_formation::comm::testing

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

#pragma once
// Shared pieces of the libFuzzer targets (fuzz/README.md).

#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "gesture_formation/comm/key_ring.hpp"
#include "gesture_formation/comm/verifier.hpp"

namespace gf_fuzz {

/// An invariant broke: report and abort so that libFuzzer saves the input as a crash.
#define GF_FUZZ_ASSERT(cond)                                                            \
  do {                                                                                  \
    if (!(cond)) {                                                                      \
      std::fprintf(stderr, "fuzz invariant failed: %s (%s:%d)\n", #cond, __FILE__, __LINE__); \
      std::abort();                                                                     \
    }                                                                                   \
  } while (0)

inline gesture_formation::comm::SecretKey fuzzKey(std::uint8_t fill) {
  std::array<std::uint8_t, gesture_formation::comm::kKeyBytes> k{};
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<std::uint8_t>(fill + 13 * i);
  return gesture_formation::comm::SecretKey(k);
}

/// Key ring {1 (fill 1, accepted until t = 500), 2 (fill 2, active)}; senders 1..3, own id 9.
inline gesture_formation::comm::Verifier makeVerifier() {
  using namespace gesture_formation::comm;
  KeyEntry a;
  a.id = 1;
  a.key = fuzzKey(1);
  a.accept_until_s = 500.0;
  KeyEntry b;
  b.id = 2;
  b.key = fuzzKey(2);
  VerifierConfig c;
  c.known_senders = {1, 2, 3};
  c.own_sender_id = 9;
  c.max_age_s = 1.0;
  c.max_future_s = 0.25;
  c.max_age_s_by_type[MessageType::kFormationCommand] = 5.0;
  c.replay_window = 64;
  auto v = Verifier::create(c, KeyRing::create({a, b}, 2).value());
  if (!v) std::abort();
  return std::move(v.value());
}

}  // namespace gf_fuzz

// Per-sender envelopes (version 2, Ed25519; docs/security.md §4, §5) through a per-sender
// receiver: parsing, the per-sender rate lanes, signature, authorisation, freshness and replay
// state. The input is a script of datagrams: raw attacker bytes, or an envelope the harness
// seals — with the claimed sender's own key (valid), with another fleet member's key under the
// claimed id (impersonation by a captured node), or as a version-1 HMAC envelope (downgrade) —
// optionally damaged. Invariants: an accepted datagram is exactly what its claimed sender's key
// seals (Ed25519 is deterministic), so impersonation, downgrades and damage never pass; nothing
// from a sender outside the command list is accepted as a command; no (sender, sequence) is
// accepted twice; every datagram is counted once.
#include <fuzzer/FuzzedDataProvider.h>

#include <array>
#include <set>
#include <utility>
#include <vector>

#include "fuzz_common.hpp"
#include "gesture_formation/comm/envelope.hpp"

using namespace gesture_formation::comm;

namespace {

constexpr std::uint16_t kOwnId = 9;
constexpr std::array<std::uint16_t, 3> kSenders = {0, 1, 2};  ///< 0 may send commands, 1 and 2 may not

std::array<std::uint8_t, kKeyBytes> seedOf(std::uint16_t sender, std::uint8_t key_id) {
  std::array<std::uint8_t, kKeyBytes> s{};
  for (std::size_t i = 0; i < s.size(); ++i) s[i] = static_cast<std::uint8_t>(17 * sender + 29 * key_id + 7 * i + 1);
  return s;
}

/// Node 9's receiver: verifying keys of senders 0..2 (key id 1; sender 0 also key id 2,
/// accepted until t = 500), commands from sender 0 only.
Verifier makeReceiver() {
  std::vector<KeyEntry> keys;
  auto own = signingKey(1, kOwnId, seedOf(kOwnId, 1));
  if (!own) std::abort();
  keys.push_back(own.value());
  for (const std::uint16_t s : kSenders) {
    auto k = signingKey(1, s, seedOf(s, 1));
    if (!k) std::abort();
    keys.push_back(verifyingKeyOf(k.value()));
  }
  auto rotated = signingKey(2, 0, seedOf(0, 2));
  if (!rotated) std::abort();
  keys.push_back(verifyingKeyOf(rotated.value(), 500.0));
  auto ring = KeyRing::create(std::move(keys), 1);
  if (!ring) std::abort();
  VerifierConfig c;
  c.known_senders = {kSenders.begin(), kSenders.end()};
  c.own_sender_id = kOwnId;
  c.max_age_s = 1.0;
  c.max_future_s = 0.25;
  c.max_age_s_by_type[MessageType::kFormationCommand] = 5.0;
  c.senders_by_type[MessageType::kFormationCommand] = {0};
  c.replay_window = 64;
  c.max_rate_hz = 50.0;  // small, so that scripts reach the rate lanes
  c.burst = 8;
  auto v = Verifier::create(c, std::move(ring.value()));
  if (!v) std::abort();
  return std::move(v.value());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  Verifier verifier = makeReceiver();
  std::set<std::pair<std::uint16_t, std::uint64_t>> accepted;
  std::uint64_t datagrams = 0;
  double now = 100.0;
  while (in.remaining_bytes() > 0 && datagrams < 48) {
    ++datagrams;
    const std::uint8_t mode = in.ConsumeIntegral<std::uint8_t>();
    now += static_cast<double>(in.ConsumeIntegralInRange<int>(-100, 1000)) * 1e-3;
    if ((mode & 0x40) != 0) now = in.ConsumeFloatingPoint<double>();  // hostile clocks too
    std::vector<std::uint8_t> bytes;
    bool sealed_by_claimed_sender = false;
    if ((mode & 1) == 0) {
      bytes = in.ConsumeBytes<std::uint8_t>(in.ConsumeIntegralInRange<std::size_t>(0, 512));
    } else {
      Envelope e;
      e.type = static_cast<MessageType>(in.ConsumeIntegralInRange<int>(1, 5));
      // Mostly the fleet (so that scripts get through to the state), sometimes this node's own
      // id or a stranger.
      static constexpr std::array<std::uint16_t, 5> kClaimed = {0, 1, 2, kOwnId, 10};
      e.sender_id = kClaimed[in.ConsumeIntegralInRange<std::size_t>(0, kClaimed.size() - 1)];
      e.key_id = in.ConsumeIntegralInRange<std::uint8_t>(1, 3);
      e.sequence = (mode & 2) ? in.ConsumeIntegral<std::uint64_t>() : in.ConsumeIntegralInRange<std::uint64_t>(0, 200);
      const int skew_ms = (mode & 0x20) ? in.ConsumeIntegralInRange<int>(-6000, 600) : in.ConsumeIntegralInRange<int>(-1200, 300);
      e.stamp_s = now + static_cast<double>(skew_ms) * 1e-3;
      e.payload = in.ConsumeBytes<std::uint8_t>(in.ConsumeIntegralInRange<std::size_t>(0, 300));
      const std::uint8_t how = (mode >> 2) & 3;  // 0, 1: own key; 2: another member's key; 3: version 1
      if (how == 3) {
        const auto k = seedOf(e.sender_id, e.key_id);
        auto sealed = sealEnvelope(e, k.data(), k.size());
        if (!sealed) continue;
        bytes = std::move(sealed.value());
      } else {
        const std::uint16_t signer = how == 2 ? static_cast<std::uint16_t>((e.sender_id + 1) % 3) : e.sender_id;
        const auto seed = seedOf(signer, e.key_id);
        auto sealed = sealEnvelopeEd25519(e, seed.data());
        if (!sealed) continue;
        bytes = std::move(sealed.value());
        sealed_by_claimed_sender = signer == e.sender_id;
      }
      if ((mode & 0x10) != 0 && !bytes.empty()) {  // damage it
        const std::size_t pos = in.ConsumeIntegralInRange<std::size_t>(0, bytes.size() - 1);
        bytes[pos] ^= in.ConsumeIntegralInRange<std::uint8_t>(1, 255);
        sealed_by_claimed_sender = false;
      }
    }
    const std::uint64_t total_before = verifier.counters().total();
    const VerifyResult r = verifier.verify(bytes.data(), bytes.size(), now);
    GF_FUZZ_ASSERT(verifier.counters().total() == total_before + 1);
    if (!r.accepted()) continue;
    // Only the claimed sender's key seals what is accepted: resealing gives the same bytes.
    const auto seed = seedOf(r.envelope.sender_id, r.envelope.key_id);
    auto resealed = sealEnvelopeEd25519(r.envelope, seed.data());
    GF_FUZZ_ASSERT(resealed.has_value() && resealed.value() == bytes);
    GF_FUZZ_ASSERT(r.envelope.version == kEnvelopeVersionEd25519);
    GF_FUZZ_ASSERT(sealed_by_claimed_sender || (mode & 1) == 0 || (mode & 0x10) != 0);
    GF_FUZZ_ASSERT(r.envelope.type != MessageType::kFormationCommand || r.envelope.sender_id == 0);
    GF_FUZZ_ASSERT(r.envelope.sender_id != kOwnId);
    GF_FUZZ_ASSERT(accepted.insert({r.envelope.sender_id, r.envelope.sequence}).second);
  }
  GF_FUZZ_ASSERT(verifier.counters().accepted() == accepted.size());
  return 0;
}

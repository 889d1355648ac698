// Cost per message of the inter-UAV envelope (docs/security.md §5): sealing and verifying a
// worker state (113-byte payload) and a 50-sample planned trajectory (4 424 bytes) with the
// group HMAC-SHA256 tag (version 1) and the per-sender Ed25519 signature (version 2), plus the
// cheap pre-checks a flood meets before any cryptography. Prints Google Benchmark's table;
// tools/security_figures.sh runs it and writes docs/results/security.md.
#include <benchmark/benchmark.h>

#include <array>
#include <cstdint>
#include <vector>

#include "gesture_formation/comm/envelope.hpp"
#include "gesture_formation/comm/key_ring.hpp"
#include "gesture_formation/comm/signer.hpp"
#include "gesture_formation/comm/verifier.hpp"

using namespace gesture_formation::comm;

namespace {

std::array<std::uint8_t, kKeyBytes> seed(std::uint8_t fill) {
  std::array<std::uint8_t, kKeyBytes> k{};
  for (std::size_t i = 0; i < k.size(); ++i) k[i] = static_cast<std::uint8_t>(fill + 7 * i);
  return k;
}

KeyRing groupRing() {
  KeyEntry e;
  e.id = 1;
  e.key = SecretKey(seed(10));
  return KeyRing::create({e}, 1).value();
}

/// Sender 1's ring (its signing key) and receiver 2's ring (its own key + sender 1's public key).
KeyRing perSenderRing(std::uint16_t own, bool with_peer) {
  std::vector<KeyEntry> keys{signingKey(1, own, seed(static_cast<std::uint8_t>(40 + own))).value()};
  if (with_peer) keys.push_back(verifyingKeyOf(signingKey(1, 1, seed(41)).value()));
  return KeyRing::create(std::move(keys), 1).value();
}

Verifier receiver(bool per_sender) {
  VerifierConfig c;
  c.known_senders = {1};
  c.own_sender_id = 2;
  c.max_age_s = 1e9;  // the benchmark reuses one stamp
  c.burst = 1e15;     // and one instant: no rate limit here (BM_RejectRateLimited has it)
  return Verifier::create(c, per_sender ? perSenderRing(2, true) : groupRing()).value();
}

void BM_Seal(benchmark::State& state) {
  const bool per_sender = state.range(0) != 0;
  const std::vector<std::uint8_t> payload(static_cast<std::size_t>(state.range(1)), 0x5A);
  Signer s(1, per_sender ? perSenderRing(1, false) : groupRing(), 1);
  for (auto _ : state) benchmark::DoNotOptimize(s.seal(MessageType::kWorkerState, payload, 1.0));
  state.SetLabel(per_sender ? "ed25519" : "hmac-sha256");
}

void BM_Verify(benchmark::State& state) {
  const bool per_sender = state.range(0) != 0;
  const std::vector<std::uint8_t> payload(static_cast<std::size_t>(state.range(1)), 0x5A);
  Signer s(1, per_sender ? perSenderRing(1, false) : groupRing(), 1);
  // Distinct sequence numbers so that every verify runs the whole path and is accepted.
  std::vector<std::vector<std::uint8_t>> sealed;
  for (int i = 0; i < 4096; ++i) sealed.push_back(s.seal(MessageType::kWorkerState, payload, 1.0).value());
  Verifier v = receiver(per_sender);
  std::size_t i = 0;
  for (auto _ : state) {
    if (i == sealed.size()) {
      state.PauseTiming();
      v = receiver(per_sender);
      i = 0;
      state.ResumeTiming();
    }
    const auto& b = sealed[i++];
    if (!v.verify(b.data(), b.size(), 1.0).accepted()) state.SkipWithError("not accepted");
  }
  state.SetLabel(per_sender ? "ed25519" : "hmac-sha256");
}

/// A keyless forgery of a known sender: parse + key lookup + tag check, refused as forged.
void BM_RejectForged(benchmark::State& state) {
  const bool per_sender = state.range(0) != 0;
  Signer s(1, per_sender ? perSenderRing(1, false) : groupRing(), 1);
  auto b = s.seal(MessageType::kWorkerState, std::vector<std::uint8_t>(113, 0x5A), 1.0).value();
  b.back() ^= 1;
  Verifier v = receiver(per_sender);
  for (auto _ : state) benchmark::DoNotOptimize(v.verify(b.data(), b.size(), 1.0));
  state.SetLabel(per_sender ? "ed25519" : "hmac-sha256");
}

/// A forgery of a known sender once its budget is spent: refused before any cryptography.
void BM_RejectRateLimited(benchmark::State& state) {
  Signer s(1, perSenderRing(1, false), 1);
  auto b = s.seal(MessageType::kWorkerState, std::vector<std::uint8_t>(113, 0x5A), 1.0).value();
  b.back() ^= 1;
  VerifierConfig c;
  c.known_senders = {1};
  c.own_sender_id = 2;
  c.burst = 1.0;
  Verifier v = Verifier::create(c, perSenderRing(2, true)).value();
  for (auto _ : state) benchmark::DoNotOptimize(v.verify(b.data(), b.size(), 1.0));
}

/// Garbage from an unknown sender: refused before any cryptography.
void BM_RejectUnknownSender(benchmark::State& state) {
  Signer s(7, perSenderRing(7, false), 1);
  const auto b = s.seal(MessageType::kWorkerState, std::vector<std::uint8_t>(113, 0x5A), 1.0).value();
  Verifier v = receiver(true);
  for (auto _ : state) benchmark::DoNotOptimize(v.verify(b.data(), b.size(), 1.0));
}

}  // namespace

BENCHMARK(BM_Seal)->ArgsProduct({{0, 1}, {113, 4424}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Verify)->ArgsProduct({{0, 1}, {113, 4424}})->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RejectForged)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RejectRateLimited)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RejectUnknownSender)->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();

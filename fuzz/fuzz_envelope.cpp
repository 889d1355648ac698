// Envelope parsing + authentication + replay/freshness state, then payload decoding.
// The input is a script of datagrams: each either raw attacker bytes, or an envelope the
// harness signs with a real key (so the fuzzer reaches the replay window, the age checks and
// the payload decoders). Invariants: an accepted datagram is exactly what sealing its
// envelope with the key gives (so forgeries and damaged datagrams never pass); an envelope
// sealed with a wrong key never passes; no (sender, sequence) is accepted twice; counters add up.
#include <fuzzer/FuzzedDataProvider.h>

#include <set>
#include <utility>
#include <vector>

#include "fuzz_common.hpp"
#include "gesture_formation/comm/map_update.hpp"
#include "gesture_formation/comm/payloads.hpp"
#include "gesture_formation/comm/signer.hpp"

using namespace gesture_formation;
using namespace gesture_formation::comm;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  Verifier verifier = gf_fuzz::makeVerifier();
  PayloadDecoder decoder;
  std::set<std::pair<std::uint16_t, std::uint64_t>> accepted;
  std::uint64_t datagrams = 0;
  double now = 100.0;
  while (in.remaining_bytes() > 0 && datagrams < 64) {
    ++datagrams;
    const std::uint8_t mode = in.ConsumeIntegral<std::uint8_t>();
    now += static_cast<double>(in.ConsumeIntegralInRange<int>(-100, 1000)) * 1e-3;
    if ((mode & 0x10) != 0) now = in.ConsumeFloatingPoint<double>();  // hostile clocks too
    std::vector<std::uint8_t> bytes;
    bool signed_by_us = false;
    if ((mode & 1) == 0) {
      bytes = in.ConsumeBytes<std::uint8_t>(in.ConsumeIntegralInRange<std::size_t>(0, 512));
    } else {
      Envelope e;
      e.type = static_cast<MessageType>(in.ConsumeIntegralInRange<int>(1, 5));
      e.sender_id = in.ConsumeIntegralInRange<std::uint16_t>(0, 10);
      e.key_id = in.ConsumeIntegralInRange<std::uint8_t>(0, 3);
      e.sequence = (mode & 2) ? in.ConsumeIntegral<std::uint64_t>() : in.ConsumeIntegralInRange<std::uint64_t>(0, 200);
      e.stamp_s = now + static_cast<double>(in.ConsumeIntegralInRange<int>(-6000, 600)) * 1e-3;
      e.payload = in.ConsumeBytes<std::uint8_t>(in.ConsumeIntegralInRange<std::size_t>(0, 400));
      const SecretKey key = gf_fuzz::fuzzKey((mode & 4) ? 3 : static_cast<std::uint8_t>(e.key_id));  // 3: wrong key
      auto sealed = sealEnvelope(e, key.data(), key.size());
      if (!sealed) continue;
      bytes = std::move(sealed.value());
      signed_by_us = (mode & 4) == 0 && (e.key_id == 1 || e.key_id == 2);
      if ((mode & 8) != 0 && !bytes.empty()) {  // damage it
        const std::size_t pos = in.ConsumeIntegralInRange<std::size_t>(0, bytes.size() - 1);
        bytes[pos] ^= in.ConsumeIntegralInRange<std::uint8_t>(1, 255);
        signed_by_us = false;  // (could still be valid if the flip was undone: not assumed)
      }
    }
    const std::uint64_t total_before = verifier.counters().total();
    VerifyResult r = verifier.verify(bytes.data(), bytes.size(), now);
    GF_FUZZ_ASSERT(verifier.counters().total() == total_before + 1);
    if (!r.accepted()) continue;
    // Only what the key holder sealed verifies: re-sealing the envelope gives the same bytes.
    {
      const SecretKey key = gf_fuzz::fuzzKey(r.envelope.key_id);
      auto resealed = sealEnvelope(r.envelope, key.data(), key.size());
      GF_FUZZ_ASSERT(resealed.has_value() && resealed.value() == bytes);
    }
    GF_FUZZ_ASSERT(signed_by_us || (mode & 1) == 0 || (mode & 8) != 0);  // wrong-key envelopes never verify
    GF_FUZZ_ASSERT(accepted.insert({r.envelope.sender_id, r.envelope.sequence}).second);
    GF_FUZZ_ASSERT(r.envelope.payload.size() + kMinEnvelopeBytes == bytes.size());
    switch (r.envelope.type) {
      case MessageType::kHeartbeat: {
        Heartbeat m;
        decoder.decode(r.envelope, m);
        break;
      }
      case MessageType::kWorkerState: {
        WorkerStateMessage m;
        decoder.decode(r.envelope, m);
        break;
      }
      case MessageType::kPlannedTrajectory: {
        PlanMessage m;
        decoder.decode(r.envelope, m);
        break;
      }
      case MessageType::kFormationParams: {
        FormationParamsMessage m;
        decoder.decode(r.envelope, m);
        break;
      }
      case MessageType::kFormationCommand: {
        formation::FormationCommand m;
        decoder.decode(r.envelope, m);
        break;
      }
      case MessageType::kGestureObservation: {
        GestureObservationMessage m;
        decoder.decode(r.envelope, m);
        break;
      }
      case MessageType::kAbortCommand: {
        AbortMessage m;
        decoder.decode(r.envelope, m);
        break;
      }
      case MessageType::kCommandAck: {
        CommandAckMessage m;
        decoder.decode(r.envelope, m);
        break;
      }
      case MessageType::kAssistance: {
        AssistanceMessage m;
        decoder.decode(r.envelope, m);
        break;
      }
      case MessageType::kLeadership: {
        formation::LeadershipMessage m;
        decoder.decode(r.envelope, m);
        break;
      }
      case MessageType::kMapUpdate: {
        MapUpdate m;
        decoder.decode(r.envelope, m);
        break;
      }
    }
  }
  GF_FUZZ_ASSERT(verifier.counters().accepted() == accepted.size());
  return 0;
}

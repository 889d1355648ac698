// The LCM layer in front of the verifier: gf_lcm::envelope_t decoding (length checked
// before lcm-gen's decoder), then verification. Invariants: the codec round-trips, and an
// accepted envelope is exactly what sealing it with the key gives (nothing else verifies).
#include <vector>

#include "fuzz_common.hpp"
#include "gesture_formation/lcm_bridge/lcm_transport.hpp"

using namespace gesture_formation;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> sealed;
  if (!lcm_bridge::decodeLcmEnvelope(data, size, sealed)) return 0;
  GF_FUZZ_ASSERT(sealed.size() + 12 == size);
  const std::vector<std::uint8_t> again = lcm_bridge::encodeLcmEnvelope(sealed);
  GF_FUZZ_ASSERT(again.size() == size && std::equal(again.begin(), again.end(), data));
  comm::Verifier verifier = gf_fuzz::makeVerifier();
  const comm::VerifyResult r = verifier.verify(sealed.data(), sealed.size(), 100.0);
  if (r.accepted()) {
    // Only what the key holder sealed verifies: re-sealing the envelope gives the same bytes.
    const comm::SecretKey key = gf_fuzz::fuzzKey(r.envelope.key_id);
    auto resealed = comm::sealEnvelope(r.envelope, key.data(), key.size());
    GF_FUZZ_ASSERT(resealed.has_value() && resealed.value() == sealed);
  }
  return 0;
}

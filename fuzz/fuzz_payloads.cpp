// Payload decoders on arbitrary bytes (first byte picks the type). Invariant: whatever
// decodes re-encodes to exactly the same bytes (the codec is a bijection on valid input),
// so no NaN, oversize array or out-of-range value can slip through a decode.
#include <cmath>
#include <vector>

#include "fuzz_common.hpp"
#include "gesture_formation/comm/map_update.hpp"
#include "gesture_formation/comm/payloads.hpp"

using namespace gesture_formation;
using namespace gesture_formation::comm;

namespace {

template <class T>
void roundTrip(const std::uint8_t* data, std::size_t size) {
  T m{};
  std::string reason;
  const PayloadError e = decodePayload(data, size, m, &reason);
  if (e != PayloadError::kNone) {
    GF_FUZZ_ASSERT(!reason.empty());
    return;
  }
  auto again = encodePayload(m);
  GF_FUZZ_ASSERT(again.has_value());
  GF_FUZZ_ASSERT(again->size() == size);
  GF_FUZZ_ASSERT(std::equal(again->begin(), again->end(), data));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::uint8_t* payload = data + 1;
  const std::size_t n = size - 1;
  if (data[0] == 255) {  // (before 2026-12-03 a heartbeat, as 255 % 5)
    roundTrip<GestureObservationMessage>(payload, n);
    return 0;
  }
  if (data[0] == 254) {  // (before the abort payload a formation command, as 254 % 5)
    roundTrip<AbortMessage>(payload, n);
    return 0;
  }
  if (data[0] == 252) {  // (before the assistance payload a planned trajectory, as 252 % 5)
    roundTrip<AssistanceMessage>(payload, n);
    return 0;
  }
  if (data[0] == 251) {  // (before the leadership payload a worker state, as 251 % 5)
    roundTrip<formation::LeadershipMessage>(payload, n);
    return 0;
  }
  if (data[0] == 250) {  // (before the map-update payload a heartbeat, as 250 % 5)
    roundTrip<MapUpdate>(payload, n);
    return 0;
  }
  if (data[0] == 253) {  // (before the acknowledgement payload a formation params, as 253 % 5)
    roundTrip<CommandAckMessage>(payload, n);
    return 0;
  }
  switch (data[0] % 5) {
    case 0: roundTrip<Heartbeat>(payload, n); break;
    case 1: roundTrip<WorkerStateMessage>(payload, n); break;
    case 2: roundTrip<PlanMessage>(payload, n); break;
    case 3: roundTrip<FormationParamsMessage>(payload, n); break;
    default: roundTrip<formation::FormationCommand>(payload, n); break;
  }
  return 0;
}

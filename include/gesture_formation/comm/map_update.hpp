#pragma once
/// \file
/// \brief The map-change payload (MessageType::kMapUpdate = 11; issue 35 item 1, docs/security.md
/// §3.2 "map_update", docs/mapping.md §8): one UAV's live-map changes since its previous update
/// (mapping::MapDelta) with the sender's UAV index and an update sequence number. It travels in
/// the authenticated envelope like every payload (envelope.hpp); the codec follows payloads.hpp's
/// rules: big-endian, no padding, strict decoding (exact length, finite doubles, counts within
/// their maximum, no key listed twice), the output written only on success.
///
/// What the decoder cannot know — the receiver's map — is checked by checkMapUpdate(): a resolution
/// other than the receiver's, a key outside its grid. Thread safety: free functions, reentrant.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "gesture_formation/comm/envelope.hpp"
#include "gesture_formation/comm/payloads.hpp"
#include "gesture_formation/common/result.hpp"
#include "gesture_formation/mapping/map_delta.hpp"

namespace gesture_formation::comm {

/// \brief A UAV's map changes as they travel.
struct MapUpdate {
  std::uint16_t uav_index = 0;  ///< the sender, ≤ kMaxUavIndex (0 = leader)
  /// Per sender, +1 per update sent (a receiver can count gaps: updates lost on the link).
  std::uint32_t sequence = 0;
  mapping::MapDelta delta;  ///< stamp, resolution (> 0, ≤ kMaxMapResolutionM), keys (≤ mapping::kMaxMapUpdateVoxels)
};

/// Largest voxel size on the wire [m].
constexpr double kMaxMapResolutionM = 10.0;

inline MessageType messageTypeOf(const MapUpdate&) { return MessageType::kMapUpdate; }
/// \brief Fails naming the field on what decodePayload would refuse.
common::Result<std::vector<std::uint8_t>> encodePayload(const MapUpdate& m);
/// \brief Strict decode; `out` written only on kNone; `reason` names the field.
PayloadError decodePayload(const std::uint8_t* data, std::size_t size, MapUpdate& out, std::string* reason = nullptr);
/// \brief The receiver's check: kOutOfRange when `m` does not fit `grid` (resolution, a key outside
/// the grid; `reason` names the field, e.g. "map_update.occupied[3] key (…) is outside …"), else kNone.
PayloadError checkMapUpdate(const MapUpdate& m, const mapping::KeyGrid& grid, std::string* reason = nullptr);

}  // namespace gesture_formation::comm

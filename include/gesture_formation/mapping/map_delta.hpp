#pragma once
/// \file
/// \brief Map changes as UAVs share them (issue 35 item 1; docs/mapping.md §8): the voxels whose
/// observed occupancy class changed in the sender's live map since its last update, as OctoMap
/// keys at the map's resolution, split into those now occupied and those now free (a voxel the
/// sender had announced occupied and now sees free). What travels on the wire is comm::MapUpdate
/// (comm/map_update.hpp; byte layout in docs/security.md §3.2); this header is the mapping side's
/// data, free of the comm layer. Thread safety: value types and pure functions.

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace gesture_formation::mapping {

/// \brief An OctoMap key (tree depth 16): voxel index + 32768 per axis, x y z.
using VoxelKey = std::array<std::uint16_t, 3>;

/// \brief Wire sizes of a map update (comm/map_update.hpp checks them): bytes per voxel key, the
/// payload's fixed header, and the largest envelope around it (header 28 + Ed25519 tag 64).
constexpr std::size_t kMapUpdateKeyBytes = 6;
constexpr std::size_t kMapUpdateHeaderBytes = 26;
constexpr std::size_t kMapUpdateEnvelopeBytes = 28 + 64;
/// \brief Most voxels in one update (occupied + free): 8192 × 6 B + 26 B < the 60 000 B payload limit.
constexpr std::size_t kMaxMapUpdateVoxels = 8192;

/// \brief Bytes one update of `voxels` voxels takes on the wire, envelope included.
constexpr std::size_t mapUpdateWireBytes(std::size_t voxels) {
  return kMapUpdateEnvelopeBytes + kMapUpdateHeaderBytes + kMapUpdateKeyBytes * voxels;
}

/// \brief One sender's map changes.
struct MapDelta {
  /// The sender's map stamp: the time of the newest depth frame in its map [s, sender clock] —
  /// what the receiver compares with its own observations of the same voxels.
  double stamp_s = 0.0;
  double resolution_m = 0.0;       ///< the sender map's voxel size [m]
  std::vector<VoxelKey> occupied;  ///< voxels the sender now sees occupied
  std::vector<VoxelKey> free;      ///< voxels the sender had announced occupied and now sees free
  std::size_t size() const { return occupied.size() + free.size(); }
};

/// \brief The keys a receiver's map holds: its resolution and the inclusive key box of its grid.
struct KeyGrid {
  double resolution_m = 0.0;
  VoxelKey min_key{{0, 0, 0}};
  VoxelKey max_key{{0, 0, 0}};
};

/// \brief Why `delta` does not fit `grid` ("" when it does): a resolution differing by more than
/// 1e-9 m, or a key outside the grid, naming the list and index (`<prefix>occupied[3]`).
std::string deltaProblem(const MapDelta& delta, const KeyGrid& grid, const std::string& prefix = "");

}  // namespace gesture_formation::mapping

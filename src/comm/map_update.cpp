#include "gesture_formation/comm/map_update.hpp"
#include "gesture_formation/comm/wire_time.hpp"

#include <algorithm>
#include <cmath>

#include "gesture_formation/comm/byte_io.hpp"

namespace gesture_formation::comm {

static_assert(kHeaderBytes + kMaxTagBytes == mapping::kMapUpdateEnvelopeBytes, "the envelope around a map update");
static_assert(mapping::mapUpdateWireBytes(mapping::kMaxMapUpdateVoxels) - mapping::kMapUpdateEnvelopeBytes <= kMaxPayloadBytes,
              "the largest map update fits a payload");

namespace {

PayloadError fail(PayloadError e, std::string* reason, const std::string& why) {
  if (reason != nullptr) *reason = "map_update." + why;
  return e;
}

/// The first key listed twice (in either list), as "occupied[i]"/"free[i]"; "" when none.
std::string duplicateKey(const mapping::MapDelta& d) {
  std::vector<std::pair<mapping::VoxelKey, std::size_t>> all;
  all.reserve(d.size());
  for (std::size_t i = 0; i < d.occupied.size(); ++i) all.push_back({d.occupied[i], i});
  for (std::size_t i = 0; i < d.free.size(); ++i) all.push_back({d.free[i], d.occupied.size() + i});
  std::sort(all.begin(), all.end());
  for (std::size_t i = 1; i < all.size(); ++i) {
    if (all[i].first == all[i - 1].first) {
      const std::size_t j = std::max(all[i].second, all[i - 1].second);
      return j < d.occupied.size() ? "occupied[" + std::to_string(j) + "]"
                                   : "free[" + std::to_string(j - d.occupied.size()) + "]";
    }
  }
  return "";
}

/// What decode refuses, checked on the struct (the encoder refuses the same).
PayloadError structureProblem(const MapUpdate& m, std::string* reason) {
  if (m.uav_index > kMaxUavIndex) {
    return fail(PayloadError::kOutOfRange, reason, "uav_index must be ≤ " + std::to_string(kMaxUavIndex) + ", got " +
                                                        std::to_string(m.uav_index));
  }
  if (!std::isfinite(m.delta.stamp_s)) return fail(PayloadError::kNonFinite, reason, "stamp_s must be finite");
  if (const std::string e = wireTimeProblem(m.delta.stamp_s, "stamp_s"); !e.empty()) return fail(PayloadError::kOutOfRange, reason, e);
  if (!std::isfinite(m.delta.resolution_m)) return fail(PayloadError::kNonFinite, reason, "resolution_m must be finite");
  if (!(m.delta.resolution_m > 0.0 && m.delta.resolution_m <= kMaxMapResolutionM)) {
    return fail(PayloadError::kOutOfRange, reason, "resolution_m must be in (0, " + std::to_string(kMaxMapResolutionM) +
                                                       "], got " + std::to_string(m.delta.resolution_m));
  }
  if (m.delta.size() > mapping::kMaxMapUpdateVoxels) {
    return fail(PayloadError::kOversizeArray, reason, "occupied + free count " + std::to_string(m.delta.size()) +
                                                          " is over the limit " + std::to_string(mapping::kMaxMapUpdateVoxels));
  }
  const std::string dup = duplicateKey(m.delta);
  if (!dup.empty()) return fail(PayloadError::kOutOfRange, reason, dup + " lists a key already listed");
  return PayloadError::kNone;
}

void writeKeys(ByteWriter& w, const std::vector<mapping::VoxelKey>& keys) {
  for (const auto& k : keys) {
    w.u16(k[0]);
    w.u16(k[1]);
    w.u16(k[2]);
  }
}

bool readKeys(ByteReader& r, std::size_t n, std::vector<mapping::VoxelKey>& keys) {
  keys.resize(n);
  for (auto& k : keys) {
    if (!r.u16(k[0]) || !r.u16(k[1]) || !r.u16(k[2])) return false;
  }
  return true;
}

}  // namespace

common::Result<std::vector<std::uint8_t>> encodePayload(const MapUpdate& m) {
  using R = common::Result<std::vector<std::uint8_t>>;
  std::string why;
  if (structureProblem(m, &why) != PayloadError::kNone) return R::fail(why);
  ByteWriter w;
  w.u16(m.uav_index);
  w.u32(m.sequence);
  w.f64(m.delta.stamp_s);
  w.f64(m.delta.resolution_m);
  w.u16(static_cast<std::uint16_t>(m.delta.occupied.size()));
  w.u16(static_cast<std::uint16_t>(m.delta.free.size()));
  writeKeys(w, m.delta.occupied);
  writeKeys(w, m.delta.free);
  return R::ok(w.release());
}

PayloadError decodePayload(const std::uint8_t* data, std::size_t size, MapUpdate& out, std::string* reason) {
  ByteReader r(data, size);
  MapUpdate m;
  std::uint16_t n_occupied = 0, n_free = 0;
  if (!r.u16(m.uav_index) || !r.u32(m.sequence) || !r.f64(m.delta.stamp_s) || !r.f64(m.delta.resolution_m) ||
      !r.u16(n_occupied) || !r.u16(n_free)) {
    return fail(PayloadError::kTruncated, reason, "header needs " + std::to_string(mapping::kMapUpdateHeaderBytes) +
                                                      " bytes, got " + std::to_string(size));
  }
  const std::size_t n = static_cast<std::size_t>(n_occupied) + n_free;
  if (n > mapping::kMaxMapUpdateVoxels) {  // before reading (or allocating) any key
    return fail(PayloadError::kOversizeArray, reason, "occupied + free count " + std::to_string(n) + " is over the limit " +
                                                          std::to_string(mapping::kMaxMapUpdateVoxels));
  }
  if (r.remaining() < mapping::kMapUpdateKeyBytes * n) {
    return fail(PayloadError::kTruncated, reason, "keys: " + std::to_string(n) + " keys need " +
                                                      std::to_string(mapping::kMapUpdateKeyBytes * n) + " bytes, got " +
                                                      std::to_string(r.remaining()));
  }
  readKeys(r, n_occupied, m.delta.occupied);
  readKeys(r, n_free, m.delta.free);
  if (r.remaining() != 0) {
    return fail(PayloadError::kTrailingBytes, reason, std::to_string(r.remaining()) + " bytes after the last key");
  }
  const PayloadError e = structureProblem(m, reason);
  if (e != PayloadError::kNone) return e;
  out = std::move(m);
  return PayloadError::kNone;
}

PayloadError checkMapUpdate(const MapUpdate& m, const mapping::KeyGrid& grid, std::string* reason) {
  const std::string p = mapping::deltaProblem(m.delta, grid);
  if (p.empty()) return PayloadError::kNone;
  return fail(PayloadError::kOutOfRange, reason, p);
}

}  // namespace gesture_formation::comm

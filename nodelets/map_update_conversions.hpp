#pragma once
// Map update message <-> core conversions (FormationPlanner's live map, LcmBridge; docs/mapping.md §8).
#include <algorithm>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include <ros/time.h>

#include "gesture_formation/MapUpdate.h"
#include "gesture_formation/comm/map_update.hpp"
#include "gesture_formation/common/result.hpp"

namespace gesture_formation::nodelets {

inline gesture_formation::MapUpdate toMsg(const comm::MapUpdate& u) {
  gesture_formation::MapUpdate m;
  m.header.stamp = ros::Time(std::max(0.0, u.delta.stamp_s));
  m.uav_index = u.uav_index;
  m.sequence = u.sequence;
  m.resolution_m = u.delta.resolution_m;
  const auto flat = [](const std::vector<mapping::VoxelKey>& keys, std::vector<std::uint16_t>& out) {
    out.reserve(3 * keys.size());
    for (const auto& k : keys) out.insert(out.end(), k.begin(), k.end());
  };
  flat(u.delta.occupied, m.occupied);
  flat(u.delta.free, m.free);
  return m;
}

/// A map update from ROS, checked as the wire checks it (comm::encodePayload); fails naming the field.
inline common::Result<comm::MapUpdate> fromMsg(const gesture_formation::MapUpdate& m) {
  using R = common::Result<comm::MapUpdate>;
  comm::MapUpdate u;
  u.uav_index = m.uav_index;
  u.sequence = m.sequence;
  u.delta.stamp_s = m.header.stamp.toSec();
  u.delta.resolution_m = m.resolution_m;
  for (const auto& [name, flat, keys] : {std::make_tuple("occupied", &m.occupied, &u.delta.occupied),
                                         std::make_tuple("free", &m.free, &u.delta.free)}) {
    if (flat->size() % 3 != 0) {
      return R::fail(std::string("map_update.") + name + ": " + std::to_string(flat->size()) +
                        " numbers, not three per voxel (x y z)");
    }
    for (std::size_t i = 0; i < flat->size(); i += 3) keys->push_back({(*flat)[i], (*flat)[i + 1], (*flat)[i + 2]});
  }
  if (const auto bytes = comm::encodePayload(u); !bytes) return R::fail(bytes.reason());
  return R::ok(u);
}

}  // namespace gesture_formation::nodelets

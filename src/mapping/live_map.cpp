#include "gesture_formation/mapping/live_map.hpp"

#include <algorithm>
#include <chrono>
#include <limits>
#include <sstream>
#include <mutex>

#include <octomap/OcTree.h>

namespace gesture_formation::mapping {

namespace {

constexpr std::uint8_t kAnnouncedOccupied = 1;  ///< LiveMap::announced_ bit 0
constexpr std::uint8_t kInRefreshList = 2;      ///< LiveMap::announced_ bit 1

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

octomap::point3d toOcto(const Eigen::Vector3d& p) {
  return octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
}

std::string joinLines(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& line : lines) out += (out.empty() ? "" : "; ") + line;
  return out;
}

}  // namespace

common::Result<std::unique_ptr<LiveMap>> LiveMap::create(const MappingConfig& config, const planning::MapConfig& grid,
                                                         std::shared_ptr<const planning::OccupancyMap> prior) {
  using R = common::Result<std::unique_ptr<LiveMap>>;
  std::vector<std::string> problems = config.validate();
  for (const auto& p : grid.validate()) problems.push_back("map." + p);
  if (!problems.empty()) return R::fail(joinLines(problems));
  auto map = std::make_shared<planning::OccupancyMap>(
      planning::OccupancyMap::fromPrimitives(grid, planning::PrimitiveSet{}, planning::GroundSpec{}));
  // OctoMap's keys (tree depth 16) hold voxel indices −32768 .. 32767 around the world origin: a grid
  // beyond them would map nothing (and its keys would wrap on the wire).
  const planning::VoxelIndex lo = map->gridOrigin(), hi = map->gridOrigin() + map->gridSize() - planning::VoxelIndex::Ones();
  if ((lo.array() < -kKeyOrigin).any() || (hi.array() >= kKeyOrigin).any()) {
    std::ostringstream os;
    os << "map.bounds: voxel indices " << lo.transpose() << " .. " << hi.transpose() << " at map.resolution_m "
       << grid.resolution_m << " leave OctoMap's key range (-" << kKeyOrigin << " .. " << kKeyOrigin - 1
       << " per axis): bounds nearer the origin or a coarser resolution";
    return R::fail(os.str());
  }
  if (prior) {
    if (prior->resolution() != map->resolution() || prior->gridOrigin() != map->gridOrigin() ||
        prior->gridSize() != map->gridSize()) {
      return R::fail("prior map: its grid (resolution " + std::to_string(prior->resolution()) +
                     " m) differs from the mapping grid (map.resolution_m " + std::to_string(grid.resolution_m) +
                     " and map.bounds)");
    }
    *map = *prior;  // a deep copy: the prior itself is never changed
  }
  auto field = planning::DistanceField::truncated(*map, config.field_range_m);
  if (!field) return R::fail("field.range_m: " + field.reason());
  auto shared_field = std::make_shared<planning::DistanceField>(std::move(*field));
  return R::ok(std::unique_ptr<LiveMap>(new LiveMap(config, std::move(map), std::move(shared_field), std::move(prior))));
}

LiveMap::LiveMap(const MappingConfig& config, std::shared_ptr<planning::OccupancyMap> map,
                 std::shared_ptr<planning::DistanceField> field, std::shared_ptr<const planning::OccupancyMap> prior)
    : config_(config),
      map_(std::move(map)),
      field_(std::move(field)),
      prior_(std::move(prior)),
      seen_(std::make_shared<planning::SeenSpace>(*map_, config.seen)),
      tree_(std::make_unique<octomap::OcTree>(map_->resolution())) {
  if (prior_) seen_->markOccupied(*prior_);  // surveyed geometry
  tree_->setProbHit(config_.prob_hit);
  tree_->setProbMiss(config_.prob_miss);
  tree_->setClampingThresMin(config_.clamping_min);
  tree_->setClampingThresMax(config_.clamping_max);
  tree_->enableChangeDetection(true);
  const std::size_t voxels = static_cast<std::size_t>(map_->gridSize().prod());
  mark_.assign(voxels, 0);
  key_origin_ = map_->gridOrigin() + planning::VoxelIndex::Constant(kKeyOrigin);
  grid_size_ = map_->gridSize();
  saturated_.assign(voxels, 0);
  own_s_.assign(voxels, -std::numeric_limits<double>::infinity());
  received_.assign(voxels, kReceivedNone);
  received_s_.assign(voxels, 0.0);
  announced_.assign(voxels, 0);
  pending_mark_.assign(voxels, 0);
  pending_s_.assign(voxels, 0.0);
}

LiveMap::~LiveMap() = default;

std::vector<octomap::point3d> LiveMap::rayEnds(const DepthPoints& points, std::size_t& hits) {
  std::vector<octomap::point3d> ends;
  ends.reserve(points.hits_world.size() + points.free_rays_world.size());
  octomap::KeySet seen_outside;
  std::vector<std::size_t> touched;
  auto add = [&](const std::vector<Eigen::Vector3d>& pts) {
    for (const auto& p : pts) {
      const octomap::point3d q = toOcto(p);
      octomap::OcTreeKey key;
      if (!tree_->coordToKeyChecked(q, key)) continue;
      const std::ptrdiff_t index = gridIndex(key);
      if (index < 0) {
        if (seen_outside.insert(key).second) ends.push_back(q);
      } else if (mark_[static_cast<std::size_t>(index)] == 0) {
        mark_[static_cast<std::size_t>(index)] = 1;
        touched.push_back(static_cast<std::size_t>(index));
        ends.push_back(q);
      }
    }
  };
  add(points.hits_world);
  hits = ends.size();
  add(points.free_rays_world);
  for (const std::size_t index : touched) mark_[index] = 0;
  return ends;
}

void LiveMap::updateVoxel(const octomap::OcTreeKey& key, std::ptrdiff_t index, bool hit) {
  // OctoMap's updateNode aborts when the voxel is already clamped in the update's direction;
  // saturated_ remembers that per grid voxel, so those voxels are not even searched.
  const std::uint8_t skip = hit ? kSaturatedOccupied : kSaturatedFree;
  if (index >= 0 && saturated_[static_cast<std::size_t>(index)] == skip) return;
  // lazy_eval: the inner nodes' occupancy is not kept up to date (nothing here reads it) and the
  // tree is pruned in batches (pruneWhenGrown), not at every update: the same leaves, less work.
  const octomap::OcTreeNode* node = tree_->updateNode(key, hit, /*lazy_eval=*/true);
  if (index < 0 || node == nullptr) return;
  const float l = node->getLogOdds();
  saturated_[static_cast<std::size_t>(index)] = l <= tree_->getClampingThresMinLog()   ? kSaturatedFree
                                                : l >= tree_->getClampingThresMaxLog() ? kSaturatedOccupied
                                                                                       : 0;
}

int LiveMap::castRays(const DepthPoints& points) {
  // OctoMap's insertPointCloud (computeUpdate, then free cells, then occupied cells), with the set
  // of this frame's cells kept in a dense mark over the planner's grid instead of a hash set
  // (cells outside the grid: hash sets, as OctoMap does).
  std::size_t hits = 0;
  const std::vector<octomap::point3d> ends = rayEnds(points, hits);
  const octomap::point3d origin = toOcto(points.origin_world);
  std::vector<std::pair<octomap::OcTreeKey, std::ptrdiff_t>>& free_cells = free_cells_;
  std::vector<std::pair<octomap::OcTreeKey, std::ptrdiff_t>>& occupied_cells = occupied_cells_;
  std::vector<std::size_t>& touched = touched_;
  free_cells.clear();
  occupied_cells.clear();
  touched.clear();
  octomap::KeySet free_outside, occupied_outside;
  for (std::size_t i = 0; i < hits; ++i) {  // occupied ends first: a cell both free and occupied is occupied
    octomap::OcTreeKey key;
    if (!tree_->coordToKeyChecked(ends[i], key)) continue;
    const std::ptrdiff_t index = gridIndex(key);
    if (index < 0) {
      occupied_outside.insert(key);
    } else if (mark_[static_cast<std::size_t>(index)] == 0) {
      mark_[static_cast<std::size_t>(index)] = 2;
      touched.push_back(static_cast<std::size_t>(index));
      occupied_cells.push_back({key, index});
    }
  }
  const float max_range = static_cast<float>(config_.max_range_m);
  for (std::size_t i = 0; i < ends.size(); ++i) {
    const octomap::point3d end = i < hits ? ends[i] : origin + (ends[i] - origin).normalized() * max_range;
    if (!tree_->computeRayKeys(origin, end, keyray_)) continue;
    for (const octomap::OcTreeKey& key : keyray_) {
      const std::ptrdiff_t index = gridIndex(key);
      if (index < 0) {
        if (!occupied_outside.count(key)) free_outside.insert(key);
      } else if (mark_[static_cast<std::size_t>(index)] == 0) {
        mark_[static_cast<std::size_t>(index)] = 1;
        touched.push_back(static_cast<std::size_t>(index));
        free_cells.push_back({key, index});
      }
    }
  }
  for (const auto& [key, index] : free_cells) updateVoxel(key, index, false);
  for (const auto& key : free_outside) updateVoxel(key, -1, false);
  for (const auto& [key, index] : occupied_cells) updateVoxel(key, index, true);
  for (const auto& key : occupied_outside) updateVoxel(key, -1, true);
  for (const std::size_t index : touched) mark_[index] = 0;
  pruneWhenGrown();
  return static_cast<int>(ends.size());
}

void LiveMap::pruneWhenGrown() {
  // Collapses clamped, uniform octants once the tree has doubled since the last pass: linear in
  // the tree's size, so the cost per update stays bounded and the memory within twice the pruned tree.
  constexpr std::size_t kMinNodes = 1 << 16;
  if (tree_->size() < std::max(kMinNodes, 2 * nodes_after_prune_)) return;
  tree_->prune();
  nodes_after_prune_ = tree_->size();
}

planning::VoxelIndex LiveMap::voxelOfIndex(std::size_t index) const {
  const auto nx = static_cast<std::size_t>(grid_size_.x()), ny = static_cast<std::size_t>(grid_size_.y());
  return map_->gridOrigin() + planning::VoxelIndex(static_cast<int>(index % nx), static_cast<int>((index / nx) % ny),
                                                   static_cast<int>(index / (nx * ny)));
}

octomap::OcTreeKey LiveMap::keyOfIndex(std::size_t index) const {
  const planning::VoxelIndex k = voxelOfIndex(index) + planning::VoxelIndex::Constant(kKeyOrigin);
  return octomap::OcTreeKey(static_cast<octomap::key_type>(k.x()), static_cast<octomap::key_type>(k.y()),
                            static_cast<octomap::key_type>(k.z()));
}

bool LiveMap::ownOccupied(std::size_t index) const {
  const octomap::OcTreeNode* node = tree_->search(keyOfIndex(index));
  return node != nullptr && tree_->isNodeOccupied(node);
}

bool LiveMap::fusedOccupied(std::size_t index, const planning::VoxelIndex& voxel, bool own_occupied) const {
  if (prior_ && prior_->isOccupied(voxel)) return true;
  if (received_[index] != kReceivedNone) return received_[index] == kReceivedOccupied;
  return own_occupied;
}

void LiveMap::notePending(std::size_t index, const planning::VoxelIndex& voxel, bool own_occupied, double stamp_s) {
  if (prior_ && prior_->isOccupied(voxel)) return;  // every UAV holds the prior: nothing to tell
  if ((own_occupied ? 1 : 0) == (announced_[index] & kAnnouncedOccupied) && pending_mark_[index] == 0) return;
  pending_s_[index] = stamp_s;
  if (pending_mark_[index] == 0) {
    pending_mark_[index] = 1;
    pending_.push_back(index);
  }
}

std::vector<std::size_t> LiveMap::stampOwnCells(double stamp_s) {
  std::vector<std::size_t> recheck;
  auto stamp = [&](const std::vector<std::pair<octomap::OcTreeKey, std::ptrdiff_t>>& cells, bool hit) {
    for (const auto& cell : cells) {
      const auto index = static_cast<std::size_t>(cell.second);
      own_s_[index] = std::max(own_s_[index], stamp_s);
      // The own word is newer — or a return here contradicts a received "free", whatever its stamp:
      // an update's stamp is the sender's newest frame, not when it saw this voxel (a free voxel
      // may wait in its queue for seconds), so a received free never outweighs an own return.
      const bool newer = received_s_[index] <= stamp_s;
      const bool contradicted = hit && received_[index] == kReceivedFree;
      if (received_[index] != kReceivedNone && (newer || contradicted)) {
        received_[index] = kReceivedNone;
        recheck.push_back(index);
      }
    }
  };
  stamp(free_cells_, false);
  stamp(occupied_cells_, true);
  return recheck;
}

std::vector<planning::VoxelChange> LiveMap::fusedChanges(int& observed_changes, const std::vector<std::size_t>& recheck) {
  std::vector<planning::VoxelChange> changes;
  std::vector<std::size_t> marked;
  observed_changes = 0;
  for (auto it = tree_->changedKeysBegin(), end = tree_->changedKeysEnd(); it != end; ++it) {
    ++observed_changes;
    const planning::VoxelIndex voxel = map_->voxelOf(
        Eigen::Vector3d(tree_->keyToCoord(it->first[0]), tree_->keyToCoord(it->first[1]), tree_->keyToCoord(it->first[2])));
    const octomap::OcTreeNode* node = tree_->search(it->first);
    const bool seen_occupied = node != nullptr && tree_->isNodeOccupied(node);
    const std::ptrdiff_t index = gridIndex(it->first);
    bool occupied = seen_occupied || (prior_ && prior_->isOccupied(voxel));
    if (index >= 0) {
      const auto u = static_cast<std::size_t>(index);
      notePending(u, voxel, seen_occupied, map_stamp_s_);
      occupied = fusedOccupied(u, voxel, seen_occupied);
      mark_[u] = 3;
      marked.push_back(u);
    }
    if (occupied != map_->isOccupied(voxel)) changes.push_back({voxel, occupied});
  }
  tree_->resetChangeDetection();
  for (const std::size_t index : recheck) {  // a received class replaced by an unchanged own observation
    if (mark_[index] == 3) continue;
    const planning::VoxelIndex voxel = voxelOfIndex(index);
    const bool occupied = fusedOccupied(index, voxel, ownOccupied(index));
    if (occupied != map_->isOccupied(voxel)) changes.push_back({voxel, occupied});
  }
  for (const std::size_t index : marked) mark_[index] = 0;
  return changes;
}

common::Result<FrameUpdate> LiveMap::integrate(const DepthFrame& frame) {
  using R = common::Result<FrameUpdate>;
  const auto t0 = std::chrono::steady_clock::now();
  const auto points = depthToPoints(frame, config_, 2.0 * map_->resolution());
  if (!points) return R::fail(points.reason());
  FrameUpdate out;
  out.pixels = points->pixels;
  out.hits = static_cast<int>(points->hits_world.size());
  out.free_rays = static_cast<int>(points->free_rays_world.size());
  out.skipped = points->skipped_invalid + points->skipped_near;
  out.points_ms = msSince(t0);

  const auto t1 = std::chrono::steady_clock::now();
  out.rays_cast = castRays(*points);
  out.tree_nodes = tree_->size();
  out.raycast_ms = msSince(t1);

  const auto t2 = std::chrono::steady_clock::now();
  map_stamp_s_ = std::max(map_stamp_s_, frame.stamp_s);
  const std::vector<std::size_t> recheck = stampOwnCells(frame.stamp_s);
  const std::vector<planning::VoxelChange> changes = fusedChanges(out.observed_changes, recheck);
  std::unique_lock<std::shared_mutex> lock(mutex_);
  const std::vector<planning::VoxelIndex> changed = map_->setOccupancy(changes);
  for (const auto& cell : free_cells_) seen_->markLinear(static_cast<std::size_t>(cell.second));  // castRays' cells
  for (const auto& cell : occupied_cells_) seen_->markLinear(static_cast<std::size_t>(cell.second));
  out.map_changes = static_cast<int>(changed.size());
  out.map_ms = msSince(t2);

  const auto t3 = std::chrono::steady_clock::now();
  const auto field_stats = field_->update(*map_, changed);
  if (!field_stats) return R::fail(field_stats.reason());  // cannot happen: same grid by construction
  out.field = *field_stats;
  out.field_ms = msSince(t3);
  out.total_ms = msSince(t0);
  return R::ok(out);
}

KeyGrid LiveMap::keyGrid() const {
  KeyGrid g;
  g.resolution_m = map_->resolution();
  for (int a = 0; a < 3; ++a) {
    g.min_key[static_cast<std::size_t>(a)] = static_cast<std::uint16_t>(key_origin_[a]);
    g.max_key[static_cast<std::size_t>(a)] = static_cast<std::uint16_t>(key_origin_[a] + grid_size_[a] - 1);
  }
  return g;
}

common::Result<MergeResult> LiveMap::merge(const MapDelta& delta) {
  using R = common::Result<MergeResult>;
  const auto t0 = std::chrono::steady_clock::now();
  if (const std::string problem = deltaProblem(delta, keyGrid()); !problem.empty()) return R::fail(problem);
  MergeResult out;
  out.voxels = static_cast<int>(delta.size());
  std::vector<planning::VoxelChange> changes;
  std::vector<std::size_t> marked;
  auto take = [&](const std::vector<VoxelKey>& keys, bool occupied) {
    for (const VoxelKey& k : keys) {
      const std::ptrdiff_t i = gridIndex(octomap::OcTreeKey(k[0], k[1], k[2]));
      const auto index = static_cast<std::size_t>(i);  // ≥ 0: deltaProblem checked the keys
      if (own_s_[index] >= delta.stamp_s || (received_[index] != kReceivedNone && received_s_[index] > delta.stamp_s) ||
          mark_[index] != 0) {
        ++out.superseded;  // seen here since, a newer received class, or listed twice
        continue;
      }
      // A received "free" never clears what this UAV's own camera holds occupied: the update's stamp
      // is the sender's newest frame, not when it saw this voxel (docs/mapping.md §8), so it cannot
      // tell which word is newer; the own camera clears it when it sees the place free.
      if (!occupied && ownOccupied(index)) {
        ++out.superseded;
        continue;
      }
      received_[index] = occupied ? kReceivedOccupied : kReceivedFree;
      received_s_[index] = delta.stamp_s;
      mark_[index] = 1;
      marked.push_back(index);
      const planning::VoxelIndex voxel = voxelOfIndex(index);
      const bool fused = fusedOccupied(index, voxel, occupied);
      if (fused != map_->isOccupied(voxel)) changes.push_back({voxel, fused});
    }
  };
  take(delta.occupied, true);
  take(delta.free, false);
  for (const std::size_t index : marked) mark_[index] = 0;
  std::unique_lock<std::shared_mutex> lock(mutex_);
  const std::vector<planning::VoxelIndex> changed = map_->setOccupancy(changes);
  out.map_changes = static_cast<int>(changed.size());
  const auto field_stats = field_->update(*map_, changed);
  if (!field_stats) return R::fail(field_stats.reason());  // cannot happen: same grid by construction
  out.field = *field_stats;
  out.total_ms = msSince(t0);
  return R::ok(out);
}

MapDelta LiveMap::takeChanges(const Eigen::Vector3d& p_sender_world, double now_s, std::size_t max_voxels, double max_age_s,
                              OutgoingStats* stats) {
  MapDelta delta;
  delta.stamp_s = map_stamp_s_;
  delta.resolution_m = map_->resolution();
  OutgoingStats s;
  struct Candidate {
    double distance_m, stamp_s;
    std::size_t index;
    bool occupied;
  };
  std::vector<Candidate> candidates;
  for (const std::size_t index : pending_) {
    const bool occupied = ownOccupied(index);
    if ((occupied ? 1 : 0) == (announced_[index] & kAnnouncedOccupied)) {
      pending_mark_[index] = 0;  // changed back: receivers hold the right class
    } else if (now_s - pending_s_[index] > max_age_s) {
      pending_mark_[index] = 0;
      ++s.dropped;
    } else {
      const Eigen::Vector3d c = map_->centerOf(voxelOfIndex(index));
      candidates.push_back({(c - p_sender_world).norm(), pending_s_[index], index, occupied});
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.distance_m != b.distance_m ? a.distance_m < b.distance_m : a.stamp_s > b.stamp_s;
  });
  pending_.clear();
  std::vector<std::size_t> newly_occupied;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const Candidate& c = candidates[i];
    if (i >= max_voxels) {
      pending_.push_back(c.index);
      ++s.deferred;
      continue;
    }
    pending_mark_[c.index] = 0;
    mark_[c.index] = 4;  // sent in this update: not resent below (a key listed twice refuses the update)
    auto& a = announced_[c.index];
    a = static_cast<std::uint8_t>((a & kInRefreshList) | (c.occupied ? kAnnouncedOccupied : 0));
    if (c.occupied && (a & kInRefreshList) == 0) newly_occupied.push_back(c.index);
    const octomap::OcTreeKey k = keyOfIndex(c.index);
    (c.occupied ? delta.occupied : delta.free).push_back(VoxelKey{{k[0], k[1], k[2]}});
  }
  // Resend voxels announced occupied in earlier updates, round robin, in the room left (not the ones
  // just sent: they join the list after this pass). Entries no longer announced occupied leave it.
  const std::size_t room = max_voxels > delta.size() ? max_voxels - delta.size() : 0;
  std::size_t want = std::min(room, static_cast<std::size_t>(config_.share.refresh_share * static_cast<double>(max_voxels)));
  for (std::size_t scanned = 0, n = refresh_.size(); want > 0 && scanned < n && !refresh_.empty(); ++scanned) {
    if (refresh_cursor_ >= refresh_.size()) refresh_cursor_ = 0;
    const std::size_t index = refresh_[refresh_cursor_];
    if ((announced_[index] & kAnnouncedOccupied) == 0) {
      announced_[index] = static_cast<std::uint8_t>(announced_[index] & ~kInRefreshList);
      refresh_[refresh_cursor_] = refresh_.back();
      refresh_.pop_back();
      continue;
    }
    ++refresh_cursor_;
    if (mark_[index] == 4) continue;  // a change sent in this very update (announced again above)
    const octomap::OcTreeKey k = keyOfIndex(index);
    delta.occupied.push_back(VoxelKey{{k[0], k[1], k[2]}});
    ++s.refreshed;
    --want;
  }
  for (const auto& keys : {&delta.occupied, &delta.free}) {
    for (const VoxelKey& k : *keys) mark_[static_cast<std::size_t>(gridIndex(octomap::OcTreeKey(k[0], k[1], k[2])))] = 0;
  }
  for (const std::size_t index : newly_occupied) {
    announced_[index] = static_cast<std::uint8_t>(announced_[index] | kInRefreshList);
    refresh_.push_back(index);
  }
  s.sent = static_cast<int>(delta.size());
  if (stats != nullptr) *stats = s;
  return delta;
}

void LiveMap::restartClock(double now_s) {
  const double none = -std::numeric_limits<double>::infinity();
  std::fill(own_s_.begin(), own_s_.end(), none);
  std::fill(received_s_.begin(), received_s_.end(), none);
  for (const std::size_t index : pending_) pending_s_[index] = now_s;
  map_stamp_s_ = now_s;  // the changes carried over go out dated now (0 would lose them to every receiver's own word)
}

Observed LiveMap::observed(const Eigen::Vector3d& p_world) const {
  const octomap::OcTreeNode* node = tree_->search(toOcto(p_world));
  if (node == nullptr) return Observed::kUnknown;
  return tree_->isNodeOccupied(node) ? Observed::kOccupied : Observed::kFree;
}

}  // namespace gesture_formation::mapping

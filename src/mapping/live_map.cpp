#include "gesture_formation/mapping/live_map.hpp"

#include <chrono>
#include <mutex>

#include <octomap/OcTree.h>

namespace gesture_formation::mapping {

namespace {

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
  const octomap::OcTreeNode* node = tree_->updateNode(key, hit, /*lazy_eval=*/false);
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
  return static_cast<int>(ends.size());
}

std::vector<planning::VoxelChange> LiveMap::fusedChanges(int& observed_changes) {
  std::vector<planning::VoxelChange> changes;
  observed_changes = 0;
  for (auto it = tree_->changedKeysBegin(), end = tree_->changedKeysEnd(); it != end; ++it) {
    ++observed_changes;
    const planning::VoxelIndex voxel = map_->voxelOf(
        Eigen::Vector3d(tree_->keyToCoord(it->first[0]), tree_->keyToCoord(it->first[1]), tree_->keyToCoord(it->first[2])));
    const octomap::OcTreeNode* node = tree_->search(it->first);
    const bool seen_occupied = node != nullptr && tree_->isNodeOccupied(node);
    const bool occupied = seen_occupied || (prior_ && prior_->isOccupied(voxel));
    if (occupied != map_->isOccupied(voxel)) changes.push_back({voxel, occupied});
  }
  tree_->resetChangeDetection();
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
  out.raycast_ms = msSince(t1);

  const auto t2 = std::chrono::steady_clock::now();
  const std::vector<planning::VoxelChange> changes = fusedChanges(out.observed_changes);
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

Observed LiveMap::observed(const Eigen::Vector3d& p_world) const {
  const octomap::OcTreeNode* node = tree_->search(toOcto(p_world));
  if (node == nullptr) return Observed::kUnknown;
  return tree_->isNodeOccupied(node) ? Observed::kOccupied : Observed::kFree;
}

}  // namespace gesture_formation::mapping

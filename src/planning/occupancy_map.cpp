#include "gesture_formation/planning/occupancy_map.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <octomap/OcTree.h>

namespace gesture_formation::planning {

namespace {

constexpr double kEps = 1e-9;

}  // namespace

double OccupancyMap::rasterInflation(double resolution_m) { return 0.5 * std::sqrt(3.0) * resolution_m; }

OccupancyMap::OccupancyMap(const MapConfig& map) : resolution_m_(map.resolution_m) {
  for (int i = 0; i < 3; ++i) {
    origin_(i) = static_cast<int>(std::floor(map.bounds.min_world(i) / resolution_m_ + kEps));
    const int end = static_cast<int>(std::ceil(map.bounds.max_world(i) / resolution_m_ - kEps));
    size_(i) = std::max(1, end - origin_(i));
    blocks_(i) = (size_(i) + kBlock - 1) / kBlock;
  }
  grid_bounds_.min_world = origin_.cast<double>() * resolution_m_;
  grid_bounds_.max_world = (origin_ + size_).cast<double>() * resolution_m_;
  grid_.assign(static_cast<std::size_t>(size_.x()) * static_cast<std::size_t>(size_.y()) * static_cast<std::size_t>(size_.z()), 0);
}

VoxelIndex OccupancyMap::voxelOf(const Eigen::Vector3d& p_world) const {
  return VoxelIndex(static_cast<int>(std::floor(p_world.x() / resolution_m_)),
                    static_cast<int>(std::floor(p_world.y() / resolution_m_)),
                    static_cast<int>(std::floor(p_world.z() / resolution_m_)));
}

bool OccupancyMap::isOccupied(const VoxelIndex& v) const {
  const VoxelIndex local = v - origin_;
  if ((local.array() < 0).any() || (local.array() >= size_.array()).any()) return false;
  return grid_[linear(local)] != 0;
}

void OccupancyMap::rasterise(const PrimitiveSet& solids, const GroundSpec& ground) {
  const double rho = rasterInflation(resolution_m_) + kEps;
  // Voxels whose centre lies in [lo, hi] (world), clipped to the grid, as local indices.
  auto range = [&](const Aabb& box, VoxelIndex& a, VoxelIndex& b) {
    for (int i = 0; i < 3; ++i) {
      a(i) = std::max(0, static_cast<int>(std::ceil(box.min_world(i) / resolution_m_ - 0.5)) - origin_(i));
      b(i) = std::min(size_(i) - 1, static_cast<int>(std::floor(box.max_world(i) / resolution_m_ - 0.5)) - origin_(i));
    }
    return (a.array() <= b.array()).all();
  };
  auto mark = [&](const Aabb& box, const auto& distance) {
    VoxelIndex a, b;
    if (!range(box.inflated(rho), a, b)) return;
    for (int k = a.z(); k <= b.z(); ++k) {
      for (int j = a.y(); j <= b.y(); ++j) {
        for (int i = a.x(); i <= b.x(); ++i) {
          const VoxelIndex local(i, j, k);
          std::uint8_t& cell = grid_[linear(local)];
          if (cell == 0 && distance(centerOf(local + origin_)) <= rho) cell = 1;
        }
      }
    }
  };
  for (const auto& box : solids.boxes) mark(box.bounds(), [&](const Eigen::Vector3d& p) { return box.distance(p); });
  for (const auto& cyl : solids.cylinders) mark(cyl.bounds(), [&](const Eigen::Vector3d& p) { return cyl.distance(p); });
  if (ground.enabled) {
    Aabb below = grid_bounds_;
    below.max_world.z() = std::min(below.max_world.z(), ground.height_m);
    if (below.max_world.z() + rho >= below.min_world.z()) {
      mark(below, [&](const Eigen::Vector3d& p) { return std::max(0.0, p.z() - ground.height_m); });
    }
  }
}

void OccupancyMap::markFromOctree(const octomap::OcTree& tree) {
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const double size = it.getSize();
    const int n = std::max(1, static_cast<int>(std::lround(size / resolution_m_)));
    const octomap::point3d c = it.getCoordinate();
    const Eigen::Vector3d corner = Eigen::Vector3d(c.x(), c.y(), c.z()) - Eigen::Vector3d::Constant(0.5 * size);
    for (int k = 0; k < n; ++k) {
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          const Eigen::Vector3d p = corner + (Eigen::Vector3d(i, j, k).array() + 0.5).matrix() * resolution_m_;
          const VoxelIndex local = voxelOf(p) - origin_;
          if ((local.array() < 0).any() || (local.array() >= size_.array()).any()) {
            ++dropped_;
            continue;
          }
          grid_[linear(local)] = 1;
        }
      }
    }
  }
}

void OccupancyMap::finalise() {
  block_centers_.assign(static_cast<std::size_t>(blocks_.prod()), {});
  occupied_count_ = 0;
  auto tree = std::make_shared<octomap::OcTree>(resolution_m_);
  const float occupied_log = tree->getClampingThresMaxLog();
  for (int k = 0; k < size_.z(); ++k) {
    for (int j = 0; j < size_.y(); ++j) {
      for (int i = 0; i < size_.x(); ++i) {
        const VoxelIndex local(i, j, k);
        if (grid_[linear(local)] == 0) continue;
        const Eigen::Vector3d c = centerOf(local + origin_);
        block_centers_[blockOfLocal(local)].push_back(c);
        ++occupied_count_;
        octomap::OcTreeKey key;
        if (tree->coordToKeyChecked(octomap::point3d(static_cast<float>(c.x()), static_cast<float>(c.y()),
                                                     static_cast<float>(c.z())),
                                    key)) {
          tree->setNodeValue(key, occupied_log, true);
        }
      }
    }
  }
  tree->updateInnerOccupancy();
  tree->prune();
  octree_ = tree;
}

OccupancyMap::OccupancyMap(const OccupancyMap& other)
    : resolution_m_(other.resolution_m_),
      grid_bounds_(other.grid_bounds_),
      origin_(other.origin_),
      size_(other.size_),
      blocks_(other.blocks_),
      grid_(other.grid_),
      block_centers_(other.block_centers_),
      occupied_count_(other.occupied_count_),
      dropped_(other.dropped_),
      octree_(other.octree_ ? std::make_shared<octomap::OcTree>(*other.octree_) : nullptr) {}

OccupancyMap& OccupancyMap::operator=(const OccupancyMap& other) {
  if (this != &other) *this = OccupancyMap(other);
  return *this;
}

std::vector<Eigen::Vector3d> OccupancyMap::occupiedCenters() const {
  std::vector<Eigen::Vector3d> out;
  out.reserve(occupied_count_);
  for (const auto& block : block_centers_) out.insert(out.end(), block.begin(), block.end());
  return out;
}

std::vector<VoxelIndex> OccupancyMap::setOccupancy(const std::vector<VoxelChange>& changes) {
  std::vector<VoxelIndex> changed;
  const float occupied_log = octree_->getClampingThresMaxLog();
  for (const VoxelChange& change : changes) {
    const VoxelIndex local = change.voxel - origin_;
    if ((local.array() < 0).any() || (local.array() >= size_.array()).any()) continue;
    std::uint8_t& cell = grid_[linear(local)];
    if ((cell != 0) == change.occupied) continue;
    cell = change.occupied ? 1 : 0;
    const Eigen::Vector3d c = centerOf(change.voxel);
    std::vector<Eigen::Vector3d>& block = block_centers_[blockOfLocal(local)];
    const octomap::point3d c_octo(static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z()));
    if (change.occupied) {
      block.push_back(c);
      ++occupied_count_;
      octree_->setNodeValue(c_octo, occupied_log, false);
    } else {
      const auto it = std::find(block.begin(), block.end(), c);
      if (it != block.end()) {
        *it = block.back();
        block.pop_back();
      }
      --occupied_count_;
      // Marked free rather than deleted (OctoMap 1.9.7's deleteNode leaves childless inner nodes
      // that assert when the tree is destroyed); FCL treats free nodes as empty.
      octree_->setNodeValue(c_octo, octree_->getClampingThresMinLog(), false);
    }
    changed.push_back(change.voxel);
  }
  return changed;
}

void OccupancyMap::pointsInBox(const Aabb& box, std::vector<Eigen::Vector3d>& out) const {
  VoxelIndex a, b;
  for (int i = 0; i < 3; ++i) {
    a(i) = std::max(0, static_cast<int>(std::ceil(box.min_world(i) / resolution_m_ - 0.5)) - origin_(i));
    b(i) = std::min(size_(i) - 1, static_cast<int>(std::floor(box.max_world(i) / resolution_m_ - 0.5)) - origin_(i));
    if (a(i) > b(i)) return;
  }
  const VoxelIndex ba = a / kBlock, bb = b / kBlock;
  for (int k = ba.z(); k <= bb.z(); ++k) {
    for (int j = ba.y(); j <= bb.y(); ++j) {
      for (int i = ba.x(); i <= bb.x(); ++i) {
        const std::size_t blk = static_cast<std::size_t>(i) +
                                static_cast<std::size_t>(blocks_.x()) *
                                    (static_cast<std::size_t>(j) + static_cast<std::size_t>(blocks_.y()) * static_cast<std::size_t>(k));
        for (const Eigen::Vector3d& c : block_centers_[blk]) {
          if (box.contains(c)) out.push_back(c);
        }
      }
    }
  }
}

OccupancyMap OccupancyMap::fromPrimitives(const MapConfig& map, const PrimitiveSet& solids, const GroundSpec& ground) {
  OccupancyMap m(map);
  m.rasterise(solids, ground);
  m.finalise();
  return m;
}

common::Result<OccupancyMap> OccupancyMap::fromOctomapFile(const MapConfig& map, const std::string& path) {
  using R = common::Result<OccupancyMap>;
  if (!std::ifstream(path)) return R::fail(path + ": cannot open file");
  octomap::OcTree tree(map.resolution_m);
  if (!tree.readBinary(path)) return R::fail(path + ": not a readable OctoMap .bt file");
  if (std::abs(tree.getResolution() - map.resolution_m) > 1e-9) {
    return R::fail(path + ": resolution " + std::to_string(tree.getResolution()) + " m differs from map.resolution_m " +
                   std::to_string(map.resolution_m));
  }
  OccupancyMap m(map);
  m.markFromOctree(tree);
  m.finalise();
  return R::ok(std::move(m));
}

common::Result<OccupancyMap> OccupancyMap::fromScenario(const Scenario& scenario) {
  using R = common::Result<OccupancyMap>;
  OccupancyMap m(scenario.map);
  if (!scenario.map.octomap_file.empty()) {
    const std::string& path = scenario.map.octomap_file;
    if (!std::ifstream(path)) return R::fail(path + ": cannot open file (map.octomap_file)");
    octomap::OcTree tree(scenario.map.resolution_m);
    if (!tree.readBinary(path)) return R::fail(path + ": not a readable OctoMap .bt file (map.octomap_file)");
    if (std::abs(tree.getResolution() - scenario.map.resolution_m) > 1e-9) {
      return R::fail(path + ": resolution " + std::to_string(tree.getResolution()) + " m differs from map.resolution_m");
    }
    m.markFromOctree(tree);
  }
  m.rasterise(scenario.primitives(), scenario.ground);
  m.finalise();
  return R::ok(std::move(m));
}

std::string OccupancyMap::writeBinary(const std::string& path) const {
  if (!octree_) return "no map";
  if (!octree_->writeBinaryConst(path)) return path + ": cannot write the OctoMap";
  return "";
}

}  // namespace gesture_formation::planning

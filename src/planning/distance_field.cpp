#include "gesture_formation/planning/distance_field.hpp"

#include <algorithm>
#include <cmath>

#include <fcl/geometry/octree/octree.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>
#include <octomap/OcTree.h>

namespace gesture_formation::planning {

namespace {

constexpr double kFar = 1e20;

/// One-dimensional squared distance transform of f (length n) into d, in voxel units.
void transform1d(const double* f, int n, double* d, int* v, double* z) {
  int k = 0;
  v[0] = 0;
  z[0] = -kFar;
  z[1] = kFar;
  // |s| < kFar always (f ≤ kFar, q − r ≥ 1), so z[0] = −kFar stops the loop at k = 0.
  for (int q = 1; q < n; ++q) {
    auto intersection = [&](int r) {
      return ((f[q] + static_cast<double>(q) * q) - (f[r] + static_cast<double>(r) * r)) / (2.0 * (q - r));
    };
    double s = intersection(v[k]);
    while (s <= z[k]) {
      --k;
      s = intersection(v[k]);
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = kFar;
  }
  k = 0;
  for (int q = 0; q < n; ++q) {
    while (z[k + 1] < q) ++k;
    const double dq = q - v[k];
    d[q] = dq * dq + f[v[k]];
  }
}

}  // namespace

DistanceField::DistanceField(const OccupancyMap& map)
    : DistanceField(map, std::numeric_limits<double>::infinity()) {}

DistanceField::DistanceField(const OccupancyMap& map, double max_distance_m)
    : resolution_m_(map.resolution()), max_distance_m_(max_distance_m), origin_(map.gridOrigin()), size_(map.gridSize()) {
  range_voxels_ = std::isfinite(max_distance_m_) ? static_cast<int>(std::ceil(max_distance_m_ / resolution_m_)) : 0;
  dist_m_.assign(static_cast<std::size_t>(size_.x()) * static_cast<std::size_t>(size_.y()) * static_cast<std::size_t>(size_.z()),
                 0.0f);
  recomputeBox(map.denseGrid(), LocalBox{VoxelIndex::Zero(), size_ - VoxelIndex::Ones()});
  scratch_ = std::vector<double>();  // a whole-grid scratch is not kept
}

common::Result<DistanceField> DistanceField::truncated(const OccupancyMap& map, double max_distance_m) {
  using R = common::Result<DistanceField>;
  if (!(std::isfinite(max_distance_m) && max_distance_m > 0.0)) {
    return R::fail("distance field max_distance_m must be finite and > 0, got " + std::to_string(max_distance_m));
  }
  return R::ok(DistanceField(map, max_distance_m));
}

float DistanceField::toMetres(double squared_voxels) const {
  if (squared_voxels >= 0.5 * kFar) return static_cast<float>(max_distance_m_);
  return static_cast<float>(std::min(std::sqrt(squared_voxels) * resolution_m_, max_distance_m_));
}

std::size_t DistanceField::recomputeBox(const std::vector<std::uint8_t>& occupancy, const LocalBox& target) {
  // The box whose occupancy decides the target's values: every voxel within the range of one.
  const VoxelIndex grow = range_voxels_ > 0 ? VoxelIndex::Constant(range_voxels_) : size_;
  const VoxelIndex lo = (target.lo - grow).cwiseMax(VoxelIndex::Zero());
  const VoxelIndex hi = (target.hi + grow).cwiseMin(size_ - VoxelIndex::Ones());
  const VoxelIndex n = hi - lo + VoxelIndex::Ones();
  const VoxelIndex t0 = target.lo - lo, t1 = target.hi - lo;  // the target, relative to lo
  const std::size_t nx = static_cast<std::size_t>(n.x()), ny = static_cast<std::size_t>(n.y());
  scratch_.resize(nx * ny * static_cast<std::size_t>(n.z()));
  auto at = [&](int i, int j, int k) -> double& {
    return scratch_[static_cast<std::size_t>(i) + nx * (static_cast<std::size_t>(j) + ny * static_cast<std::size_t>(k))];
  };
  for (int k = 0; k < n.z(); ++k) {
    for (int j = 0; j < n.y(); ++j) {
      const std::size_t row = linear(lo.x(), lo.y() + j, lo.z() + k);
      for (int i = 0; i < n.x(); ++i) at(i, j, k) = occupancy[row + static_cast<std::size_t>(i)] != 0 ? 0.0 : kFar;
    }
  }
  const int nmax = n.maxCoeff();
  std::vector<double> f(static_cast<std::size_t>(nmax)), d(static_cast<std::size_t>(nmax)),
      z(static_cast<std::size_t>(nmax) + 1);
  std::vector<int> v(static_cast<std::size_t>(nmax));
  // One 1-D transform along axis `axis` through (i, j, k) (its own coordinate ignored).
  auto line = [&](int axis, int i, int j, int k) {
    VoxelIndex q(i, j, k);
    for (q(axis) = 0; q(axis) < n(axis); ++q(axis)) f[static_cast<std::size_t>(q(axis))] = at(q.x(), q.y(), q.z());
    transform1d(f.data(), n(axis), d.data(), v.data(), z.data());
  };
  // x over the whole grown box; y only where the target's x lies; z only in the target's x-y.
  for (int k = 0; k < n.z(); ++k) {
    for (int j = 0; j < n.y(); ++j) {
      line(0, 0, j, k);
      for (int i = 0; i < n.x(); ++i) at(i, j, k) = std::min(d[static_cast<std::size_t>(i)], kFar);
    }
  }
  for (int k = 0; k < n.z(); ++k) {
    for (int i = t0.x(); i <= t1.x(); ++i) {
      line(1, i, 0, k);
      for (int j = 0; j < n.y(); ++j) at(i, j, k) = std::min(d[static_cast<std::size_t>(j)], kFar);
    }
  }
  for (int j = t0.y(); j <= t1.y(); ++j) {
    for (int i = t0.x(); i <= t1.x(); ++i) {
      line(2, i, j, 0);
      for (int k = t0.z(); k <= t1.z(); ++k) {
        dist_m_[linear(lo.x() + i, lo.y() + j, lo.z() + k)] = toMetres(std::min(d[static_cast<std::size_t>(k)], kFar));
      }
    }
  }
  return scratch_.size();
}

namespace {

double boxCost(const Eigen::Vector3i& lo, const Eigen::Vector3i& hi, int grow) {
  const Eigen::Vector3d n = (hi - lo).cast<double>().array() + 1.0 + 2.0 * grow;
  return n.prod();
}

}  // namespace

common::Result<FieldUpdateStats> DistanceField::update(const OccupancyMap& map, const std::vector<VoxelIndex>& changed_voxels) {
  using R = common::Result<FieldUpdateStats>;
  if (map.gridOrigin() != origin_ || map.gridSize() != size_ || map.resolution() != resolution_m_) {
    return R::fail("distance field update: the map's grid differs from the field's");
  }
  FieldUpdateStats stats;
  stats.changed_voxels = static_cast<int>(changed_voxels.size());
  if (changed_voxels.empty()) return R::ok(stats);
  std::vector<LocalBox> boxes;
  if (range_voxels_ == 0) {
    boxes.push_back(LocalBox{VoxelIndex::Zero(), size_ - VoxelIndex::Ones()});
  } else {
    // One box per kGroup³ group of changed voxels (their bounding box), grown by the range.
    constexpr int kGroup = 8;
    std::vector<std::pair<VoxelIndex, LocalBox>> groups;
    for (const VoxelIndex& voxel : changed_voxels) {
      const VoxelIndex local = voxel - origin_;
      if ((local.array() < 0).any() || (local.array() >= size_.array()).any()) continue;
      const VoxelIndex g = local / kGroup;
      auto it = std::find_if(groups.begin(), groups.end(), [&](const auto& e) { return e.first == g; });
      if (it == groups.end()) {
        groups.push_back({g, LocalBox{local, local}});
      } else {
        it->second.lo = it->second.lo.cwiseMin(local);
        it->second.hi = it->second.hi.cwiseMax(local);
      }
    }
    const VoxelIndex grow = VoxelIndex::Constant(range_voxels_);
    for (const auto& e : groups) {
      boxes.push_back(LocalBox{(e.second.lo - grow).cwiseMax(VoxelIndex::Zero()),
                               (e.second.hi + grow).cwiseMin(size_ - VoxelIndex::Ones())});
    }
    // Merge two boxes while one transform over their bounding box reads less than two.
    for (bool merged = true; merged;) {
      merged = false;
      for (std::size_t a = 0; a < boxes.size() && !merged; ++a) {
        for (std::size_t b = a + 1; b < boxes.size() && !merged; ++b) {
          const VoxelIndex lo = boxes[a].lo.cwiseMin(boxes[b].lo), hi = boxes[a].hi.cwiseMax(boxes[b].hi);
          if (boxCost(lo, hi, range_voxels_) <
              boxCost(boxes[a].lo, boxes[a].hi, range_voxels_) + boxCost(boxes[b].lo, boxes[b].hi, range_voxels_)) {
            boxes[a] = LocalBox{lo, hi};
            boxes.erase(boxes.begin() + static_cast<std::ptrdiff_t>(b));
            merged = true;
          }
        }
      }
    }
  }
  for (const LocalBox& box : boxes) {
    stats.voxels_read += recomputeBox(map.denseGrid(), box);
    stats.voxels_written += static_cast<std::size_t>((box.hi - box.lo + VoxelIndex::Ones()).prod());
  }
  stats.boxes = static_cast<int>(boxes.size());
  if (range_voxels_ == 0) scratch_ = std::vector<double>();
  return R::ok(stats);
}

double DistanceField::clearance(const Eigen::Vector3d& p_world) const {
  VoxelIndex local;
  for (int i = 0; i < 3; ++i) {
    local(i) = std::clamp(static_cast<int>(std::floor(p_world(i) / resolution_m_)) - origin_(i), 0, size_(i) - 1);
  }
  const double d = atLocal(local.x(), local.y(), local.z());
  if (!std::isfinite(d)) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d c = ((local + origin_).cast<double>().array() + 0.5).matrix() * resolution_m_;
  return std::max(0.0, d - (p_world - c).norm());
}

struct FclClearance::Impl {
  std::shared_ptr<fcl::OcTree<double>> tree;
  std::unique_ptr<fcl::CollisionObject<double>> tree_object;
  std::shared_ptr<fcl::Sphere<double>> probe;
  const OccupancyMap* map = nullptr;  ///< asked per query: a live map may start empty and fill
  bool empty() const { return map->occupiedCount() == 0; }
};

namespace {
constexpr double kProbeRadiusM = 1e-3;
}

FclClearance::FclClearance(const OccupancyMap& map) : impl_(std::make_unique<Impl>()) {
  impl_->map = &map;
  impl_->tree = std::make_shared<fcl::OcTree<double>>(map.octree());
  impl_->tree_object = std::make_unique<fcl::CollisionObject<double>>(impl_->tree);
  impl_->probe = std::make_shared<fcl::Sphere<double>>(kProbeRadiusM);
}

FclClearance::~FclClearance() = default;

double FclClearance::clearance(const Eigen::Vector3d& p_world) const {
  if (impl_->empty()) return std::numeric_limits<double>::infinity();
  fcl::Transform3<double> tf = fcl::Transform3<double>::Identity();
  tf.translation() = p_world;
  fcl::CollisionObject<double> probe(impl_->probe, tf);
  fcl::DistanceRequest<double> request;
  fcl::DistanceResult<double> result;
  fcl::distance(impl_->tree_object.get(), &probe, request, result);
  return std::max(0.0, result.min_distance + kProbeRadiusM);
}

bool FclClearance::collides(const Eigen::Vector3d& p_world, double radius_m) const {
  if (impl_->empty()) return false;
  fcl::Transform3<double> tf = fcl::Transform3<double>::Identity();
  tf.translation() = p_world;
  fcl::CollisionObject<double> ball(std::make_shared<fcl::Sphere<double>>(std::max(radius_m, kProbeRadiusM)), tf);
  fcl::CollisionRequest<double> request;
  fcl::CollisionResult<double> result;
  fcl::collide(impl_->tree_object.get(), &ball, request, result);
  return result.isCollision();
}

}  // namespace gesture_formation::planning

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
    : resolution_m_(map.resolution()), origin_(map.gridOrigin()), size_(map.gridSize()) {
  const std::size_t nx = static_cast<std::size_t>(size_.x()), ny = static_cast<std::size_t>(size_.y()),
                    nz = static_cast<std::size_t>(size_.z());
  const std::vector<std::uint8_t>& occ = map.denseGrid();
  std::vector<double> sq(occ.size());
  for (std::size_t i = 0; i < occ.size(); ++i) sq[i] = occ[i] != 0 ? 0.0 : kFar;
  const std::size_t nmax = std::max({nx, ny, nz});
  std::vector<double> f(nmax), d(nmax), z(nmax + 1);
  std::vector<int> v(nmax);
  auto pass = [&](std::size_t n, std::size_t stride, std::size_t count_outer, auto&& base_of) {
    for (std::size_t o = 0; o < count_outer; ++o) {
      const std::size_t base = base_of(o);
      for (std::size_t q = 0; q < n; ++q) f[q] = sq[base + q * stride];
      transform1d(f.data(), static_cast<int>(n), d.data(), v.data(), z.data());
      for (std::size_t q = 0; q < n; ++q) sq[base + q * stride] = std::min(d[q], kFar);
    }
  };
  pass(nx, 1, ny * nz, [&](std::size_t o) { return o * nx; });
  pass(ny, nx, nx * nz, [&](std::size_t o) { return (o % nx) + (o / nx) * nx * ny; });
  pass(nz, nx * ny, nx * ny, [&](std::size_t o) { return o; });
  dist_m_.resize(sq.size());
  for (std::size_t i = 0; i < sq.size(); ++i) {
    dist_m_[i] = sq[i] >= 0.5 * kFar ? std::numeric_limits<float>::infinity()
                                     : static_cast<float>(std::sqrt(sq[i]) * resolution_m_);
  }
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
  bool empty = true;
};

namespace {
constexpr double kProbeRadiusM = 1e-3;
}

FclClearance::FclClearance(const OccupancyMap& map) : impl_(std::make_unique<Impl>()) {
  impl_->empty = map.occupiedCount() == 0;
  impl_->tree = std::make_shared<fcl::OcTree<double>>(map.octree());
  impl_->tree_object = std::make_unique<fcl::CollisionObject<double>>(impl_->tree);
  impl_->probe = std::make_shared<fcl::Sphere<double>>(kProbeRadiusM);
}

FclClearance::~FclClearance() = default;

double FclClearance::clearance(const Eigen::Vector3d& p_world) const {
  if (impl_->empty) return std::numeric_limits<double>::infinity();
  fcl::Transform3<double> tf = fcl::Transform3<double>::Identity();
  tf.translation() = p_world;
  fcl::CollisionObject<double> probe(impl_->probe, tf);
  fcl::DistanceRequest<double> request;
  fcl::DistanceResult<double> result;
  fcl::distance(impl_->tree_object.get(), &probe, request, result);
  return std::max(0.0, result.min_distance + kProbeRadiusM);
}

bool FclClearance::collides(const Eigen::Vector3d& p_world, double radius_m) const {
  if (impl_->empty) return false;
  fcl::Transform3<double> tf = fcl::Transform3<double>::Identity();
  tf.translation() = p_world;
  fcl::CollisionObject<double> ball(std::make_shared<fcl::Sphere<double>>(std::max(radius_m, kProbeRadiusM)), tf);
  fcl::CollisionRequest<double> request;
  fcl::CollisionResult<double> result;
  fcl::collide(impl_->tree_object.get(), &ball, request, result);
  return result.isCollision();
}

}  // namespace gesture_formation::planning

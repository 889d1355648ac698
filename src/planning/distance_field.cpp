#include "gesture_formation/planning/distance_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

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
  const std::size_t voxels =
      static_cast<std::size_t>(size_.x()) * static_cast<std::size_t>(size_.y()) * static_cast<std::size_t>(size_.z());
  squared_.assign(voxels, kFarSquared);
  metres_.resize(std::size_t{kFarSquared} + 1);
  for (std::size_t n = 0; n < kFarSquared; ++n) metres_[n] = toMetres(static_cast<double>(n));
  metres_[kFarSquared] = static_cast<float>(max_distance_m_);  // truncated: beyond the range
  if (range_voxels_ == 0) {
    recomputeAll(map.denseGrid());
    return;
  }
  const std::size_t nmax = static_cast<std::size_t>(size_.maxCoeff());
  line_f_.resize(nmax);
  line_d_.resize(nmax);
  line_z_.resize(nmax + 1);
  line_v_.resize(nmax);
  pass1_.assign(voxels, kFarSquared);
  pass2_.assign(voxels, kFarSquared);
  for (int k = 0; k < size_.z(); ++k) {
    for (int j = 0; j < size_.y(); ++j) rowX(map.denseGrid(), j, k);
  }
  for (int k = 0; k < size_.z(); ++k) {
    for (int i = 0; i < size_.x(); ++i) columnY(i, k);
  }
  for (int j = 0; j < size_.y(); ++j) {
    for (int i = 0; i < size_.x(); ++i) columnZ(i, j, 0, size_.z() - 1);
  }
}

common::Result<DistanceField> DistanceField::truncated(const OccupancyMap& map, double max_distance_m) {
  using R = common::Result<DistanceField>;
  if (!(std::isfinite(max_distance_m) && max_distance_m > 0.0)) {
    return R::fail("distance field max_distance_m must be finite and > 0, got " + std::to_string(max_distance_m));
  }
  if (max_distance_m / map.resolution() > 255.0) {
    return R::fail("distance field max_distance_m must be at most 255 voxels (" + std::to_string(255.0 * map.resolution()) +
                   " m), got " + std::to_string(max_distance_m));
  }
  return R::ok(DistanceField(map, max_distance_m));
}

float DistanceField::toMetres(double squared_voxels) const {
  if (squared_voxels >= 0.5 * kFar) return static_cast<float>(max_distance_m_);
  return static_cast<float>(std::min(std::sqrt(squared_voxels) * resolution_m_, max_distance_m_));
}

void DistanceField::recomputeAll(const std::vector<std::uint8_t>& occupancy) {
  // The untruncated transform of the whole grid, in place in squared_ (2 bytes a voxel, no second
  // grid): every pass's squared voxel distances capped at kFarSquared. Capping a pass's input at C
  // caps its output at C and changes nothing below (min_q min(f_q, C) + (x − q)² = min(d_x, C): the
  // term q = x gives C), so the stored values below the cap are the exact ones, and the cap stands
  // for "at least sqrt(kFarSquared) voxels" (51.2 m at 0.2 m) — a lower bound, like every value.
  // The z pass reads a whole column into the line buffer before writing it back.
  const VoxelIndex n = size_;
  constexpr double kCap = kFarSquared;
  bool any = false;
  for (std::size_t v = 0; v < squared_.size(); ++v) {
    squared_[v] = occupancy[v] != 0 ? 0 : kFarSquared;
    any = any || occupancy[v] != 0;
  }
  // Beyond the cap: +inf on an empty map (no obstacle at all), else the cap's distance.
  metres_[kFarSquared] = any ? static_cast<float>(std::sqrt(kCap) * resolution_m_) : std::numeric_limits<float>::infinity();
  const int nmax = n.maxCoeff();
  std::vector<double> f(static_cast<std::size_t>(nmax)), d(static_cast<std::size_t>(nmax)),
      z(static_cast<std::size_t>(nmax) + 1);
  std::vector<int> v(static_cast<std::size_t>(nmax));
  // One 1-D transform along `axis` through (i, j, k) (its own coordinate ignored), written back capped.
  auto line = [&](int axis, int i, int j, int k) {
    VoxelIndex q(i, j, k);
    for (q(axis) = 0; q(axis) < n(axis); ++q(axis)) f[static_cast<std::size_t>(q(axis))] = squared_[linear(q.x(), q.y(), q.z())];
    transform1d(f.data(), n(axis), d.data(), v.data(), z.data());
    for (q(axis) = 0; q(axis) < n(axis); ++q(axis)) {
      squared_[linear(q.x(), q.y(), q.z())] = static_cast<std::uint16_t>(std::min(d[static_cast<std::size_t>(q(axis))], kCap));
    }
  };
  for (int k = 0; k < n.z(); ++k) {
    for (int j = 0; j < n.y(); ++j) line(0, 0, j, k);
  }
  for (int k = 0; k < n.z(); ++k) {
    for (int i = 0; i < n.x(); ++i) line(1, i, 0, k);
  }
  for (int j = 0; j < n.y(); ++j) {
    for (int i = 0; i < n.x(); ++i) line(2, i, j, 0);
  }
}

namespace {

std::uint16_t capSquared(double d, int range_voxels, std::uint16_t far) {
  return d <= static_cast<double>(range_voxels) * range_voxels ? static_cast<std::uint16_t>(d) : far;
}

}  // namespace

void DistanceField::rowX(const std::vector<std::uint8_t>& occupancy, int j, int k) {
  const int n = size_.x();
  const std::size_t row = linear(0, j, k);
  bool any = false;
  for (int i = 0; i < n; ++i) {
    const bool occupied = occupancy[row + static_cast<std::size_t>(i)] != 0;
    line_f_[static_cast<std::size_t>(i)] = occupied ? 0.0 : kFar;
    any = any || occupied;
  }
  if (!any) {  // an empty line stays empty: every transform of it is far
    std::fill_n(pass1_.begin() + static_cast<std::ptrdiff_t>(row), n, kFarSquared);
    return;
  }
  transform1d(line_f_.data(), n, line_d_.data(), line_v_.data(), line_z_.data());
  for (int i = 0; i < n; ++i) pass1_[row + static_cast<std::size_t>(i)] = capSquared(line_d_[static_cast<std::size_t>(i)], range_voxels_, kFarSquared);
}

void DistanceField::columnY(int i, int k) {
  const int n = size_.y();
  bool any = false;
  for (int j = 0; j < n; ++j) {
    const std::uint16_t s = pass1_[linear(i, j, k)];
    line_f_[static_cast<std::size_t>(j)] = s == kFarSquared ? kFar : static_cast<double>(s);
    any = any || s != kFarSquared;
  }
  if (any) transform1d(line_f_.data(), n, line_d_.data(), line_v_.data(), line_z_.data());
  for (int j = 0; j < n; ++j) {
    pass2_[linear(i, j, k)] = any ? capSquared(line_d_[static_cast<std::size_t>(j)], range_voxels_, kFarSquared) : kFarSquared;
  }
}

void DistanceField::columnZ(int i, int j, int k_lo, int k_hi) {
  const int n = size_.z();
  bool any = false;
  for (int k = 0; k < n; ++k) {
    const std::uint16_t s = pass2_[linear(i, j, k)];
    line_f_[static_cast<std::size_t>(k)] = s == kFarSquared ? kFar : static_cast<double>(s);
    any = any || s != kFarSquared;
  }
  if (!any) {
    for (int k = k_lo; k <= k_hi; ++k) squared_[linear(i, j, k)] = kFarSquared;
    return;
  }
  transform1d(line_f_.data(), n, line_d_.data(), line_v_.data(), line_z_.data());
  // Beyond the range the value is max_distance_m (metres_[kFarSquared]), as toMetres gives it.
  for (int k = k_lo; k <= k_hi; ++k) {
    squared_[linear(i, j, k)] = capSquared(line_d_[static_cast<std::size_t>(k)], range_voxels_, kFarSquared);
  }
}

FieldUpdateStats DistanceField::updateTruncated(const std::vector<std::uint8_t>& occupancy,
                                                const std::vector<VoxelIndex>& changed) {
  const int nx = size_.x(), ny = size_.y(), nz = size_.z(), r = range_voxels_;
  constexpr int kNone = std::numeric_limits<int>::max();
  // x rows holding a changed voxel, with the x range of the changes
  std::vector<int> rows, row_lo(static_cast<std::size_t>(ny) * static_cast<std::size_t>(nz), kNone),
      row_hi(row_lo.size(), -1);
  for (const VoxelIndex& voxel : changed) {
    const VoxelIndex c = voxel - origin_;
    if ((c.array() < 0).any() || (c.array() >= size_.array()).any()) continue;
    const std::size_t row = static_cast<std::size_t>(c.y()) + static_cast<std::size_t>(ny) * static_cast<std::size_t>(c.z());
    if (row_lo[row] == kNone) rows.push_back(static_cast<int>(row));
    row_lo[row] = std::min(row_lo[row], c.x());
    row_hi[row] = std::max(row_hi[row], c.x());
  }
  // y columns (i, k) whose pass-1 input changed within the range, with the y range of the rows
  std::vector<int> columns, col_lo(static_cast<std::size_t>(nx) * static_cast<std::size_t>(nz), kNone),
      col_hi(col_lo.size(), -1);
  for (const int row : rows) {
    const int j = row % ny, k = row / ny;
    rowX(occupancy, j, k);
    for (int i = std::max(0, row_lo[static_cast<std::size_t>(row)] - r);
         i <= std::min(nx - 1, row_hi[static_cast<std::size_t>(row)] + r); ++i) {
      const std::size_t col = static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * static_cast<std::size_t>(k);
      if (col_lo[col] == kNone) columns.push_back(static_cast<int>(col));
      col_lo[col] = std::min(col_lo[col], j);
      col_hi[col] = std::max(col_hi[col], j);
    }
  }
  // z columns (i, j) whose pass-2 input changed, with the z range of the change (values change
  // only within the range of it)
  std::vector<int> verticals, vert_lo(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny), kNone),
      vert_hi(vert_lo.size(), -1);
  for (const int col : columns) {
    const int i = col % nx, k = col / nx;
    columnY(i, k);
    for (int j = std::max(0, col_lo[static_cast<std::size_t>(col)] - r);
         j <= std::min(ny - 1, col_hi[static_cast<std::size_t>(col)] + r); ++j) {
      const std::size_t xy = static_cast<std::size_t>(i) + static_cast<std::size_t>(nx) * static_cast<std::size_t>(j);
      if (vert_lo[xy] == kNone) verticals.push_back(static_cast<int>(xy));
      vert_lo[xy] = std::min(vert_lo[xy], k);
      vert_hi[xy] = std::max(vert_hi[xy], k);
    }
  }
  FieldUpdateStats stats;
  for (const int xy : verticals) {
    const int k_lo = std::max(0, vert_lo[static_cast<std::size_t>(xy)] - r);
    const int k_hi = std::min(nz - 1, vert_hi[static_cast<std::size_t>(xy)] + r);
    columnZ(xy % nx, xy / nx, k_lo, k_hi);
    stats.voxels_written += static_cast<std::size_t>(k_hi - k_lo + 1);
  }
  stats.lines = static_cast<int>(rows.size() + columns.size() + verticals.size());
  return stats;
}

common::Result<FieldUpdateStats> DistanceField::update(const OccupancyMap& map, const std::vector<VoxelIndex>& changed_voxels) {
  using R = common::Result<FieldUpdateStats>;
  if (map.gridOrigin() != origin_ || map.gridSize() != size_ || map.resolution() != resolution_m_) {
    return R::fail("distance field update: the map's grid differs from the field's");
  }
  FieldUpdateStats stats;
  if (!changed_voxels.empty()) {
    if (range_voxels_ > 0) {
      stats = updateTruncated(map.denseGrid(), changed_voxels);
    } else {
      recomputeAll(map.denseGrid());
      stats.lines = size_.y() * size_.z() + size_.x() * size_.z() + size_.x() * size_.y();
      stats.voxels_written = squared_.size();
    }
  }
  stats.changed_voxels = static_cast<int>(changed_voxels.size());
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

#include "gesture_formation/sim/depth_raycaster.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace gesture_formation::sim {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kTilePx = 32;  ///< image tiles of the per-frame candidate lists

/// Entry distance of the ray into the axis-aligned box [lo, hi] within [0, t_max]; +inf: missed.
double slab(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
            double t_max) {
  double t0 = 0.0, t1 = t_max;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-15) {
      if (o[a] < lo[a] || o[a] > hi[a]) return kInf;
      continue;
    }
    const double inv = 1.0 / d[a];
    double ta = (lo[a] - o[a]) * inv, tb = (hi[a] - o[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return kInf;
  }
  return t0;
}

/// The 8 corners of an AABB.
std::array<Eigen::Vector3d, 8> corners(const planning::Aabb& b) {
  std::array<Eigen::Vector3d, 8> c;
  for (int i = 0; i < 8; ++i) {
    c[static_cast<std::size_t>(i)] = Eigen::Vector3d(i & 1 ? b.max_world.x() : b.min_world.x(),
                                                     i & 2 ? b.max_world.y() : b.min_world.y(),
                                                     i & 4 ? b.max_world.z() : b.min_world.z());
  }
  return c;
}

/// Distance from p to the AABB (0 inside).
double aabbDistance(const planning::Aabb& b, const Eigen::Vector3d& p) {
  const Eigen::Vector3d q = (b.min_world - p).cwiseMax(p - b.max_world).cwiseMax(0.0);
  return q.norm();
}

struct Candidate {
  const planning::OrientedBox* box = nullptr;  ///< one of box, cylinder
  const planning::Cylinder* cylinder = nullptr;
  planning::Aabb bounds;
};

/// Pixel rectangle [u0, u1] × [v0, v1] (inclusive) the AABB can cover; false: not in view.
bool pixelRect(const planning::Aabb& b, const Eigen::Isometry3d& T_camera_world, const estimation::CameraIntrinsics& k,
               int& u0, int& u1, int& v0, int& v1) {
  double umin = kInf, umax = -kInf, vmin = kInf, vmax = -kInf;
  int behind = 0;
  for (const Eigen::Vector3d& c : corners(b)) {
    const Eigen::Vector3d p = T_camera_world * c;
    if (p.z() <= 1e-3) {
      ++behind;
      continue;
    }
    const double u = k.fx * p.x() / p.z() + k.cx, v = k.fy * p.y() / p.z() + k.cy;
    umin = std::min(umin, u);
    umax = std::max(umax, u);
    vmin = std::min(vmin, v);
    vmax = std::max(vmax, v);
  }
  if (behind == 8) return false;
  if (behind > 0) {  // straddles the camera plane: anywhere in the image (conservative)
    u0 = 0, v0 = 0, u1 = k.width_px - 1, v1 = k.height_px - 1;
    return true;
  }
  u0 = std::max(0, static_cast<int>(std::floor(umin)) - 1);
  v0 = std::max(0, static_cast<int>(std::floor(vmin)) - 1);
  u1 = std::min(k.width_px - 1, static_cast<int>(std::ceil(umax)) + 1);
  v1 = std::min(k.height_px - 1, static_cast<int>(std::ceil(vmax)) + 1);
  return u0 <= u1 && v0 <= v1;
}

}  // namespace

Eigen::Isometry3d opticalPoseFromHeadingPitch(const Eigen::Vector3d& p_world, double heading_rad, double pitch_rad) {
  const Eigen::Vector3d z(std::cos(pitch_rad) * std::cos(heading_rad), std::cos(pitch_rad) * std::sin(heading_rad),
                          std::sin(pitch_rad));
  const Eigen::Vector3d x(std::sin(heading_rad), -std::cos(heading_rad), 0.0);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = z.cross(x);
  T.linear().col(2) = z;
  T.translation() = p_world;
  return T;
}

double rayBoxHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const planning::OrientedBox& box) {
  const Eigen::Matrix3d Rt = box.R_world_box.transpose();
  const Eigen::Vector3d o = Rt * (origin - box.center_world);
  const Eigen::Vector3d d = Rt * dir;
  const Eigen::Vector3d half = 0.5 * box.size_m;
  return slab(o, d, -half, half, kInf);
}

double rayCylinderHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const planning::Cylinder& c) {
  const Eigen::Vector3d axis_full = c.p1_world - c.p0_world;
  const double len = axis_full.norm();
  if (!(len > 0.0)) return kInf;
  const Eigen::Vector3d a = axis_full / len;
  const Eigen::Vector3d w = origin - c.p0_world;
  const double wa = w.dot(a), da = dir.dot(a);
  const Eigen::Vector3d w_perp = w - wa * a, d_perp = dir - da * a;
  const double r2 = c.radius_m * c.radius_m;
  double best = kInf;
  const double A = d_perp.squaredNorm(), B = 2.0 * w_perp.dot(d_perp), C = w_perp.squaredNorm() - r2;
  if (C <= 0.0 && wa >= 0.0 && wa <= len) return 0.0;  // the origin is inside
  if (A > 1e-18) {
    const double disc = B * B - 4.0 * A * C;
    if (disc >= 0.0) {
      const double t = (-B - std::sqrt(disc)) / (2.0 * A);  // entry through the side
      const double h = wa + t * da;
      if (t >= 0.0 && h >= 0.0 && h <= len) best = t;
    }
  }
  if (std::abs(da) > 1e-15) {
    for (const double h : {0.0, len}) {  // the end discs
      const double t = (h - wa) / da;
      if (t >= 0.0 && t < best && (w_perp + t * d_perp).squaredNorm() <= r2) best = t;
    }
  }
  return best;
}

DepthRaycaster::DepthRaycaster(const planning::PrimitiveSet& solids, double ground_height_m)
    : boxes_(solids.boxes), cylinders_(solids.cylinders), ground_height_m_(ground_height_m) {
  for (const auto& b : boxes_) box_bounds_.push_back(b.bounds());
  for (const auto& c : cylinders_) cylinder_bounds_.push_back(c.bounds());
}

cv::Mat DepthRaycaster::render(const estimation::CameraIntrinsics& k, const Eigen::Isometry3d& T_world_camera,
                               int pixel_stride, double max_range_m, const planning::PrimitiveSet& dynamic) const {
  const int W = k.width_px, H = k.height_px, stride = std::max(1, pixel_stride);
  cv::Mat depth(H, W, CV_32FC1, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  const Eigen::Vector3d o = T_world_camera.translation();
  const Eigen::Matrix3d R = T_world_camera.linear();
  const Eigen::Isometry3d T_camera_world = T_world_camera.inverse();
  // This frame's candidates: solids within range, binned into image tiles by their projection.
  std::vector<Candidate> cands;
  auto consider = [&](const planning::OrientedBox* b, const planning::Cylinder* c, const planning::Aabb& bounds) {
    if (aabbDistance(bounds, o) <= max_range_m) cands.push_back(Candidate{b, c, bounds});
  };
  for (std::size_t i = 0; i < boxes_.size(); ++i) consider(&boxes_[i], nullptr, box_bounds_[i]);
  for (std::size_t i = 0; i < cylinders_.size(); ++i) consider(nullptr, &cylinders_[i], cylinder_bounds_[i]);
  for (const auto& b : dynamic.boxes) consider(&b, nullptr, b.bounds());
  for (const auto& c : dynamic.cylinders) consider(nullptr, &c, c.bounds());
  const int tiles_u = (W + kTilePx - 1) / kTilePx, tiles_v = (H + kTilePx - 1) / kTilePx;
  std::vector<std::vector<int>> tiles(static_cast<std::size_t>(tiles_u * tiles_v));
  for (std::size_t i = 0; i < cands.size(); ++i) {
    int u0 = 0, u1 = 0, v0 = 0, v1 = 0;
    if (!pixelRect(cands[i].bounds, T_camera_world, k, u0, u1, v0, v1)) continue;
    for (int tv = v0 / kTilePx; tv <= v1 / kTilePx; ++tv) {
      for (int tu = u0 / kTilePx; tu <= u1 / kTilePx; ++tu) tiles[static_cast<std::size_t>(tv * tiles_u + tu)].push_back(static_cast<int>(i));
    }
  }
  const bool ground = std::isfinite(ground_height_m_);
  for (int v = 0; v < H; v += stride) {
    float* row = depth.ptr<float>(v);
    for (int u = 0; u < W; u += stride) {
      const Eigen::Vector3d d = R * Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);  // depth = t
      const double t_max = max_range_m / d.norm();
      double best = t_max;
      if (ground && d.z() < 0.0) best = std::min(best, std::max(0.0, (ground_height_m_ - o.z()) / d.z()));
      for (const int ci : tiles[static_cast<std::size_t>((v / kTilePx) * tiles_u + u / kTilePx)]) {
        const Candidate& c = cands[static_cast<std::size_t>(ci)];
        if (slab(o, d, c.bounds.min_world, c.bounds.max_world, best) >= best) continue;
        best = std::min(best, c.box != nullptr ? rayBoxHit(o, d, *c.box) : rayCylinderHit(o, d, *c.cylinder));
      }
      row[u] = best < t_max ? static_cast<float>(best) : std::numeric_limits<float>::infinity();
    }
  }
  return depth;
}

}  // namespace gesture_formation::sim

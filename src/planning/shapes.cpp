#include "gesture_formation/planning/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace gesture_formation::planning {

double OrientedBox::distance(const Eigen::Vector3d& p_world) const {
  const Eigen::Vector3d p_box = R_world_box.transpose() * (p_world - center_world);
  const Eigen::Vector3d outside = (p_box.cwiseAbs() - 0.5 * size_m).cwiseMax(0.0);
  return outside.norm();
}

Aabb OrientedBox::bounds() const {
  // Half extent along world axis i: sum_j |R_ij| h_j.
  const Eigen::Vector3d half = R_world_box.cwiseAbs() * (0.5 * size_m);
  return Aabb{center_world - half, center_world + half};
}

double Cylinder::distance(const Eigen::Vector3d& p_world) const {
  const Eigen::Vector3d axis = p1_world - p0_world;
  const double length = axis.norm();
  if (length <= 0.0) return std::max(0.0, (p_world - p0_world).norm() - radius_m);
  const Eigen::Vector3d u = axis / length;
  const Eigen::Vector3d d = p_world - p0_world;
  const double along = d.dot(u);
  const double radial = (d - along * u).norm();
  const double out_axial = std::max({0.0, -along, along - length});
  const double out_radial = std::max(0.0, radial - radius_m);
  return std::hypot(out_axial, out_radial);
}

Aabb Cylinder::bounds() const {
  const Eigen::Vector3d axis = p1_world - p0_world;
  const double length = axis.norm();
  Eigen::Vector3d half = Eigen::Vector3d::Constant(radius_m);
  if (length > 0.0) {
    const Eigen::Vector3d u = axis / length;
    // Extent of a disc of radius r with normal u along world axis i: r sqrt(1 - u_i^2).
    for (int i = 0; i < 3; ++i) half(i) = radius_m * std::sqrt(std::max(0.0, 1.0 - u(i) * u(i)));
  }
  return Aabb{p0_world.cwiseMin(p1_world) - half, p0_world.cwiseMax(p1_world) + half};
}

double Cylinder::volume() const { return M_PI * radius_m * radius_m * (p1_world - p0_world).norm(); }

double PrimitiveSet::distance(const Eigen::Vector3d& p_world) const {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& b : boxes) d = std::min(d, b.distance(p_world));
  for (const auto& c : cylinders) d = std::min(d, c.distance(p_world));
  return d;
}

Eigen::Matrix3d rotationFromRpy(double roll_rad, double pitch_rad, double yaw_rad) {
  return (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d closestPointOnSegment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& x) {
  const Eigen::Vector3d ab = b - a;
  const double L2 = ab.squaredNorm();
  if (!(L2 > 1e-18)) return a;
  return a + std::clamp((x - a).dot(ab) / L2, 0.0, 1.0) * ab;
}

double distanceToPolyline(const std::vector<Eigen::Vector3d>& poly, const Eigen::Vector3d& x) {
  double d = std::numeric_limits<double>::infinity();
  if (poly.size() == 1) return (x - poly.front()).norm();
  for (std::size_t i = 0; i + 1 < poly.size(); ++i) d = std::min(d, (x - closestPointOnSegment(poly[i], poly[i + 1], x)).norm());
  return d;
}

double distanceToPolyline(const std::vector<Eigen::Vector3d>& poly, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  if (poly.size() == 1) return (poly.front() - closestPointOnSegment(a, b, poly.front())).norm();
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < poly.size(); ++i) d = std::min(d, segmentSegmentDistance(a, b, poly[i], poly[i + 1]));
  return d;
}

double segmentSegmentDistance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                              const Eigen::Vector3d& d) {
  // Closest points: minimise |a + s·u − c − t·v| over s, t ∈ [0, 1] — the unconstrained optimum
  // clamped, then each parameter re-optimised for the other's (clamped) value.
  const Eigen::Vector3d u = b - a, v = d - c, w = a - c;
  const double uu = u.squaredNorm(), vv = v.squaredNorm();
  if (!(uu > 1e-18)) return (a - closestPointOnSegment(c, d, a)).norm();
  if (!(vv > 1e-18)) return (c - closestPointOnSegment(a, b, c)).norm();
  const double uv = u.dot(v), uw = u.dot(w), vw = v.dot(w);
  const double den = uu * vv - uv * uv;  // ≥ 0; 0: parallel
  double s = den > 1e-12 * uu * vv ? std::clamp((uv * vw - vv * uw) / den, 0.0, 1.0) : 0.0;
  const double t = std::clamp((uv * s + vw) / vv, 0.0, 1.0);
  s = std::clamp((uv * t - uw) / uu, 0.0, 1.0);
  return (a + s * u - c - t * v).norm();
}

std::vector<Eigen::Vector3d> simplifyPolyline(const std::vector<Eigen::Vector3d>& p, double tolerance) {
  if (p.size() < 3) return p;
  std::vector<Eigen::Vector3d> out{p.front()};
  std::size_t i = 0;
  while (i + 1 < p.size()) {
    std::size_t j = i + 1;
    while (j + 1 < p.size()) {
      bool ok = true;
      for (std::size_t m = i + 1; m <= j && ok; ++m) ok = (p[m] - closestPointOnSegment(p[i], p[j + 1], p[m])).norm() <= tolerance;
      if (!ok) break;
      ++j;
    }
    out.push_back(p[j]);
    i = j;
  }
  return out;
}

}  // namespace gesture_formation::planning

#pragma once
/// \file
/// \brief Bench-only anchor: DecompUtil's line-segment decomposition (Liu et al., RA-L 2017;
/// `LineSegment::dilate` with `offset_x = 0`, `DecompBase::set_obs` / `find_polyhedron`,
/// `Ellipsoid::dist` / `closest_point` / `closest_hyperplane`) written as that library does it —
/// the same steps, the same point handling and the same arithmetic — so that gf_bench_corridors
/// can time our CorridorBuilder against it on the same points (docs/planning.md §3 "Speed").
/// Our own code (read from DecompUtil's public sources for understanding); never linked by the
/// product. What DecompUtil does, and this anchor with it:
/// - the local box is oriented along the segment (x along it, y ⟂ to it and world z, z = x × y),
///   `bbox(0)` beyond each end, ±`bbox(1)` sideways, ±`bbox(2)` "up"; `set_obs` keeps the points
///   inside it (signed distance ≤ 1e-10 to each of its six planes) in a new vector;
/// - the ellipsoid is `{x : ‖C⁻¹ (x − d)‖ ≤ 1}`, C = R diag(axes) Rᵀ; every distance evaluation
///   inverts C (`Ellipsoid::dist`), and each shrink step copies the points still inside;
/// - the first pass shrinks both cross axes against the closest point inside, the frame rolled
///   so that the point lies in its x–y plane (R = R_initial · Rx(roll), not cumulative); the
///   second pass restores the third axis to L/2 and shrinks it alone (skipping a point whose
///   x–y part already fills the ellipsoid, `dd ≤ ε`, as the library's current version does);
/// - planes pass through their obstacle point (no clearance), normal C⁻¹C⁻ᵀ(p − d); a point is
///   kept while its signed distance is < 0; the six box planes are appended last.
/// Conventions: world frame, metres; rows `n·x ≤ n·p` with outward unit normals
/// (docs/conventions.md). Not thread-safe per object (one per segment, as DecompUtil).

#include <cmath>
#include <limits>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "gesture_formation/planning/polytope.hpp"

namespace gesture_formation::bench::decomp_reference {

/// DecompUtil's `epsilon_` (decomp_basis/data_type.h).
constexpr double kEpsilon = 1e-10;

/// \brief Plane through `p` with outward normal `n` (DecompUtil's Hyperplane).
struct Hyperplane {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d n = Eigen::Vector3d::UnitX();
  double signedDist(const Eigen::Vector3d& x) const { return n.dot(x - p); }
};

/// \brief Ellipsoid `‖C⁻¹ (x − d)‖ ≤ 1`. With `kInvertEachCall` (the library's behaviour) every
/// distance evaluation inverts C; without, C⁻¹ is kept next to C (a variant that tells how much of
/// the anchor's time that one detail costs).
template <bool kInvertEachCall>
struct Ellipsoid {
  Eigen::Matrix3d C = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d C_inv = Eigen::Matrix3d::Identity();
  Eigen::Vector3d d = Eigen::Vector3d::Zero();

  void setC(const Eigen::Matrix3d& c) {
    C = c;
    if (!kInvertEachCall) C_inv = c.inverse();
  }
  Eigen::Matrix3d inverseC() const { return kInvertEachCall ? Eigen::Matrix3d(C.inverse()) : C_inv; }
  double dist(const Eigen::Vector3d& x) const { return (inverseC() * (x - d)).norm(); }
  /// Non-exclusive, as DecompUtil: a point on the surface is inside.
  std::vector<Eigen::Vector3d> pointsInside(const std::vector<Eigen::Vector3d>& points) const {
    std::vector<Eigen::Vector3d> out;
    for (const Eigen::Vector3d& x : points) {
      if (dist(x) <= 1.0) out.push_back(x);
    }
    return out;
  }
  /// The point of `points` with the smallest dist (the first of equals).
  Eigen::Vector3d closestPoint(const std::vector<Eigen::Vector3d>& points) const {
    Eigen::Vector3d best = Eigen::Vector3d::Zero();
    double best_dist = std::numeric_limits<double>::max();
    for (const Eigen::Vector3d& x : points) {
      const double m = dist(x);
      if (m < best_dist) best_dist = m, best = x;
    }
    return best;
  }
  /// The plane through the closest point, tangent to the ellipsoid's level set there.
  Hyperplane closestHyperplane(const std::vector<Eigen::Vector3d>& points) const {
    const Eigen::Vector3d p = closestPoint(points);
    const Eigen::Vector3d n = inverseC() * inverseC().transpose() * (p - d);
    return Hyperplane{p, n.normalized()};
  }
};

/// \brief DecompUtil's `vec3_to_rotation`: x along v, zero roll (R = Rz(yaw) Ry(pitch)).
inline Eigen::Matrix3d rotationAlong(const Eigen::Vector3d& v) {
  const double pitch = std::atan2(-v.z(), v.head<2>().norm());
  const double yaw = std::atan2(v.y(), v.x());
  const Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())) *
                               Eigen::Quaterniond(Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()));
  return q.toRotationMatrix();
}

/// \brief One segment's decomposition (DecompUtil's LineSegment<3>): setObstacles, dilate, then
/// the ellipsoid and the planes (obstacle planes first, the six local-box planes last).
template <bool kInvertEachCall = true>
class LineSegmentDecomp {
 public:
  using EllipsoidT = Ellipsoid<kInvertEachCall>;

  /// \param bbox_m the local box's margins: beyond each end, sideways, "up" (m; all > 0).
  LineSegmentDecomp(const Eigen::Vector3d& p1_world, const Eigen::Vector3d& p2_world, const Eigen::Vector3d& bbox_m)
      : p1_(p1_world), p2_(p2_world), bbox_(bbox_m) {}

  /// \brief Keeps the points inside the local box (DecompBase::set_obs).
  void setObstacles(const std::vector<Eigen::Vector3d>& points_world) {
    std::vector<Hyperplane> box;
    addLocalBox(box);
    obs_.clear();
    for (const Eigen::Vector3d& x : points_world) {
      bool inside = true;
      for (const Hyperplane& h : box) {
        if (h.signedDist(x) > kEpsilon) {
          inside = false;
          break;
        }
      }
      if (inside) obs_.push_back(x);
    }
  }

  /// \brief LineSegment::dilate(0): ellipsoid, obstacle planes, local box.
  void dilate() {
    findEllipsoid();
    findPolyhedron();
    addLocalBox(planes_);
  }

  const EllipsoidT& ellipsoid() const { return ellipsoid_; }
  const std::vector<Hyperplane>& planes() const { return planes_; }
  std::size_t obstacleCount() const { return obs_.size(); }
  /// The ellipsoid's semi-axes in DecompUtil's own frame (along, cross, cross).
  const Eigen::Vector3d& axes() const { return axes_; }

  /// \brief The polytope as rows `n·x ≤ n·p` (the form DecompUtil's LinearConstraint gives).
  planning::Polytope polytope() const {
    planning::Polytope P;
    P.A.resize(static_cast<Eigen::Index>(planes_.size()), 3);
    P.b.resize(static_cast<Eigen::Index>(planes_.size()));
    for (std::size_t i = 0; i < planes_.size(); ++i) {
      P.A.row(static_cast<Eigen::Index>(i)) = planes_[i].n.transpose();
      P.b(static_cast<Eigen::Index>(i)) = planes_[i].n.dot(planes_[i].p);
    }
    return P;
  }

 private:
  /// The six planes of the oriented local box (LineSegment::add_local_bbox).
  void addLocalBox(std::vector<Hyperplane>& out) const {
    const Eigen::Vector3d dir = (p2_ - p1_).normalized();
    Eigen::Vector3d dir_h(dir.y(), -dir.x(), 0.0);
    if (dir_h.norm() == 0.0) dir_h = Eigen::Vector3d(-1.0, 0.0, 0.0);
    dir_h.normalize();
    const Eigen::Vector3d dir_v = dir.cross(dir_h);
    out.push_back(Hyperplane{p1_ + dir_h * bbox_(1), dir_h});
    out.push_back(Hyperplane{p1_ - dir_h * bbox_(1), -dir_h});
    out.push_back(Hyperplane{p2_ + dir * bbox_(0), dir});
    out.push_back(Hyperplane{p1_ - dir * bbox_(0), -dir});
    out.push_back(Hyperplane{p1_ + dir_v * bbox_(2), dir_v});
    out.push_back(Hyperplane{p1_ - dir_v * bbox_(2), -dir_v});
  }

  /// C = R diag(axes) Rᵀ.
  static Eigen::Matrix3d shape(const Eigen::Matrix3d& R, const Eigen::Vector3d& axes) {
    return R * axes.asDiagonal() * R.transpose();
  }

  /// The points of `points` still strictly inside (1 − dist > ε), in a new vector.
  std::vector<Eigen::Vector3d> stillInside(const std::vector<Eigen::Vector3d>& points) const {
    std::vector<Eigen::Vector3d> out;
    for (const Eigen::Vector3d& x : points) {
      if (1.0 - ellipsoid_.dist(x) > kEpsilon) out.push_back(x);
    }
    return out;
  }

  /// Pass 1: both cross axes against the closest point inside; returns the rolled frame.
  Eigen::Matrix3d shrinkCrossAxes(const Eigen::Matrix3d& Ri, std::vector<Eigen::Vector3d> inside) {
    Eigen::Matrix3d Rf = Ri;
    while (!inside.empty()) {
      const Eigen::Vector3d pw = ellipsoid_.closestPoint(inside);
      Eigen::Vector3d p = Ri.transpose() * (pw - ellipsoid_.d);
      const double roll = std::atan2(p(2), p(1));
      Rf = Ri * Eigen::Quaterniond(std::cos(roll / 2), std::sin(roll / 2), 0, 0).toRotationMatrix();
      p = Rf.transpose() * (pw - ellipsoid_.d);
      if (p(0) < axes_(0)) axes_(1) = std::abs(p(1)) / std::sqrt(1 - std::pow(p(0) / axes_(0), 2));
      ellipsoid_.setC(shape(Rf, Eigen::Vector3d(axes_(0), axes_(1), axes_(1))));
      const std::vector<Eigen::Vector3d> still = stillInside(inside);
      inside = still;  // a copy, as DecompUtil's `obs_inside = obs_new`
    }
    return Rf;
  }

  /// Pass 2: the third axis back to L/2, then shrunk alone against what is inside.
  void shrinkThirdAxis(const Eigen::Matrix3d& Rf, const std::vector<Eigen::Vector3d>& initially_inside) {
    ellipsoid_.setC(shape(Rf, axes_));
    std::vector<Eigen::Vector3d> inside = ellipsoid_.pointsInside(initially_inside);
    while (!inside.empty()) {
      const Eigen::Vector3d pw = ellipsoid_.closestPoint(inside);
      const Eigen::Vector3d p = Rf.transpose() * (pw - ellipsoid_.d);
      // The current DecompUtil's guard: without it, the last point of pass 1 (on the surface, in the
      // x–y plane) collapses the axis to ~0 or NaN when it is the only point counted inside.
      const double dd = 1 - std::pow(p(0) / axes_(0), 2) - std::pow(p(1) / axes_(1), 2);
      if (dd > kEpsilon) axes_(2) = std::abs(p(2)) / std::sqrt(dd);
      ellipsoid_.setC(shape(Rf, axes_));
      const std::vector<Eigen::Vector3d> still = stillInside(inside);
      inside = still;
    }
  }

  void findEllipsoid() {
    const double f = (p1_ - p2_).norm() / 2;
    axes_ = Eigen::Vector3d::Constant(f);
    const Eigen::Matrix3d Ri = rotationAlong(p2_ - p1_);
    ellipsoid_.d = (p1_ + p2_) / 2;
    ellipsoid_.setC(shape(Ri, axes_));
    const std::vector<Eigen::Vector3d> obs = ellipsoid_.pointsInside(obs_);
    const Eigen::Matrix3d Rf = shrinkCrossAxes(Ri, obs);
    axes_(2) = f;
    shrinkThirdAxis(Rf, obs);
  }

  /// DecompBase::find_polyhedron: the closest remaining point's tangent plane, repeatedly.
  void findPolyhedron() {
    planes_.clear();
    std::vector<Eigen::Vector3d> remain = obs_;
    while (!remain.empty()) {
      const Hyperplane h = ellipsoid_.closestHyperplane(remain);
      planes_.push_back(h);
      std::vector<Eigen::Vector3d> kept;
      for (const Eigen::Vector3d& x : remain) {
        if (h.signedDist(x) < 0) kept.push_back(x);
      }
      remain = kept;  // a copy, as DecompUtil's `obs_remain = obs_tmp`
    }
  }

  Eigen::Vector3d p1_, p2_, bbox_;
  Eigen::Vector3d axes_ = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> obs_;
  EllipsoidT ellipsoid_;
  std::vector<Hyperplane> planes_;
};

}  // namespace gesture_formation::bench::decomp_reference

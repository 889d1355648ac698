#include "gesture_formation/planning/corridor_builder.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::planning {

const common::FieldTable<CorridorConfig>& corridorConfigFields() {
  using C = CorridorConfig;
  using common::Range;
  static const common::FieldTable<CorridorConfig> t{{
      {"clearance_m", Range::nonNegative(), [](C& c) { return &c.clearance_m; }},
      {"seed_margin_m", Range::positive(), [](C& c) { return &c.seed_margin_m; }},
      {"min_exclusion_m", Range::positive(), [](C& c) { return &c.min_exclusion_m; }},
      {"min_segment_length_m", Range::positive(), [](C& c) { return &c.min_segment_length_m; }},
  }};
  return t;
}

std::vector<std::string> CorridorConfig::validate() const {
  std::vector<common::ConfigError> e = corridorConfigFields().rangeProblems(*this);
  for (int i = 0; i < 3; ++i) {
    common::checkRule(e, std::isfinite(local_box_margin_m(i)) && local_box_margin_m(i) > seed_margin_m,
                      "local_box_margin_m[" + std::to_string(i) + "]", local_box_margin_m(i), "must be > seed_margin_m");
  }
  return common::problemLines(e);
}

CorridorBuilder::CorridorBuilder(const CorridorConfig& config) : config_(config) {
  const auto errors = config.validate();
  if (!errors.empty()) {
    config_ = CorridorConfig{};
    for (const auto& e : errors) config_error_ += (config_error_.empty() ? "" : "; ") + e;
  }
}

namespace {

/// Added to seed_margin_m and min_exclusion_m internally so that both hold after rounding.
constexpr double kSlackM = 1e-9;

std::string str(const Eigen::Vector3d& p) {
  std::ostringstream os;
  os << "(" << p.x() << ", " << p.y() << ", " << p.z() << ")";
  return os.str();
}

/// An orthonormal basis whose first column is the unit vector u.
Eigen::Matrix3d frameAlong(const Eigen::Vector3d& u) {
  const Eigen::Vector3d helper = std::abs(u.z()) < 0.9 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX();
  const Eigen::Vector3d e1 = helper.cross(u).normalized();
  Eigen::Matrix3d R;
  R.col(0) = u;
  R.col(1) = e1;
  R.col(2) = u.cross(e1);
  return R;
}

/// The squared metric of q (segment frame) in the ellipsoid with semi-axes `a`; < 1 − 1e-9 is
/// "strictly inside" (the slack makes a point that a shrink step placed on the surface count as
/// outside). The one expression every inside test, closest-point choice and plane order uses.
double metric(const Eigen::Vector3d& q, const Eigen::Vector3d& a) { return q.cwiseQuotient(a).squaredNorm(); }
constexpr double kInside = 1.0 - 1e-9;

/// A point above this squared distance from the centre, as a multiple of the largest semi-axis
/// squared, is outside the ellipsoid whatever the rounding (1e-7 ≫ the ~1e-15 relative rounding
/// of metric()): the cheap test that spares most points the divisions.
constexpr double kSurelyOutside = 1.0 + 1e-7;

struct Plane {
  Eigen::Vector3d n;
  double b;
};

/// `in`: indices into q in increasing order (stable). Removes `drop` and every point no longer
/// strictly inside the ellipsoid with semi-axes `axes`, and returns the one of the rest closest
/// to the centre in its metric (the first of equals; `in.size()` when none is left) — the
/// closest-point search of the next shrink step done in the same pass as the filtering. The
/// divisions of metric() are paid only where they can decide: its value made with
/// multiplications is within a relative 1e-14 of it (rounding: a few 1e-16), so a point is
/// surely in or out, and surely not the closest, unless that value lies within 1e-12 of the
/// threshold or of the best exact metric so far.
std::size_t shrinkTo(std::vector<std::size_t>& in, std::size_t drop, const std::vector<Eigen::Vector3d>& q,
                     const Eigen::Vector3d& axes) {
  const Eigen::Vector3d inv_a2 = axes.cwiseProduct(axes).cwiseInverse();
  constexpr double kLow = 1.0 - 1e-12, kHigh = 1.0 + 1e-12;
  std::size_t keep = 0, best = 0;
  double best_m = std::numeric_limits<double>::infinity();
  for (const std::size_t i : in) {
    if (i == drop) continue;
    const double approx = q[i].cwiseProduct(q[i]).dot(inv_a2);
    if (approx * kLow >= kInside) continue;  // surely outside
    if (approx * kHigh >= kInside || approx * kLow <= best_m) {
      const double m = metric(q[i], axes);
      if (!(m < kInside)) continue;
      if (keep == 0 || m < best_m) best_m = m, best = keep;
    }
    in[keep++] = i;
  }
  in.resize(keep);
  return keep == 0 ? in.size() : best;
}

/// The corridor's ellipsoid (step 1): the segment frame R0 (x along the segment) turned about x
/// by `roll`, semi-axes `axes`.
struct EllipsoidFit {
  Eigen::Matrix3d R0, Rroll, R;
  Eigen::Vector3d axes;
};

/// The point in the initial segment frame R0 (x along the segment, origin at its centre): the one
/// expression of it, so that the fitted-frame coordinates (this, turned by the roll) are the same
/// bits wherever they are computed.
Eigen::Vector3d initialFrame(const Eigen::Matrix3d& R0, const Eigen::Vector3d& p, const Eigen::Vector3d& center) {
  return R0.transpose() * (p - center);
}

/// Start from the sphere whose diameter is the segment; shrink the two cross axes together
/// against the closest point inside, rotating the frame so that this point lies in the x–y
/// plane; then shrink the remaining z axis alone against what is still inside. `near`: the
/// points (world) that may lie inside that sphere — no other can be inside any ellipsoid of the
/// fit, whose semi-axes never exceed the sphere's radius. `q`, `in`: scratch (their contents are
/// replaced).
EllipsoidFit fitEllipsoid(const std::vector<Eigen::Vector3d>& near, const Eigen::Vector3d& center,
                          const Eigen::Vector3d& u, double length, std::vector<Eigen::Vector3d>& q, std::vector<std::size_t>& in) {
  EllipsoidFit fit;
  fit.R0 = frameAlong(u);
  const double a0 = 0.5 * length;
  Eigen::Vector3d axes(a0, a0, a0);
  q.clear();  // initial frame
  q.reserve(near.size());
  in.clear();
  for (const Eigen::Vector3d& p : near) {
    q.push_back(initialFrame(fit.R0, p, center));
    if (metric(q.back(), axes) < kInside) in.push_back(q.size() - 1);
  }
  double roll = 0.0;
  std::size_t best = shrinkTo(in, q.size(), q, axes);  // the closest of `in` (nothing dropped)
  while (best < in.size()) {
    const std::size_t b = in[best];
    const Eigen::Vector3d& qb = q[b];
    const double radial = std::hypot(qb.y(), qb.z());
    const double along = std::min(std::abs(qb.x()) / a0, 1.0 - 1e-12);
    axes.y() = axes.z() = radial / std::sqrt(1.0 - along * along);
    roll = std::atan2(qb.z(), qb.y());
    best = shrinkTo(in, b, q, axes);
  }
  // Rotate the frame about x by `roll`: the last closest point now lies on the new y axis side.
  fit.Rroll = Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()).toRotationMatrix();
  fit.R = fit.R0 * fit.Rroll;
  for (auto& qi : q) qi = fit.Rroll.transpose() * qi;
  axes.z() = std::max(a0, axes.y());
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (metric(q[i], axes) < kInside) in.push_back(i);
  }
  best = shrinkTo(in, q.size(), q, axes);
  while (best < in.size()) {
    const std::size_t b = in[best];
    const Eigen::Vector3d& qb = q[b];
    const double rest = 1.0 - std::pow(qb.x() / axes.x(), 2) - std::pow(qb.y() / axes.y(), 2);
    // rest > (z/a2)² ≥ 0 for a point inside; a2 ≥ a1 holds because every point is already
    // outside the symmetric ellipsoid of pass 1 (clamped against rounding).
    axes.z() = std::max(axes.y(), rest > 0.0 ? std::abs(qb.z()) / std::sqrt(rest) : axes.y());
    best = shrinkTo(in, b, q, axes);
  }
  fit.axes = axes;
  return fit;
}

/// The obstacle points of step 2 and the search for the one closest to the centre in the fitted
/// ellipsoid's metric among those left. The metric's divisions are paid only where they can
/// decide: each point keeps a lower bound of its metric, made with multiplications in one product
/// with the fitted frame and lowered by a relative margin `m` far above their rounding (≤ ~6e-15
/// × the axes' ratio), so metric ≤ bound · (1 + m) / (1 − m). The exact metric() of the point's
/// fitted-frame coordinates — the expression that defines the order — is computed for the point
/// of least bound, and then only for the points whose bound does not exceed it (noted during the
/// same pass: any point with a bound ≤ (least bound so far) · (1 + m) / (1 − m)). Same choice as taking
/// metric() of every point, the first of equals included.
class PlaneCandidates {
 public:
  struct Item {
    Eigen::Vector3d p;  // world
    double bound;       // ≤ the exact metric
  };
  /// `items`, `candidates`: scratch, cleared here (reused between segments: no allocation per call).
  PlaneCandidates(const std::vector<Eigen::Vector3d>& points, const EllipsoidFit& fit, const Eigen::Vector3d& center,
                  std::vector<Item>& items, std::vector<std::size_t>& candidates)
      : fit_(fit), center_(center), items_(items), candidates_(candidates) {
    items_.clear();
    candidates_.clear();
    const double ratio = fit.axes.maxCoeff() / fit.axes.minCoeff();
    const double margin = std::min(1e-12 + 1e-12 * ratio, 0.5);
    widen_ = (1.0 + margin) / (1.0 - margin);
    const Eigen::Vector3d inv_a2 = fit.axes.cwiseProduct(fit.axes).cwiseInverse() * (1.0 - margin);
    const Eigen::Matrix3d Rt = fit.R.transpose();
    items_.reserve(points.size());
    Least least;
    for (const Eigen::Vector3d& p : points) {
      const Eigen::Vector3d q = Rt * (p - center);
      items_.push_back(Item{p, q.cwiseProduct(q).dot(inv_a2)});
      note(items_.size() - 1, least);
    }
    first_ = select(least);
  }
  std::size_t size() const { return items_.size(); }
  const Eigen::Vector3d& point(std::size_t i) const { return items_[i].p; }

  /// The index of the closest point (the first of equals); size() when none is left.
  std::size_t closest() const { return first_; }

  /// Removes `drop` and every point p with n·p ≥ threshold (the others keep their order) and
  /// returns closest() of what is left.
  std::size_t dropBeyond(std::size_t drop, const Eigen::Vector3d& n, double threshold) {
    std::size_t keep = 0;
    Least least;
    for (std::size_t i = 0; i < items_.size(); ++i) {
      if (i == drop || !(n.dot(items_[i].p) < threshold)) continue;
      items_[keep] = items_[i];
      note(keep++, least);
    }
    items_.resize(keep);
    return select(least);
  }

 private:
  struct Least {
    std::size_t index = 0;
    double bound = std::numeric_limits<double>::infinity();
  };
  double exact(std::size_t i) const {
    return metric(fit_.Rroll.transpose() * initialFrame(fit_.R0, items_[i].p, center_), fit_.axes);
  }
  /// Item i (in its final place) during a pass: the least bound so far, and i as a candidate if
  /// it may still turn out to be the closest.
  void note(std::size_t i, Least& least) {
    const double b = items_[i].bound;
    if (b < least.bound) least.bound = b, least.index = i;
    if (b <= least.bound * widen_) candidates_.push_back(i);
  }
  /// The closest point among the pass's candidates (none: size()). The minimum exact metric is ≤
  /// exact(least), so only points bounded by that can have it.
  std::size_t select(const Least& least) {
    std::size_t best = items_.size();
    if (!candidates_.empty()) {
      const double cap = exact(least.index);
      double best_m = cap;
      best = least.index;
      for (const std::size_t i : candidates_) {
        if (i == least.index || items_[i].bound > cap) continue;
        const double m = exact(i);
        if (m < best_m || (m == best_m && i < best)) best_m = m, best = i;
      }
    }
    candidates_.clear();
    return best;
  }
  const EllipsoidFit& fit_;
  Eigen::Vector3d center_;
  double widen_ = 1.0;
  std::vector<Item>& items_;
  std::vector<std::size_t>& candidates_;
  std::size_t first_ = 0;
};

/// buildSegment's working vectors, kept per thread so that a segment allocates nothing once they
/// have grown (a corridor of a few hundred points costs a few microseconds: allocations showed).
struct Scratch {
  std::vector<Eigen::Vector3d> points, near, q;
  std::vector<std::size_t> in, candidates;
  std::vector<PlaneCandidates::Item> items;
  std::vector<Plane> planes;
};

}  // namespace

common::Result<SegmentCorridor> CorridorBuilder::buildSegment(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                                                              const ObstaclePoints& obstacles) const {
  using R = common::Result<SegmentCorridor>;
  CorridorConfig c = config_;
  c.seed_margin_m += kSlackM;
  c.min_exclusion_m += kSlackM;
  if (!p0.allFinite() || !p1.allFinite()) return R::fail("segment end is not finite");
  const double length = (p1 - p0).norm();
  if (!(length >= c.min_segment_length_m)) {
    return R::fail("segment " + str(p0) + " → " + str(p1) + " is shorter than " + std::to_string(c.min_segment_length_m) + " m");
  }

  SegmentCorridor out;
  out.seed_begin_world = p0;
  out.seed_end_world = p1;
  out.local_box = Aabb{p0.cwiseMin(p1) - c.local_box_margin_m, p0.cwiseMax(p1) + c.local_box_margin_m};
  // Points farther than clearance (+ the exclusion margin) outside the local box cannot
  // come closer than that to the polytope: the box planes keep them out.
  thread_local Scratch scratch;
  std::vector<Eigen::Vector3d>& points = scratch.points;
  points.clear();
  obstacles.pointsInBox(out.local_box.inflated(c.clearance_m + c.min_exclusion_m), points);
  out.obstacle_points = points.size();

  const Eigen::Vector3d center = 0.5 * (p0 + p1);
  const Eigen::Vector3d u = (p1 - p0) / length;
  const double needed_gap = c.min_exclusion_m + c.seed_margin_m;  // includes 2 kSlackM
  // The nearest point to the segment: squared distances, one square root (of the least; exact,
  // as the root is monotonic and correctly rounded) — and the root of any point that may lie
  // closer than needed_gap, the first of which fails the segment.
  // In the same pass, the points that may lie inside the sphere the ellipsoid starts from.
  const double fail_sq = needed_gap * needed_gap * kSurelyOutside;
  const double near_sq = 0.25 * length * length * kSurelyOutside;
  double least_sq = std::numeric_limits<double>::infinity();
  std::vector<Eigen::Vector3d>& near = scratch.near;
  near.clear();
  for (const auto& o : points) {
    const double t = std::clamp((o - p0).dot(u), 0.0, length);
    const double d_sq = (o - (p0 + t * u)).squaredNorm();
    least_sq = std::min(least_sq, d_sq);
    if ((o - center).squaredNorm() <= near_sq) near.push_back(o);
    if (d_sq < fail_sq && std::sqrt(d_sq) < needed_gap) {
      return R::fail("obstacle point " + str(o) + " lies " + std::to_string(std::sqrt(d_sq)) + " m from the segment " + str(p0) +
                     " → " + str(p1) + " (a corridor needs > " + std::to_string(needed_gap) + " m)");
    }
  }
  out.segment_clearance_m = std::sqrt(least_sq);

  // (1) Ellipsoid, in the segment frame (x along the segment).
  const EllipsoidFit fit = fitEllipsoid(near, center, u, length, scratch.q, scratch.in);
  const Eigen::Matrix3d& Rw = fit.R;
  const Eigen::Vector3d& axes = fit.axes;
  out.ellipsoid.R_world_ellipsoid = Rw;
  out.ellipsoid.axes_m = axes;
  out.ellipsoid.center_world = center;

  // (2) Planes, closest point first in the ellipsoid's metric.
  const Eigen::Vector3d inv_a2 = axes.cwiseProduct(axes).cwiseInverse();
  PlaneCandidates remaining(points, fit, center, scratch.items, scratch.candidates);
  std::vector<Plane>& planes = scratch.planes;
  planes.clear();
  // A plane never passes through its point: it moves at least min_exclusion_m.
  const double clearance = std::max(c.clearance_m, c.min_exclusion_m);
  double achieved = clearance;
  for (std::size_t best = remaining.closest(); best < remaining.size(); ) {
    const Eigen::Vector3d o = remaining.point(best);
    // Tangent plane of the ellipsoid's level set through o.
    Eigen::Vector3d n = Rw * inv_a2.cwiseProduct(Rw.transpose() * (o - center));
    double gap = -1.0;
    if (n.norm() > 0.0) {
      n.normalize();
      gap = n.dot(o) - std::max(n.dot(p0), n.dot(p1));
    }
    // Supporting plane of the segment at o's nearest point: gap = distance to the segment,
    // the largest any plane can have. Used when the tangent plane cannot move as far.
    const double t = std::clamp((o - p0).dot(u), 0.0, length);
    const Eigen::Vector3d foot = p0 + t * u;
    const double support_gap = (o - foot).norm();
    const double want = std::min(clearance, support_gap - c.seed_margin_m);
    if (!(gap - c.seed_margin_m >= want)) {
      n = (o - foot) / support_gap;
      gap = support_gap;
    }
    const double shift = std::min(clearance, gap - c.seed_margin_m);  // ≥ min_exclusion_m (checked above)
    achieved = std::min(achieved, shift);
    const double threshold = n.dot(o);
    planes.push_back(Plane{n, threshold - shift});
    // Drop o and every point at least as far along n: it is ≥ shift outside the new plane.
    best = remaining.dropBeyond(best, n, threshold);
  }

  // (3) The local box: x_i ≤ max_i and −x_i ≤ −min_i for every axis.
  const int rows = static_cast<int>(planes.size()) + 6;
  out.polytope.A.resize(rows, 3);
  out.polytope.b.resize(rows);
  for (int r = 0; r < static_cast<int>(planes.size()); ++r) {
    out.polytope.A.row(r) = planes[static_cast<std::size_t>(r)].n.transpose();
    out.polytope.b(r) = planes[static_cast<std::size_t>(r)].b;
  }
  for (int i = 0; i < 3; ++i) {
    const int r = static_cast<int>(planes.size()) + 2 * i;
    out.polytope.A.row(r) = Eigen::RowVector3d::Unit(i);
    out.polytope.b(r) = out.local_box.max_world(i);
    out.polytope.A.row(r + 1) = -Eigen::RowVector3d::Unit(i);
    out.polytope.b(r + 1) = -out.local_box.min_world(i);
  }
  out.clearance_m = std::min(achieved, c.clearance_m);
  return R::ok(std::move(out));
}

common::Result<std::vector<SegmentCorridor>> CorridorBuilder::buildPath(const std::vector<Eigen::Vector3d>& path,
                                                                        const ObstaclePoints& obstacles) const {
  using R = common::Result<std::vector<SegmentCorridor>>;
  if (path.size() < 2) return R::fail("a path needs at least 2 waypoints, got " + std::to_string(path.size()));
  std::vector<SegmentCorridor> out;
  out.reserve(path.size() - 1);
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    auto seg = buildSegment(path[i], path[i + 1], obstacles);
    if (!seg) {
      return R::fail("segment " + std::to_string(i) + " (waypoints " + std::to_string(i) + " → " + std::to_string(i + 1) +
                     "): " + seg.reason());
    }
    out.push_back(std::move(seg.value()));
  }
  return R::ok(std::move(out));
}

}  // namespace gesture_formation::planning

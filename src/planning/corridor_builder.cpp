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

/// Points (segment frame) strictly inside the ellipsoid with semi-axes `a` (1e-9 slack so
/// that points placed on the surface by a shrink step count as outside).
bool inside(const Eigen::Vector3d& q, const Eigen::Vector3d& a) { return q.cwiseQuotient(a).squaredNorm() < 1.0 - 1e-9; }

struct Plane {
  Eigen::Vector3d n;
  double b;
};

/// The point of `in` closest to the ellipsoid's centre in its metric (`in` not empty).
std::size_t closestInside(const std::vector<std::size_t>& in, const std::vector<Eigen::Vector3d>& q,
                          const Eigen::Vector3d& axes) {
  std::size_t best = in.front();
  double best_m = q[best].cwiseQuotient(axes).squaredNorm();
  for (const std::size_t i : in) {
    const double m = q[i].cwiseQuotient(axes).squaredNorm();
    if (m < best_m) best_m = m, best = i;
  }
  return best;
}

/// Keeps in `in` the points other than `best` still inside the ellipsoid with semi-axes `axes`.
void keepInside(std::vector<std::size_t>& in, std::size_t best, const std::vector<Eigen::Vector3d>& q,
                const Eigen::Vector3d& axes) {
  std::vector<std::size_t> still;
  for (const std::size_t i : in) {
    if (i != best && inside(q[i], axes)) still.push_back(i);
  }
  in.swap(still);
}

/// The corridor's ellipsoid (step 1), in the segment frame R (x along the segment) with
/// semi-axes `axes`; q: the points in that frame.
struct EllipsoidFit {
  Eigen::Matrix3d R;
  Eigen::Vector3d axes;
  std::vector<Eigen::Vector3d> q;
};

/// Start from the sphere whose diameter is the segment; shrink the two cross axes together
/// against the closest point inside, rotating the frame so that this point lies in the x–y
/// plane; then shrink the remaining z axis alone against what is still inside.
EllipsoidFit fitEllipsoid(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& center,
                          const Eigen::Vector3d& u, double length) {
  Eigen::Matrix3d Rw = frameAlong(u);
  const double a0 = 0.5 * length;
  Eigen::Vector3d axes(a0, a0, a0);
  std::vector<Eigen::Vector3d> q(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) q[i] = Rw.transpose() * (points[i] - center);
  std::vector<std::size_t> in;
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (inside(q[i], axes)) in.push_back(i);
  }
  double roll = 0.0;
  while (!in.empty()) {
    const std::size_t best = closestInside(in, q, axes);
    const Eigen::Vector3d& qb = q[best];
    const double radial = std::hypot(qb.y(), qb.z());
    const double along = std::min(std::abs(qb.x()) / a0, 1.0 - 1e-12);
    axes.y() = axes.z() = radial / std::sqrt(1.0 - along * along);
    roll = std::atan2(qb.z(), qb.y());
    keepInside(in, best, q, axes);
  }
  // Rotate the frame about x by `roll`: the last closest point now lies on the new y axis side.
  const Eigen::Matrix3d Rroll = Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()).toRotationMatrix();
  Rw = Rw * Rroll;
  for (auto& qi : q) qi = Rroll.transpose() * qi;
  axes.z() = std::max(a0, axes.y());
  for (std::size_t i = 0; i < q.size(); ++i) {
    if (inside(q[i], axes)) in.push_back(i);
  }
  while (!in.empty()) {
    const std::size_t best = closestInside(in, q, axes);
    const Eigen::Vector3d& qb = q[best];
    const double rest = 1.0 - std::pow(qb.x() / axes.x(), 2) - std::pow(qb.y() / axes.y(), 2);
    // rest > (z/a2)² ≥ 0 for a point inside; a2 ≥ a1 holds because every point is already
    // outside the symmetric ellipsoid of pass 1 (clamped against rounding).
    axes.z() = std::max(axes.y(), rest > 0.0 ? std::abs(qb.z()) / std::sqrt(rest) : axes.y());
    keepInside(in, best, q, axes);
  }
  return EllipsoidFit{Rw, axes, std::move(q)};
}

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
  std::vector<Eigen::Vector3d> points;
  obstacles.pointsInBox(out.local_box.inflated(c.clearance_m + c.min_exclusion_m), points);
  out.obstacle_points = points.size();

  const Eigen::Vector3d center = 0.5 * (p0 + p1);
  const Eigen::Vector3d u = (p1 - p0) / length;
  const double needed_gap = c.min_exclusion_m + c.seed_margin_m;  // includes 2 kSlackM
  out.segment_clearance_m = std::numeric_limits<double>::infinity();
  for (const auto& o : points) {
    const double t = std::clamp((o - p0).dot(u), 0.0, length);
    const double d = (o - (p0 + t * u)).norm();
    out.segment_clearance_m = std::min(out.segment_clearance_m, d);
    if (d < needed_gap) {
      return R::fail("obstacle point " + str(o) + " lies " + std::to_string(d) + " m from the segment " + str(p0) + " → " +
                     str(p1) + " (a corridor needs > " + std::to_string(needed_gap) + " m)");
    }
  }

  // (1) Ellipsoid, in the segment frame (x along the segment).
  const EllipsoidFit fit = fitEllipsoid(points, center, u, length);
  const Eigen::Matrix3d& Rw = fit.R;
  const Eigen::Vector3d& axes = fit.axes;
  const std::vector<Eigen::Vector3d>& q = fit.q;
  out.ellipsoid.R_world_ellipsoid = Rw;
  out.ellipsoid.axes_m = axes;
  out.ellipsoid.center_world = center;

  // (2) Planes, closest point first in the ellipsoid's metric.
  const Eigen::Vector3d inv_a2 = axes.cwiseProduct(axes).cwiseInverse();
  struct Candidate {
    Eigen::Vector3d p;
    double metric;
  };
  std::vector<Candidate> remaining(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) remaining[i] = Candidate{points[i], q[i].cwiseQuotient(axes).squaredNorm()};
  std::vector<Plane> planes;
  // A plane never passes through its point: it moves at least min_exclusion_m.
  const double clearance = std::max(c.clearance_m, c.min_exclusion_m);
  double achieved = clearance;
  while (!remaining.empty()) {
    std::size_t best = 0;
    for (std::size_t i = 1; i < remaining.size(); ++i) {
      if (remaining[i].metric < remaining[best].metric) best = i;
    }
    const Eigen::Vector3d o = remaining[best].p;
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
    // Drop every point at least as far along n as o: it is ≥ shift outside the new plane.
    std::size_t keep = 0;
    for (std::size_t i = 0; i < remaining.size(); ++i) {
      if (i != best && n.dot(remaining[i].p) < threshold) remaining[keep++] = remaining[i];
    }
    remaining.resize(keep);
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

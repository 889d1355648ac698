#include "gesture_formation/planning/catenary.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace gesture_formation::planning {

namespace {

/// z(u) − h1 for the catenary through (0, h1) with parameter a and vertex u0, written with
/// cosh A − cosh B = 2 sinh((A+B)/2) sinh((A−B)/2) to avoid cancellation for large a.
double riseFromStart(double a, double u0, double u) {
  const double A = (u - u0) / a;
  const double B = -u0 / a;
  return a * 2.0 * std::sinh(0.5 * (A + B)) * std::sinh(0.5 * (A - B));
}

double vertexFor(double a, double span, double dh) {
  return 0.5 * span - a * std::asinh(dh / (2.0 * a * std::sinh(span / (2.0 * a))));
}

}  // namespace

common::Result<Catenary> Catenary::fit(const Eigen::Vector3d& from_world, const Eigen::Vector3d& to_world, double sag_m) {
  using R = common::Result<Catenary>;
  const Eigen::Vector2d d_xy = (to_world - from_world).head<2>();
  const double span = d_xy.norm();
  if (!(span >= 1e-3)) return R::fail("the attachment points are vertically aligned (horizontal span < 1 mm)");
  if (!(std::isfinite(sag_m) && sag_m > 0.0)) return R::fail("sag must be > 0, got " + std::to_string(sag_m));
  Catenary c;
  c.from_world_ = from_world;
  c.dir_xy_ = d_xy / span;
  c.span_m_ = span;
  c.h1_ = from_world.z();
  c.h2_ = to_world.z();
  const double dh = c.h2_ - c.h1_;
  auto sagFor = [&](double a) {
    const double u0 = vertexFor(a, span, dh);
    return 0.5 * dh - riseFromStart(a, u0, 0.5 * span);  // chord mid height − curve mid height
  };
  // sag(a) decreases monotonically from +inf (a → 0) to 0 (a → inf): bisect in log a.
  double lo = span / 100.0, hi = span * 1e7;
  if (!(sagFor(lo) > sag_m)) return R::fail("sag " + std::to_string(sag_m) + " m is too large for the span");
  if (!(sagFor(hi) < sag_m)) return R::fail("sag " + std::to_string(sag_m) + " m is too small to represent");
  for (int i = 0; i < 200; ++i) {
    const double mid = std::sqrt(lo * hi);
    (sagFor(mid) > sag_m ? lo : hi) = mid;
  }
  c.a_ = std::sqrt(lo * hi);
  c.u0_ = vertexFor(c.a_, span, dh);
  return R::ok(c);
}

double Catenary::zAt(double u) const { return h1_ + riseFromStart(a_, u0_, u); }

Eigen::Vector3d Catenary::point(double s) const {
  const double u = s * span_m_;
  Eigen::Vector3d p;
  p.head<2>() = from_world_.head<2>() + u * dir_xy_;
  p.z() = zAt(u);
  return p;
}

double Catenary::lowestZ() const {
  const double u = std::clamp(u0_, 0.0, span_m_);
  return std::min({zAt(u), h1_, h2_});
}

double Catenary::length() const {
  // Arc length of a cosh curve: a (sinh((u1−u0)/a) − sinh((0−u0)/a)).
  return a_ * (std::sinh((span_m_ - u0_) / a_) - std::sinh(-u0_ / a_));
}

common::Result<PrimitiveSet> conductorPrimitives(const ConductorSpec& spec) {
  using R = common::Result<PrimitiveSet>;
  if (!(spec.radius_m > 0.0)) return R::fail("radius_m must be > 0");
  if (!(spec.max_piece_length_m > 0.0)) return R::fail("max_piece_length_m must be > 0");
  const auto cat = Catenary::fit(spec.from_world, spec.to_world, spec.sag_m);
  if (!cat) return R::fail(cat.reason());
  const int pieces = std::max(1, static_cast<int>(std::ceil(cat->length() / spec.max_piece_length_m)));
  PrimitiveSet set;
  set.cylinders.reserve(static_cast<std::size_t>(pieces));
  Eigen::Vector3d prev = cat->point(0.0);
  for (int i = 1; i <= pieces; ++i) {
    const Eigen::Vector3d next = cat->point(static_cast<double>(i) / pieces);
    set.cylinders.push_back(Cylinder{prev, next, spec.radius_m});
    prev = next;
  }
  return R::ok(set);
}

}  // namespace gesture_formation::planning

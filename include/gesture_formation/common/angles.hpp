#pragma once
/// \file
/// \brief Angle helpers. Convention (docs/conventions.md): angles in radians unless the
/// name ends in `_deg`; headings wrapped to (−π, π].

#include <cmath>

namespace gesture_formation::common {

constexpr double kPi = 3.14159265358979323846;

constexpr double degToRad(double deg) { return deg * kPi / 180.0; }
constexpr double radToDeg(double rad) { return rad * 180.0 / kPi; }

/// \brief Wraps an angle to (−π, π]. Non-finite input is returned unchanged.
inline double wrapAngle(double a) {
  if (!std::isfinite(a)) return a;
  double w = std::remainder(a, 2.0 * kPi);  // in [−π, π]
  if (w <= -kPi) w += 2.0 * kPi;
  return w;
}

}  // namespace gesture_formation::common

#pragma once
/// \file
/// \brief A conductor line hanging between two attachment points: the catenary
/// z(u) = c + a cosh((u − u0)/a) in the vertical plane through both points (u: horizontal
/// distance from `from_world`, metres), fixed by its sag, and sampled into thin cylinders
/// for the rasteriser.
/// Thread safety: value type.

#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/planning/shapes.hpp"

namespace gesture_formation::planning {

/// \brief One conductor line (world frame, metres).
struct ConductorSpec {
  Eigen::Vector3d from_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d to_world = Eigen::Vector3d::UnitX();
  /// Vertical distance at mid-span between the straight chord and the line, > 0.
  double sag_m = 1.0;
  /// Conductor radius, > 0 (real conductors: 0.01–0.02 m).
  double radius_m = 0.015;
  /// Longest cylinder piece the line is sampled into, > 0. At 1 m the polyline deviates
  /// from the catenary by l²/(8a) ≈ 1 mm for a typical a ≈ 100 m.
  double max_piece_length_m = 1.0;
};

/// \brief The catenary through two points with a given mid-span sag.
class Catenary {
 public:
  /// \brief Fits the curve. Fails when the points are (nearly) vertically aligned
  /// (horizontal span < 1 mm), the sag is not > 0, or it is absurd (no finite solution).
  static common::Result<Catenary> fit(const Eigen::Vector3d& from_world, const Eigen::Vector3d& to_world, double sag_m);

  /// \brief The point at horizontal fraction s ∈ [0, 1] of the span (world frame, m).
  Eigen::Vector3d point(double s) const;
  /// \brief The catenary parameter a = H/w (m): horizontal tension over weight per length.
  double parameter() const { return a_; }
  /// \brief The lowest height (m) of the curve between its ends.
  double lowestZ() const;
  /// \brief Arc length (m).
  double length() const;

 private:
  Catenary() = default;
  double zAt(double u) const;

  Eigen::Vector3d from_world_ = Eigen::Vector3d::Zero();
  Eigen::Vector2d dir_xy_ = Eigen::Vector2d::UnitX();  ///< horizontal unit direction from → to
  double span_m_ = 1.0;                                 ///< horizontal distance
  double h1_ = 0.0, h2_ = 0.0;                          ///< end heights
  double a_ = 1.0, u0_ = 0.0;                           ///< parameter, vertex position
};

/// \brief The conductor as a chain of cylinders (radius `radius_m`, pieces of at most
/// `max_piece_length_m`). Fails for the reasons of Catenary::fit.
common::Result<PrimitiveSet> conductorPrimitives(const ConductorSpec& spec);

}  // namespace gesture_formation::planning

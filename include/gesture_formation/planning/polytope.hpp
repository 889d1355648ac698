#pragma once
/// \file
/// \brief Convex polytope `A x ≤ b` (world frame, metres): each row of A is an outward unit
/// normal, b the plane's offset (docs/planning.md §3). Ready for a QP as linear constraints.
/// Thread safety: value type.

#include <algorithm>
#include <limits>

#include <Eigen/Core>

namespace gesture_formation::planning {

struct Polytope {
  Eigen::MatrixX3d A;  ///< rows: outward unit normals
  Eigen::VectorXd b;   ///< offsets, m

  int rows() const { return static_cast<int>(b.size()); }
  /// \brief max_i (A_i x − b_i) (m): ≤ 0 inside, > 0 outside (distance past the most
  /// violated plane). −inf for a polytope without planes (all of R³).
  double violation(const Eigen::Vector3d& x_world) const {
    if (b.size() == 0) return -std::numeric_limits<double>::infinity();
    return (A * x_world - b).maxCoeff();
  }
  /// \brief True when A x ≤ b + tolerance.
  bool contains(const Eigen::Vector3d& x_world, double tolerance_m = 0.0) const {
    return violation(x_world) <= tolerance_m;
  }
};

/// \brief Ellipsoid {x : ‖diag(1/axes) Rᵀ (x − c)‖ ≤ 1}; R's columns are its axes in the
/// world frame, the first along the segment it was grown from.
struct Ellipsoid {
  Eigen::Matrix3d R_world_ellipsoid = Eigen::Matrix3d::Identity();
  Eigen::Vector3d axes_m = Eigen::Vector3d::Ones();  ///< semi-axes
  Eigen::Vector3d center_world = Eigen::Vector3d::Zero();

  /// \brief ‖diag(1/axes) Rᵀ (x − c)‖: < 1 inside, 1 on the surface.
  double metric(const Eigen::Vector3d& x_world) const {
    return (R_world_ellipsoid.transpose() * (x_world - center_world)).cwiseQuotient(axes_m).norm();
  }
};

}  // namespace gesture_formation::planning

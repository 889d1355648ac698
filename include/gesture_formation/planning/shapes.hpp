#pragma once
/// \file
/// \brief Solid primitives of the world model (world frame, metres): oriented boxes, finite
/// cylinders with an arbitrary axis, and the ground half-space. Each answers the Euclidean
/// distance from a point to the solid (0 inside), its axis-aligned bounding box and its
/// volume, which is all the rasteriser (occupancy_map.hpp) needs.
/// Thread safety: value types, no shared state.

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace gesture_formation::planning {

/// \brief Axis-aligned box [min, max] in the world frame, metres.
struct Aabb {
  Eigen::Vector3d min_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d max_world = Eigen::Vector3d::Zero();

  /// \brief The box grown by `margin_m` on every side.
  Aabb inflated(double margin_m) const {
    return Aabb{min_world - Eigen::Vector3d::Constant(margin_m), max_world + Eigen::Vector3d::Constant(margin_m)};
  }
  /// \brief True when p lies in the closed box.
  bool contains(const Eigen::Vector3d& p_world) const {
    return (p_world.array() >= min_world.array()).all() && (p_world.array() <= max_world.array()).all();
  }
};

/// \brief A solid box: centre, full edge lengths along its own axes, and orientation
/// `R_world_box` (columns: the box axes in the world frame).
struct OrientedBox {
  Eigen::Vector3d center_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d size_m = Eigen::Vector3d::Ones();  ///< full edge lengths, each > 0
  Eigen::Matrix3d R_world_box = Eigen::Matrix3d::Identity();

  /// \brief Distance (m) from p to the box; 0 when p is inside or on it.
  double distance(const Eigen::Vector3d& p_world) const;
  Aabb bounds() const;
  double volume() const { return size_m.prod(); }
};

/// \brief A solid finite cylinder between the centres of its two end discs (any axis).
struct Cylinder {
  Eigen::Vector3d p0_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d p1_world = Eigen::Vector3d::UnitZ();
  double radius_m = 0.1;  ///< > 0

  /// \brief Distance (m) from p to the solid cylinder (flat end caps); 0 inside.
  double distance(const Eigen::Vector3d& p_world) const;
  Aabb bounds() const;
  double volume() const;
};

/// \brief The primitives of one scene after expanding towers and conductors.
struct PrimitiveSet {
  std::vector<OrientedBox> boxes;
  std::vector<Cylinder> cylinders;

  void append(const PrimitiveSet& other) {
    boxes.insert(boxes.end(), other.boxes.begin(), other.boxes.end());
    cylinders.insert(cylinders.end(), other.cylinders.begin(), other.cylinders.end());
  }
  /// \brief Distance (m) from p to the nearest primitive (brute force; tests and tools).
  double distance(const Eigen::Vector3d& p_world) const;
};

// ---- segments and polylines (the planner's envelopes and keep-outs) ----

/// \brief The point of segment [a, b] nearest to x (a when a == b).
Eigen::Vector3d closestPointOnSegment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& x);

/// \brief Distance between the segments [a, b] and [c, d] (exact; either may be a point).
double segmentSegmentDistance(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                              const Eigen::Vector3d& d);

/// \brief Distance (m) from x to a polyline (a single point: to that point; +inf when empty).
double distanceToPolyline(const std::vector<Eigen::Vector3d>& polyline, const Eigen::Vector3d& x);

/// \brief Distance (m) from the segment [a, b] to a polyline (a single point: to that point;
/// +inf when empty).
double distanceToPolyline(const std::vector<Eigen::Vector3d>& polyline, const Eigen::Vector3d& a, const Eigen::Vector3d& b);

/// \brief Greedy simplification: every dropped point lies within `tolerance` of the segment that
/// replaces it, so the simplified polyline is within `tolerance` of every original point (fewer
/// than three points: unchanged; a point repeated n times: that point twice).
std::vector<Eigen::Vector3d> simplifyPolyline(const std::vector<Eigen::Vector3d>& points, double tolerance);

/// \brief Rotation from roll, pitch, yaw in radians (R = Rz(yaw) Ry(pitch) Rx(roll)).
Eigen::Matrix3d rotationFromRpy(double roll_rad, double pitch_rad, double yaw_rad);

}  // namespace gesture_formation::planning

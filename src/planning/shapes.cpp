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

}  // namespace gesture_formation::planning

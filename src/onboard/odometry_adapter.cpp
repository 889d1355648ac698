#include "gesture_formation/onboard/odometry_adapter.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace gesture_formation::onboard {

namespace {

/// The unit quaternion, or the reason `q` is none (named `field`).
common::Result<Eigen::Quaterniond> unitQuaternion(const Eigen::Quaterniond& q, const std::string& field) {
  using R = common::Result<Eigen::Quaterniond>;
  const double n = q.norm();
  if (!q.coeffs().allFinite() || n < 0.5 || n > 1.5) {
    std::ostringstream os;
    os << field << ": (w " << q.w() << ", x " << q.x() << ", y " << q.y() << ", z " << q.z()
       << ") is not a rotation (norm " << n << ")";
    return R::fail(os.str());
  }
  return R::ok(q.normalized());
}

std::string vectorText(const Eigen::Vector3d& v) {
  std::ostringstream os;
  os << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return os.str();
}

}  // namespace

CameraMount CameraMount::fromRpy(double roll_rad, double pitch_rad, double yaw_rad) {
  CameraMount m;
  m.q_body_camera = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
                    Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX());
  m.optical_axis = OpticalAxis::kX;
  return m;
}

common::Result<planning::UavKinematicState> toPlannerState(const FlightStackOdometry& odom, const CameraMount& mount) {
  using R = common::Result<planning::UavKinematicState>;
  if (!std::isfinite(odom.t_s)) return R::fail("header.stamp: not finite");
  if (!odom.p_world.allFinite()) return R::fail("pose.position " + vectorText(odom.p_world) + ": not finite");
  if (!odom.v.allFinite()) return R::fail("twist.linear " + vectorText(odom.v) + ": not finite");
  const auto q_world_body = unitQuaternion(odom.q_world_body, "pose.orientation");
  if (!q_world_body) return R::fail(q_world_body.reason());
  const auto q_body_camera = unitQuaternion(mount.q_body_camera, "camera mount rotation");
  if (!q_body_camera) return R::fail(q_body_camera.reason());

  const Eigen::Vector3d axis_camera =
      mount.optical_axis == OpticalAxis::kX ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d axis_world = (*q_world_body) * ((*q_body_camera) * axis_camera);
  if (axis_world.head<2>().norm() < 1e-6) {
    return R::fail("camera axis " + vectorText(axis_world) + " is vertical: its heading is undefined");
  }
  planning::UavKinematicState s;
  s.t_s = odom.t_s;
  s.p_world = odom.p_world;
  s.v_world = odom.twist_in_body ? Eigen::Vector3d((*q_world_body) * odom.v) : odom.v;
  s.heading_rad = std::atan2(axis_world.y(), axis_world.x());
  s.pitch_rad = std::asin(std::clamp(axis_world.z(), -1.0, 1.0));
  return R::ok(s);
}

planning::UavKinematicState carriedTo(const planning::UavKinematicState& odom, double stamp_s, double t_s) {
  planning::UavKinematicState s = odom;
  const double age = t_s - stamp_s;
  if (age > 0.0 && std::isfinite(age)) s.p_world += age * odom.v_world;
  s.t_s = t_s;
  return s;
}

}  // namespace gesture_formation::onboard

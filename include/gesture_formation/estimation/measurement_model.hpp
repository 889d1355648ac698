#pragma once
/// \file
/// \brief The worker's 3-D position measurement from a bounding box and a distance
/// (paper: "Human 3D position estimation"; docs/design.md §3):
///
///   z = R_C (d · d̂) + p_C,   Σ = R_C diag(σ_xy², σ_xy², σ_z²) R_Cᵀ,
///
/// d̂ the unit ray through the undistorted box centre in the camera optical frame,
/// (R_C, p_C) the optical frame's pose in the world, and (d, σ_z) chosen by availability:
/// UWB > stereo > apparent size, d_apparent = H / (2 tan(α/2)) with α the angle between the
/// rays through the box's top-centre and bottom-centre.

#include <cmath>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/estimation/camera_model.hpp"

namespace gesture_formation::estimation {

/// \brief Axis-aligned box in the distorted image: top-left (u, v) and size (w, h) [px].
struct Box {
  double u = 0.0;
  double v = 0.0;
  double w = 0.0;
  double h = 0.0;

  Eigen::Vector2d centre() const { return Eigen::Vector2d(u + 0.5 * w, v + 0.5 * h); }
  Eigen::Vector2d topCentre() const { return Eigen::Vector2d(u + 0.5 * w, v); }
  Eigen::Vector2d bottomCentre() const { return Eigen::Vector2d(u + 0.5 * w, v + h); }
};

/// \brief Where a measurement's distance came from, in order of preference.
enum class DistanceSource { kNone = 0, kUwb, kStereo, kApparent };

inline const char* toString(DistanceSource s) {
  switch (s) {
    case DistanceSource::kUwb: return "uwb";
    case DistanceSource::kStereo: return "stereo";
    case DistanceSource::kApparent: return "apparent";
    case DistanceSource::kNone: break;
  }
  return "none";
}

/// \brief Measurement noise standard deviations (paper Table II). All > 0.
struct MeasurementNoise {
  double sigma_xy_m = 0.05;          ///< optical-frame x and y (box-centre uncertainty) [m]
  double sigma_z_uwb_m = 0.1;        ///< optical-frame z (optical axis), UWB distance [m]
  double sigma_z_stereo_m = 0.3;     ///< optical-frame z, stereo distance [m]
  double sigma_z_apparent_m = 0.6;   ///< optical-frame z, apparent-size distance [m]

  double sigmaAlongRay(DistanceSource s) const {
    switch (s) {
      case DistanceSource::kUwb: return sigma_z_uwb_m;
      case DistanceSource::kStereo: return sigma_z_stereo_m;
      case DistanceSource::kApparent: return sigma_z_apparent_m;
      case DistanceSource::kNone: break;
    }
    return std::nan("");
  }
};

/// \brief Pose of the camera optical frame in the world: p_world = R · p_camera + t.
/// The quaternion is (w, x, y, z); Eigen stores it as such.
struct CameraPose {
  Eigen::Vector3d t_world_camera = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q_world_camera = Eigen::Quaterniond::Identity();
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// Quaternions whose norm differs from 1 by more than this are rejected; within it they
/// are normalised (CSV logs round to ~1e-6).
constexpr double kQuaternionNormTolerance = 1e-3;

/// \brief One fused-ready measurement of the worker's position in the world.
struct PositionMeasurement {
  Eigen::Vector3d z_world = Eigen::Vector3d::Zero();
  Eigen::Matrix3d sigma_world = Eigen::Matrix3d::Identity();  ///< covariance Σ [m²]
  DistanceSource source = DistanceSource::kNone;
  double distance_m = 0.0;
  Eigen::Vector3d ray_camera = Eigen::Vector3d::UnitZ();  ///< d̂ in the optical frame
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief Checks a box against the image: finite, positive size, centre inside the image.
/// (A box may extend past the border — people at the edge — but its centre may not.)
inline common::Result<Box> validateBox(const Box& box, const CameraIntrinsics& k) {
  using R = common::Result<Box>;
  if (!std::isfinite(box.u) || !std::isfinite(box.v) || !std::isfinite(box.w) || !std::isfinite(box.h)) {
    return R::fail("box has a non-finite coordinate");
  }
  if (box.w <= 0.0 || box.h <= 0.0) {
    return R::fail("box size must be positive, got w=" + std::to_string(box.w) + " h=" + std::to_string(box.h));
  }
  const Eigen::Vector2d c = box.centre();
  if (c.x() < 0.0 || c.y() < 0.0 || c.x() > k.width_px || c.y() > k.height_px) {
    return R::fail("box centre (" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ") is outside the " +
                   std::to_string(k.width_px) + "x" + std::to_string(k.height_px) + " image");
  }
  return R::ok(box);
}

/// \brief Checks and normalises a camera pose (finite, unit quaternion within tolerance).
inline common::Result<CameraPose> validatePose(const CameraPose& pose) {
  using R = common::Result<CameraPose>;
  if (!pose.t_world_camera.allFinite() || !pose.q_world_camera.coeffs().allFinite()) {
    return R::fail("camera pose has a non-finite value");
  }
  const double n = pose.q_world_camera.norm();
  if (std::abs(n - 1.0) > kQuaternionNormTolerance) {
    return R::fail("camera quaternion is not unit (norm " + std::to_string(n) + ")");
  }
  CameraPose out = pose;
  out.q_world_camera.normalize();
  return R::ok(out);
}

/// \brief Apparent distance d = H / (2 tan(α/2)) of a person of height `height_m` whose
/// box spans the angle α between the rays through its top-centre and bottom-centre.
inline common::Result<double> apparentDistance(const CameraModel& camera, const Box& box, double height_m) {
  using R = common::Result<double>;
  const auto top = camera.rayThroughPixel(box.topCentre());
  const auto bottom = camera.rayThroughPixel(box.bottomCentre());
  if (!top || !bottom) return R::fail("cannot undistort the box's top or bottom centre");
  // atan2 of |a×b| and a·b is accurate for small angles, unlike acos.
  const double alpha = std::atan2(top->cross(*bottom).norm(), top->dot(*bottom));
  if (!(alpha > 0.0) || !std::isfinite(alpha)) return R::fail("box spans no angle");
  return R::ok(height_m / (2.0 * std::tan(0.5 * alpha)));
}

/// \brief A distance is available when finite and > 0 (NaN encodes "no reading").
inline bool distanceAvailable(double d_m) { return std::isfinite(d_m) && d_m > 0.0; }

/// \brief Builds the measurement of design.md §3 from a detection. `d_uwb_m`, `d_stereo_m`: NaN
/// when unavailable. Fails (with a reason) for a bad box, pose or geometry, and for an apparent
/// distance over `max_apparent_distance_m`; never returns non-finite values.
inline common::Result<PositionMeasurement> makeMeasurement(const CameraModel& camera, const CameraPose& pose,
                                                           const Box& box, double d_uwb_m, double d_stereo_m,
                                                           double human_height_m, const MeasurementNoise& noise,
                                                           double max_apparent_distance_m) {
  using R = common::Result<PositionMeasurement>;
  const auto box_ok = validateBox(box, camera.intrinsics());
  if (!box_ok) return R::fail(box_ok.reason());
  const auto pose_ok = validatePose(pose);
  if (!pose_ok) return R::fail(pose_ok.reason());
  const auto ray = camera.rayThroughPixel(box.centre());
  if (!ray) return R::fail("cannot undistort the box centre");

  PositionMeasurement m;
  m.ray_camera = *ray;
  if (distanceAvailable(d_uwb_m)) {
    m.source = DistanceSource::kUwb;
    m.distance_m = d_uwb_m;
  } else if (distanceAvailable(d_stereo_m)) {
    m.source = DistanceSource::kStereo;
    m.distance_m = d_stereo_m;
  } else {
    // A box at the image's top or bottom edge is clipped (the detectors cut boxes to the image):
    // its height is not the person's, and the distance from it would be too long — refused.
    const double edge_px = 0.5, height_px = camera.intrinsics().height_px;
    if (box.v <= edge_px || box.v + box.h >= height_px - edge_px) {
      return R::fail("box touches the image's top or bottom edge (v " + std::to_string(box.v) + ", h " +
                     std::to_string(box.h) + " of " + std::to_string(height_px) +
                     " px): clipped, its height gives no distance, and no UWB or stereo range");
    }
    const auto d = apparentDistance(camera, box, human_height_m);
    if (!d) return R::fail(d.reason());
    if (!(*d <= max_apparent_distance_m)) {
      return R::fail("box of " + std::to_string(box.h) + " px gives an apparent distance of " + std::to_string(*d) +
                     " m, over max_apparent_distance_m (" + std::to_string(max_apparent_distance_m) +
                     " m), and no UWB or stereo range");
    }
    m.source = DistanceSource::kApparent;
    m.distance_m = *d;
  }
  const Eigen::Matrix3d R_wc = pose_ok->q_world_camera.toRotationMatrix();
  m.z_world = R_wc * (m.distance_m * m.ray_camera) + pose_ok->t_world_camera;
  const double sxy2 = noise.sigma_xy_m * noise.sigma_xy_m;
  const double sz = noise.sigmaAlongRay(m.source);
  const Eigen::Vector3d diag(sxy2, sxy2, sz * sz);
  m.sigma_world = R_wc * diag.asDiagonal() * R_wc.transpose();
  if (!m.z_world.allFinite() || !m.sigma_world.allFinite()) return R::fail("measurement is not finite");
  return R::ok(m);
}

}  // namespace gesture_formation::estimation

#pragma once
/// \file
/// \brief Pinhole camera with OpenCV's plumb_bob distortion (k1, k2, p1, p2, k3).
///
/// Frames (docs/conventions.md): the camera *optical* frame has z forward along the optical
/// axis, x right, y down. Pixels (u, v): u right, v down, origin at the top-left corner of
/// the top-left pixel's centre convention used by OpenCV (pixel centres at integers).

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>

#include "gesture_formation/common/result.hpp"

namespace gesture_formation::common {
template <class Config>
struct FieldTable;
}  // namespace gesture_formation::common

namespace gesture_formation::estimation {

/// \brief Intrinsics of a calibrated camera. Defaults: RealSense D435 colour camera,
/// 640×480, ~69° horizontal field of view, no distortion.
struct CameraIntrinsics {
  double fx = 615.0;  ///< focal length along u [px], > 0
  double fy = 615.0;  ///< focal length along v [px], > 0
  double cx = 320.0;  ///< principal point u [px]
  double cy = 240.0;  ///< principal point v [px]
  std::array<double, 5> distortion{0.0, 0.0, 0.0, 0.0, 0.0};  ///< plumb_bob k1 k2 p1 p2 k3
  int width_px = 640;   ///< image width [px], > 0
  int height_px = 480;  ///< image height [px], > 0

  /// Every problem, each naming the field and value. Empty when valid. Ranges:
  /// cameraIntrinsicsFields() (keys `camera.*`), shared with the YAML reader.
  std::vector<std::string> validate() const;
};

/// \brief CameraIntrinsics' numbers (keys `camera.fx`, `camera.fy`, `camera.cx`, `camera.cy`,
/// `camera.width`, `camera.height`) with their ranges: the only place they are written, used by
/// validate() and by the estimator's YAML reader (common/config_fields.hpp).
const common::FieldTable<CameraIntrinsics>& cameraIntrinsicsFields();

/// \brief What part of the sensor an image shows (ROS sensor_msgs/CameraInfo, REP 104): the
/// calibration (K, width, height) is the full sensor's; a camera that bins pixels (binning 0 or 1:
/// none) or reads out a region (width or height 0: the full image) publishes a smaller image.
struct SensorReadout {
  int binning_x = 0, binning_y = 0;           ///< ≥ 0
  int roi_x_offset = 0, roi_y_offset = 0;     ///< full-resolution pixels, ≥ 0
  int roi_width = 0, roi_height = 0;          ///< full-resolution pixels, ≥ 0 (0: the full image)
};

/// \brief The intrinsics of the image a camera calibrated as `full` publishes with `readout`: the
/// region's offset subtracted, then every length divided by the binning. Pixel centres are at
/// integers (this file's convention), so a binned pixel i covers full pixels b·i … b·i + b − 1 and
/// the principal point is (c − offset − (b − 1)/2) / b (image_geometry's PinholeCameraModel drops
/// the half-pixel term: (b − 1) / (2b) px apart). Distortion acts on normalised coordinates and is
/// unchanged. Fails naming the field and value: a region outside the sensor, a region with a zero
/// and a non-zero side, an offset without a region, a negative binning, or an image of no pixels.
common::Result<CameraIntrinsics> readoutIntrinsics(const CameraIntrinsics& full, const SensorReadout& readout);

/// \brief Projection and back-projection through a plumb_bob camera.
/// Thread safety: immutable after construction; all methods are const and reentrant.
class CameraModel {
 public:
  CameraModel() = default;
  explicit CameraModel(const CameraIntrinsics& intrinsics) : k_(intrinsics) {}

  const CameraIntrinsics& intrinsics() const { return k_; }

  /// \brief Applies the distortion to normalised coordinates (x, y) = (X/Z, Y/Z).
  Eigen::Vector2d distortNormalized(const Eigen::Vector2d& xy) const {
    const double x = xy.x();
    const double y = xy.y();
    const double k1 = k_.distortion[0], k2 = k_.distortion[1], p1 = k_.distortion[2], p2 = k_.distortion[3],
                 k3 = k_.distortion[4];
    const double r2 = x * x + y * y;
    const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
    return Eigen::Vector2d(x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
                           y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y);
  }

  /// \brief Undistorted normalised coordinates of a pixel of the distorted image, or nullopt
  /// when the inverse does not converge (extreme distortion far outside the image) or the
  /// pixel is not finite. Newton iterations on the forward model, converged to 1e-13.
  std::optional<Eigen::Vector2d> undistortPixel(const Eigen::Vector2d& uv) const {
    if (!uv.allFinite()) return std::nullopt;
    const Eigen::Vector2d target((uv.x() - k_.cx) / k_.fx, (uv.y() - k_.cy) / k_.fy);
    if (isDistortionFree()) return target;
    Eigen::Vector2d x = target;
    for (int it = 0; it < 50; ++it) {
      const Eigen::Vector2d r = distortNormalized(x) - target;
      if (r.norm() < 1e-14) return x;
      // Numerical Jacobian of the forward model (cheap and exact enough for Newton).
      const double h = 1e-7;
      Eigen::Matrix2d J;
      J.col(0) = (distortNormalized(x + Eigen::Vector2d(h, 0.0)) - distortNormalized(x - Eigen::Vector2d(h, 0.0))) / (2 * h);
      J.col(1) = (distortNormalized(x + Eigen::Vector2d(0.0, h)) - distortNormalized(x - Eigen::Vector2d(0.0, h))) / (2 * h);
      const double det = J.determinant();
      if (!std::isfinite(det) || std::abs(det) < 1e-12) return std::nullopt;
      x -= J.inverse() * r;
      if (!x.allFinite()) return std::nullopt;
    }
    if ((distortNormalized(x) - target).norm() < 1e-12) return x;
    return std::nullopt;
  }

  /// \brief Unit vector in the camera optical frame through a (distorted) pixel.
  std::optional<Eigen::Vector3d> rayThroughPixel(const Eigen::Vector2d& uv) const {
    const auto xy = undistortPixel(uv);
    if (!xy) return std::nullopt;
    return Eigen::Vector3d(xy->x(), xy->y(), 1.0).normalized();
  }

  /// \brief Pixel (distorted image) of a point in the optical frame; nullopt behind the camera.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& p_camera) const {
    if (!(p_camera.z() > 1e-9) || !p_camera.allFinite()) return std::nullopt;
    const Eigen::Vector2d d = distortNormalized(Eigen::Vector2d(p_camera.x() / p_camera.z(), p_camera.y() / p_camera.z()));
    return Eigen::Vector2d(k_.fx * d.x() + k_.cx, k_.fy * d.y() + k_.cy);
  }

  /// True if (u, v) lies in [0, width) × [0, height).
  bool inImage(const Eigen::Vector2d& uv) const {
    return uv.x() >= 0.0 && uv.y() >= 0.0 && uv.x() < k_.width_px && uv.y() < k_.height_px;
  }

  bool isDistortionFree() const {
    for (double d : k_.distortion) {
      if (d != 0.0) return false;
    }
    return true;
  }

 private:
  CameraIntrinsics k_;
};

}  // namespace gesture_formation::estimation

#pragma once
/// \file
/// \brief The synthetic depth camera of `gfctl simulate --camera synthetic` (docs/mapping.md §7):
/// an aligned depth image computed analytically by casting the ray of each (decimated) pixel
/// against the world's solids — the scenario's primitives, the unmapped obstacles at the frame's
/// time, the ground plane. No GL, no noise.
///
/// Conventions (docs/conventions.md, as the rendered camera): REP 103 world frame; the optical
/// frame of REP 103 §"Suffix frames" / REP 118: x right, y down, z forward; the pinhole
/// intrinsics of the mission's camera without distortion (the rectified image; pixel centres at
/// integer coordinates: the ray of pixel (u, v) is ((u − cx)/fx, (v − cy)/fy, 1)); depth in
/// metres along the optical axis (z), CV_32FC1. Pixels off the decimation grid are NaN (no
/// return: skipped by mapping::depthToPoints); a ray that meets nothing within `max_range_m`
/// is +Inf (REP 118 "too far": free space for the mapping).
///
/// Thread safety: render() is const and may run concurrently on one instance.

#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "gesture_formation/estimation/camera_model.hpp"
#include "gesture_formation/planning/shapes.hpp"

namespace gesture_formation::sim {

/// \brief The optical-frame pose T_world_camera of a camera at `p_world` with heading φ (from +x
/// towards +y) and gimbal pitch ξ (positive up), no roll: z forward (cos ξ cos φ, cos ξ sin φ,
/// sin ξ), x right (sin φ, −cos φ, 0), y = z × x (down) — render::cameraPoseFromHeadingPitch's
/// pose, which the rendered cameras use.
Eigen::Isometry3d opticalPoseFromHeadingPitch(const Eigen::Vector3d& p_world, double heading_rad, double pitch_rad);

/// \brief Distance t ≥ 0 along `dir` (any length, non-zero) from `origin` to the first point of
/// the solid box, +inf when the ray misses it (0 when the origin is inside).
double rayBoxHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const planning::OrientedBox& box);
/// \brief As rayBoxHit for a solid finite cylinder with flat end caps (any axis).
double rayCylinderHit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const planning::Cylinder& cylinder);

class DepthRaycaster {
 public:
  /// \brief The static world: `solids` (copied) and the ground plane z = ground_height_m
  /// (non-finite: no ground).
  DepthRaycaster(const planning::PrimitiveSet& solids, double ground_height_m);

  /// \brief The depth image seen from T_world_camera (optical frame) with `intrinsics` (distortion
  /// ignored), every `pixel_stride`-th pixel of every `pixel_stride`-th row (others NaN), rays
  /// up to `max_range_m` (+Inf beyond), the static world plus `dynamic` (this frame's unmapped
  /// obstacles).
  cv::Mat render(const estimation::CameraIntrinsics& intrinsics, const Eigen::Isometry3d& T_world_camera,
                 int pixel_stride, double max_range_m, const planning::PrimitiveSet& dynamic = {}) const;

  std::size_t primitiveCount() const { return boxes_.size() + cylinders_.size(); }

 private:
  std::vector<planning::OrientedBox> boxes_;
  std::vector<planning::Cylinder> cylinders_;
  std::vector<planning::Aabb> box_bounds_, cylinder_bounds_;
  double ground_height_m_;
};

}  // namespace gesture_formation::sim

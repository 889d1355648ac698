#pragma once
/// \file
/// \brief An aligned depth frame and its decimated, range-limited points in the world frame —
/// the first stage of mapping::LiveMap::integrate (docs/mapping.md §1).
///
/// Frames (docs/conventions.md): the camera *optical* frame (z forward along the optical axis,
/// x right, y down); pixels (u, v) with centres at integers (OpenCV). Depth values are REP 118
/// float depth: metres along the optical axis (the z of the optical frame, as a RealSense
/// aligned depth image and render::Renderer give it — not the ray length); NaN: no valid return
/// (skipped); +Inf: nothing within the sensor's range (free space up to max_range_m); −Inf, 0
/// and negative values: too close or invalid (skipped).
/// Thread safety: pure functions on value types.

#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/mapping/mapping_config.hpp"

namespace gesture_formation::mapping {

/// \brief Pinhole intrinsics of the (rectified, aligned) depth image [px].
struct PinholeIntrinsics {
  double fx = 615.0;
  double fy = 615.0;
  double cx = 320.0;
  double cy = 240.0;
};

/// \brief One aligned depth frame.
struct DepthFrame {
  cv::Mat depth_m;               ///< CV_32FC1, REP 118 float depth (see the file comment)
  PinholeIntrinsics intrinsics;  ///< of depth_m's pixels
  /// The optical frame's pose in the world at the frame's time (camera → world).
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  /// The frame's time [s] (finite): what the live map stamps its own observations with, compared
  /// with the stamps of map changes received from other UAVs (LiveMap::merge, docs/mapping.md §8).
  double stamp_s = 0.0;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The decimated points of one frame, world frame (m).
struct DepthPoints {
  Eigen::Vector3d origin_world = Eigen::Vector3d::Zero();  ///< the camera centre
  /// Returns with a range in [min_range_m, max_range_m]: the end of a free ray and an occupied voxel.
  std::vector<Eigen::Vector3d> hits_world;
  /// Returns beyond max_range_m and +Inf: a point on the pixel's ray beyond max_range_m (by two
  /// voxels' worth, `beyond_m`), for free space only — the ray is cleared up to max_range_m.
  std::vector<Eigen::Vector3d> free_rays_world;
  int pixels = 0;          ///< pixels looked at (after decimation)
  int skipped_invalid = 0; ///< NaN, −Inf, ≤ 0
  int skipped_near = 0;    ///< range < min_range_m
};

/// \brief Checks a frame: depth CV_32FC1 and not empty, fx, fy > 0 and finite, cx, cy finite, a
/// finite rigid pose. Empty string when valid, else the reason naming the field and value.
std::string frameProblem(const DepthFrame& frame);

/// \brief The frame's pixels (u, v) = (i·stride, j·stride) turned into world points (see
/// DepthPoints); `beyond_m` (> 0) places the free-only points past max_range_m. Fails as
/// frameProblem().
common::Result<DepthPoints> depthToPoints(const DepthFrame& frame, const MappingConfig& config, double beyond_m);

}  // namespace gesture_formation::mapping

#include "gesture_formation/mapping/depth_points.hpp"

#include <cmath>
#include <sstream>

namespace gesture_formation::mapping {

std::string frameProblem(const DepthFrame& frame) {
  std::ostringstream out;
  if (frame.depth_m.empty()) return "depth_m is empty";
  if (frame.depth_m.type() != CV_32FC1) {
    out << "depth_m must be CV_32FC1 (32-bit float metres), got OpenCV type " << frame.depth_m.type();
    return out.str();
  }
  const PinholeIntrinsics& k = frame.intrinsics;
  if (!(std::isfinite(k.fx) && k.fx > 0.0)) out << "intrinsics.fx must be finite and > 0, got " << k.fx;
  else if (!(std::isfinite(k.fy) && k.fy > 0.0)) out << "intrinsics.fy must be finite and > 0, got " << k.fy;
  else if (!std::isfinite(k.cx)) out << "intrinsics.cx must be finite, got " << k.cx;
  else if (!std::isfinite(k.cy)) out << "intrinsics.cy must be finite, got " << k.cy;
  if (!out.str().empty()) return out.str();
  const Eigen::Matrix4d& T = frame.T_world_camera.matrix();
  if (!T.allFinite()) return "T_world_camera must be finite";
  if (!std::isfinite(frame.stamp_s)) return "stamp_s must be finite, got " + std::to_string(frame.stamp_s);
  const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
  const double orthogonality = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthogonality > 1e-6 || R.determinant() < 0.0) {
    out << "T_world_camera's rotation must be orthonormal (right-handed), off by " << orthogonality;
    return out.str();
  }
  return "";
}

common::Result<DepthPoints> depthToPoints(const DepthFrame& frame, const MappingConfig& config, double beyond_m) {
  using R = common::Result<DepthPoints>;
  if (const std::string problem = frameProblem(frame); !problem.empty()) return R::fail(problem);
  DepthPoints out;
  const Eigen::Isometry3d& T = frame.T_world_camera;
  out.origin_world = T.translation();
  const PinholeIntrinsics& k = frame.intrinsics;
  const int stride = std::max(1, config.pixel_stride);
  const double free_range_m = config.max_range_m + beyond_m;
  for (int v = 0; v < frame.depth_m.rows; v += stride) {
    const float* row = frame.depth_m.ptr<float>(v);
    const double y = (v - k.cy) / k.fy;
    for (int u = 0; u < frame.depth_m.cols; u += stride) {
      ++out.pixels;
      const double d = row[u];
      const Eigen::Vector3d ray_camera((u - k.cx) / k.fx, y, 1.0);  // the point at depth 1
      if (std::isnan(d) || d <= 0.0) {
        ++out.skipped_invalid;
        continue;
      }
      if (std::isinf(d)) {  // +Inf: nothing within range (REP 118)
        out.free_rays_world.push_back(T * (ray_camera * (free_range_m / ray_camera.norm())));
        continue;
      }
      const Eigen::Vector3d p_camera = ray_camera * d;
      const double range_m = p_camera.norm();
      if (range_m < config.min_range_m) {
        ++out.skipped_near;
      } else if (range_m > config.max_range_m) {
        out.free_rays_world.push_back(T * (p_camera * (free_range_m / range_m)));
      } else {
        out.hits_world.push_back(T * p_camera);
      }
    }
  }
  return R::ok(std::move(out));
}

}  // namespace gesture_formation::mapping

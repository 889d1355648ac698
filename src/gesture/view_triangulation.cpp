#include "gesture_formation/gesture/view_triangulation.hpp"

#include <algorithm>
#include <utility>
#include <bitset>
#include <cmath>
#include <limits>
#include <sstream>

#include <Eigen/Dense>
#include <Eigen/Geometry>

#include "gesture_formation/common/angles.hpp"

namespace gesture_formation::gesture {

namespace {

double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return common::radToDeg(std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)));
}

}  // namespace

CalibratedSkeleton cameraAround(double distance_m, double elevation_deg, double azimuth_deg, double aim_height_m,
                                const estimation::CameraIntrinsics& intrinsics) {
  const double e = common::degToRad(elevation_deg), a = common::degToRad(azimuth_deg);
  const Eigen::Vector3d aim(0.0, 0.0, aim_height_m);
  CalibratedSkeleton c;
  c.intrinsics = intrinsics;
  c.p_world_camera = aim + distance_m * Eigen::Vector3d(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
  const Eigen::Vector3d zc = (aim - c.p_world_camera).normalized();
  const Eigen::Vector3d xc = zc.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d yc = zc.cross(xc);
  c.R_world_camera << xc, yc, zc;
  return c;
}

std::vector<std::string> validate(const CalibratedSkeleton& c) {
  std::vector<std::string> e = c.intrinsics.validate();
  const Eigen::Matrix3d& R = c.R_world_camera;
  if (!R.allFinite() || !((R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <= 1e-6) ||
      !(R.determinant() > 0.0)) {
    std::ostringstream m;
    m << "R_world_camera: not a rotation (orthonormal within 1e-6, det +1): [" << R.format(Eigen::IOFormat(6, 0, ", ", "; "))
      << "]";
    e.push_back(m.str());
  }
  if (!(c.p_world_camera.allFinite() && c.p_world_camera.norm() <= 1e4)) {
    e.push_back("p_world_camera: expected finite within 10 km, got (" + std::to_string(c.p_world_camera.x()) + ", " +
                std::to_string(c.p_world_camera.y()) + ", " + std::to_string(c.p_world_camera.z()) + ")");
  }
  for (int k = 0; k < kNumKeypoints; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const Skeleton2D& s = c.skeleton;
    if (!(std::isfinite(s.x[i]) && std::isfinite(s.y[i]))) {
      e.push_back("keypoint " + std::to_string(k) + ": position not finite (" + std::to_string(s.x[i]) + ", " +
                  std::to_string(s.y[i]) + ")");
    }
    if (!(s.c[i] >= 0.0 && s.c[i] <= 1.0)) {
      e.push_back("keypoint " + std::to_string(k) + ": confidence expected [0, 1], got " + std::to_string(s.c[i]));
    }
  }
  return e;
}

std::vector<std::string> TriangulationConfig::validate() const {
  std::vector<std::string> e;
  if (!(min_confidence >= 0.0 && min_confidence < 1.0)) {
    e.push_back("min_confidence: expected [0, 1), got " + std::to_string(min_confidence));
  }
  if (!(nose_behind_m >= 0.0 && nose_behind_m <= 1.0)) {
    e.push_back("nose_behind_m: expected [0, 1], got " + std::to_string(nose_behind_m));
  }
  if (!(min_ray_angle_deg > 0.0 && min_ray_angle_deg < 90.0)) {
    e.push_back("min_ray_angle_deg: expected (0, 90), got " + std::to_string(min_ray_angle_deg));
  }
  return e;
}

std::vector<std::string> ArmGestureThresholds::validate() const {
  std::vector<std::string> e;
  const auto angle = [&e](const char* name, double v) {
    if (!(v > 0.0 && v < 90.0)) e.push_back(std::string(name) + ": expected (0, 90) deg, got " + std::to_string(v));
  };
  angle("extend_max_deg", extend_max_deg);
  angle("raise_max_deg", raise_max_deg);
  if (!(min_reach_ratio > 0.0 && min_reach_ratio <= 1.0)) {
    e.push_back("min_reach_ratio: expected (0, 1], got " + std::to_string(min_reach_ratio));
  }
  angle("max_trunk_tilt_deg", max_trunk_tilt_deg);
  if (!(max_foot_offset_torso > 0.0 && max_foot_offset_torso <= 5.0)) {
    e.push_back("max_foot_offset_torso: expected (0, 5], got " + std::to_string(max_foot_offset_torso));
  }
  return e;
}

namespace {

/// The COCO-17 keypoint of the other side (nose: itself).
constexpr std::array<int, kNumKeypoints> kMirror{0, 2, 1, 4, 3, 6, 5, 8, 7, 10, 9, 12, 11, 14, 13, 16, 15};
/// The keypoints that decide which views are mirrored: the body, not the arms (the arms' own
/// naming errors are what the gesture geometry allows for).
constexpr std::array<int, 12> kBodyKeypoints{1, 2, 3, 4, 5, 6, 11, 12, 13, 14, 15, 16};

/// Triangulates the keypoints `which` with view v's keypoint k read as kMirror[k] when bit v of
/// `mirrored` is set; returns the sum of the confidence-weighted squared reprojection errors [px²].
double triangulateSome(const std::vector<CalibratedSkeleton>& views, const std::vector<estimation::CameraModel>& cameras,
                       const TriangulationConfig& config, unsigned mirrored, const int* which, std::size_t count,
                       Skeleton3D& out) {
  const double min_sin = std::sin(common::degToRad(config.min_ray_angle_deg));
  double total = 0.0;
  for (std::size_t w = 0; w < count; ++w) {
    const int k = which[w];
    const auto i = static_cast<std::size_t>(k);
    // Least squares: Σ w (I − r rᵀ) p = Σ w (I − r rᵀ) c over the rays (c, r), r unit, world frame.
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    Eigen::Vector3d b = Eigen::Vector3d::Zero();
    std::vector<Eigen::Vector3d> rays;
    std::vector<std::size_t> used;
    for (std::size_t v = 0; v < views.size(); ++v) {
      const CalibratedSkeleton& cs = views[v];
      const auto j = static_cast<std::size_t>(v < 32 && ((mirrored >> v) & 1U) ? kMirror[i] : k);
      const double c = cs.skeleton.c[j];
      if (!(c >= config.min_confidence) || c <= 0.0) continue;
      if (!cs.R_world_camera.allFinite() || !cs.p_world_camera.allFinite()) continue;
      const auto ray_camera = cameras[v].rayThroughPixel(Eigen::Vector2d(cs.skeleton.x[j], cs.skeleton.y[j]));
      if (!ray_camera) continue;
      const Eigen::Vector3d r = (cs.R_world_camera * *ray_camera).normalized();
      const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - r * r.transpose();
      A += c * P;
      b += c * P * cs.p_world_camera;
      rays.push_back(r);
      used.push_back(v);
    }
    if (rays.size() < 2) continue;
    double widest = 0.0;
    for (std::size_t a = 0; a < rays.size(); ++a) {
      for (std::size_t c = a + 1; c < rays.size(); ++c) widest = std::max(widest, rays[a].cross(rays[c]).norm());
    }
    if (widest < min_sin) continue;
    const Eigen::Vector3d p = A.ldlt().solve(b);
    if (!p.allFinite()) continue;
    double worst = 0.0, squared = 0.0;
    for (std::size_t v : used) {
      const CalibratedSkeleton& cs = views[v];
      const auto j = static_cast<std::size_t>(v < 32 && ((mirrored >> v) & 1U) ? kMirror[i] : k);
      const auto px = cameras[v].project(cs.R_world_camera.transpose() * (p - cs.p_world_camera));
      if (!px) {
        worst = std::numeric_limits<double>::infinity();
        break;
      }
      const double e = (*px - Eigen::Vector2d(cs.skeleton.x[j], cs.skeleton.y[j])).norm();
      worst = std::max(worst, e);
      squared += cs.skeleton.c[j] * e * e;
    }
    if (!std::isfinite(worst)) {  // behind a camera that saw it: inconsistent rays
      total += 1e12;
      continue;
    }
    total += squared;
    out.p_world[i] = p;
    out.valid[i] = true;
    out.views[i] = static_cast<int>(used.size());
    out.reprojection_px[i] = worst;
  }
  return total;
}

}  // namespace

Skeleton3D triangulate(const std::vector<CalibratedSkeleton>& views, const TriangulationConfig& config) {
  std::vector<estimation::CameraModel> cameras;
  cameras.reserve(views.size());
  for (const auto& v : views) cameras.emplace_back(v.intrinsics);
  std::array<int, kNumKeypoints> all{};
  for (int k = 0; k < kNumKeypoints; ++k) all[static_cast<std::size_t>(k)] = k;
  unsigned mirrored = 0;
  if (config.resolve_sides && views.size() >= 2) {
    const std::size_t n = std::min<std::size_t>(views.size(), 6);
    double best = std::numeric_limits<double>::infinity();
    int best_count = 0;
    for (unsigned m = 0; m < (1U << n); ++m) {
      Skeleton3D body;
      const double e = triangulateSome(views, cameras, config, m, kBodyKeypoints.data(), kBodyKeypoints.size(), body);
      const auto count = static_cast<int>(std::bitset<32>(m).count());
      if (e < best || (e == best && count < best_count)) {
        best = e;
        best_count = count;
        mirrored = m;
      }
    }
  }
  Skeleton3D out;
  triangulateSome(views, cameras, config, mirrored, all.data(), all.size(), out);
  out.mirrored_views = mirrored;
  if (config.resolve_sides) {
    // The views agree; all of them may still have named the sides from behind: the face says.
    const auto frame = bodyFrameOf(out);
    if (frame && out.valid[kNose] &&
        (out.p_world[kNose] - frame->p_world_origin).dot(frame->R_world_body.col(0)) < -config.nose_behind_m) {
      for (std::size_t k = 0; k < out.p_world.size(); ++k) {  // each left/right pair exchanged once
        const auto o = static_cast<std::size_t>(kMirror[k]);
        if (o <= k) continue;
        std::swap(out.p_world[k], out.p_world[o]);
        std::swap(out.valid[k], out.valid[o]);
        std::swap(out.views[k], out.views[o]);
        std::swap(out.reprojection_px[k], out.reprojection_px[o]);
      }
      out.mirrored_all = true;
    }
  }
  return out;
}

std::optional<BodyFrame> bodyFrameOf(const Skeleton3D& s) {
  for (int k : {kLeftShoulder, kRightShoulder, kLeftHip, kRightHip}) {
    if (!s.valid[static_cast<std::size_t>(k)]) return std::nullopt;
  }
  const Eigen::Vector3d ls = s.p_world[kLeftShoulder], rs = s.p_world[kRightShoulder];
  const Eigen::Vector3d mid_shoulder = 0.5 * (ls + rs);
  const Eigen::Vector3d mid_hip = 0.5 * (s.p_world[kLeftHip] + s.p_world[kRightHip]);
  const Eigen::Vector3d lateral = ls - rs, torso = mid_shoulder - mid_hip;
  if (lateral.norm() < 0.15 || lateral.norm() > 0.7 || torso.norm() < 0.2 || torso.norm() > 1.0) return std::nullopt;
  const Eigen::Vector3d y = lateral.normalized();
  const Eigen::Vector3d z_raw = torso - torso.dot(y) * y;
  if (z_raw.norm() < 0.1) return std::nullopt;  // torso along the shoulder axis: not a body
  const Eigen::Vector3d z = z_raw.normalized();
  BodyFrame f;
  f.R_world_body.col(0) = y.cross(z);
  f.R_world_body.col(1) = y;
  f.R_world_body.col(2) = z;
  f.p_world_origin = mid_shoulder;
  return f;
}

Stance stanceOf(const Skeleton3D& s) {
  Stance st;
  for (int k : {kLeftShoulder, kRightShoulder, kLeftHip, kRightHip, kLeftAnkle, kRightAnkle}) {
    if (!s.valid[static_cast<std::size_t>(k)]) return st;
  }
  const Eigen::Vector3d mid_hip = 0.5 * (s.p_world[kLeftHip] + s.p_world[kRightHip]);
  const Eigen::Vector3d trunk = 0.5 * (s.p_world[kLeftShoulder] + s.p_world[kRightShoulder]) - mid_hip;
  const double torso = trunk.norm();
  if (!(torso >= 0.2)) return st;
  st.valid = true;
  st.trunk_tilt_deg = angleDeg(trunk, Eigen::Vector3d::UnitZ());
  for (int k : {kLeftAnkle, kRightAnkle}) {
    const Eigen::Vector3d d = s.p_world[static_cast<std::size_t>(k)] - mid_hip;
    st.foot_offset_torso = std::max(st.foot_offset_torso, std::hypot(d.x(), d.y()) / torso);
  }
  return st;
}

ArmGeometry armGeometry(const Skeleton3D& s, bool left_arm) {
  ArmGeometry g;
  const auto shoulder = static_cast<std::size_t>(left_arm ? kLeftShoulder : kRightShoulder);
  const auto elbow = static_cast<std::size_t>(left_arm ? kLeftElbow : kRightElbow);
  const auto wrist = static_cast<std::size_t>(left_arm ? kLeftWrist : kRightWrist);
  const auto frame = bodyFrameOf(s);
  if (!frame || !s.valid[shoulder] || !s.valid[wrist]) return g;
  const Eigen::Vector3d arm_world = s.p_world[wrist] - s.p_world[shoulder];
  if (arm_world.norm() < 1e-3) return g;
  g.valid = true;
  g.direction_body = frame->R_world_body.transpose() * arm_world.normalized();
  g.from_outward_deg = angleDeg(g.direction_body, Eigen::Vector3d(0.0, left_arm ? 1.0 : -1.0, 0.0));
  g.from_up_deg = angleDeg(g.direction_body, Eigen::Vector3d::UnitZ());
  g.from_forward_deg = angleDeg(g.direction_body, Eigen::Vector3d::UnitX());
  if (s.valid[elbow]) {
    const double path = (s.p_world[elbow] - s.p_world[shoulder]).norm() + (s.p_world[wrist] - s.p_world[elbow]).norm();
    if (path > 1e-3) g.reach_ratio = arm_world.norm() / path;
  }
  return g;
}

int oneArmGesture3D(const Skeleton3D& s, const ArmGestureThresholds& t) {
  const Stance stance = stanceOf(s);
  if (!stance.valid || stance.trunk_tilt_deg > t.max_trunk_tilt_deg || stance.foot_offset_torso > t.max_foot_offset_torso) {
    return kNone;
  }
  int best = kNone;
  for (bool left : {true, false}) {
    const ArmGeometry g = armGeometry(s, left);
    if (!g.valid) continue;
    if (g.from_up_deg <= t.raise_max_deg) return kRaiseArmUp;
    if (g.from_outward_deg <= t.extend_max_deg && g.reach_ratio >= t.min_reach_ratio) best = kExtendArmSide;
  }
  return best;
}

}  // namespace gesture_formation::gesture

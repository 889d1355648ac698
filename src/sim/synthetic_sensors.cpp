#include "gesture_formation/sim/synthetic_sensors.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "gesture_formation/planning/occupancy_map.hpp"

namespace gesture_formation::sim {

const common::FieldTable<CameraSensorConfig>& cameraSensorFields() {
  using common::Range;
  using C = CameraSensorConfig;
  static const common::FieldTable<C> t{{
      {"rate_hz", Range::openClosed(0.0, 60.0), [](C& c) { return &c.rate_hz; }},
      {"pixel_noise_px", Range::nonNegative(), [](C& c) { return &c.pixel_noise_px; }},
      {"detection_dropout", Range{0.0, 1.0, true, false}, [](C& c) { return &c.detection_dropout; }},
      {"max_detection_range_m", Range::positive(), [](C& c) { return &c.max_detection_range_m; }},
      {"min_box_height_px", Range::atLeast(1.0), [](C& c) { return &c.min_box_height_px; }},
      {"min_visible_fraction", Range::openClosed(0.0, 1.0), [](C& c) { return &c.min_visible_fraction; }},
      {"occlusion_ignore_near_worker_m", Range::nonNegative(), [](C& c) { return &c.occlusion_ignore_near_worker_m; }},
  }};
  return t;
}

const common::FieldTable<RangeSensorConfig>& rangeSensorFields() {
  using common::Range;
  using C = RangeSensorConfig;
  static const common::FieldTable<C> t{{
      {"noise_m", Range::nonNegative(), [](C& c) { return &c.noise_m; }},
      {"max_range_m", Range::positive(), [](C& c) { return &c.max_range_m; }},
      {"dropout", Range::closed(0.0, 1.0), [](C& c) { return &c.dropout; }},
  }};
  return t;
}

std::vector<std::string> CameraSensorConfig::validate(const std::string& prefix) const {
  std::vector<std::string> e;
  for (const auto& c : camera.validate()) e.push_back(prefix + c);
  for (auto& line : common::problemLines(cameraSensorFields().rangeProblems(*this), prefix)) e.push_back(std::move(line));
  return e;
}

std::vector<std::string> RangeSensorConfig::validate(const std::string& prefix) const {
  return common::problemLines(rangeSensorFields().rangeProblems(*this), prefix);
}

const char* toString(Visibility v) {
  switch (v) {
    case Visibility::kVisible: return "visible";
    case Visibility::kOutOfView: return "out_of_view";
    case Visibility::kTooFar: return "too_far";
    case Visibility::kOccluded: return "occluded";
    case Visibility::kDropout: return "dropout";
    case Visibility::kBlackout: return "blackout";
  }
  return "?";
}

estimation::CameraPose cameraPose(const Eigen::Vector3d& p_world, double heading_rad, double pitch_rad) {
  const double cp = std::cos(pitch_rad), sp = std::sin(pitch_rad), ch = std::cos(heading_rad), sh = std::sin(heading_rad);
  const Eigen::Vector3d z(cp * ch, cp * sh, sp);
  const Eigen::Vector3d x(sh, -ch, 0.0);
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.col(0) = x;
  R.col(1) = y;
  R.col(2) = z;
  estimation::CameraPose pose;
  pose.t_world_camera = p_world;
  pose.q_world_camera = Eigen::Quaterniond(R).normalized();
  return pose;
}

SyntheticSensors::SyntheticSensors(const CameraSensorConfig& camera, const RangeSensorConfig& stereo,
                                   const RangeSensorConfig& uwb, const planning::OccupancyMap* map,
                                   std::mt19937_64 camera_rng, std::mt19937_64 stereo_rng, std::mt19937_64 uwb_rng)
    : camera_(camera),
      stereo_(stereo),
      uwb_(uwb),
      map_(map),
      camera_model_(camera.camera),
      camera_rng_(std::move(camera_rng)),
      stereo_rng_(std::move(stereo_rng)),
      uwb_rng_(std::move(uwb_rng)) {}

bool SyntheticSensors::occluded(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double ignore_end_m) const {
  if (map_ == nullptr) return false;
  const Eigen::Vector3d d = b - a;
  const double len = d.norm() - ignore_end_m;
  if (len <= 0.0) return false;
  const Eigen::Vector3d dir = d.normalized();
  const double step = 0.5 * map_->resolution();
  for (double s = 0.0; s <= len; s += step) {
    if (map_->isOccupied(Eigen::Vector3d(a + s * dir))) return true;
  }
  return false;
}

SensorFrame SyntheticSensors::observe(const estimation::CameraPose& pose, const Eigen::Vector3d& feet_world,
                                      const Eigen::Vector3d& p_world, double height_m, bool blackout) {
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  SensorFrame f;
  const Eigen::Vector3d cam = pose.t_world_camera;
  f.true_range_m = (p_world - cam).norm();
  // Draw every random number every frame so that one sensor's outcome never shifts another's.
  const double cam_drop = u01(camera_rng_);
  const double edge_noise[4] = {n01(camera_rng_), n01(camera_rng_), n01(camera_rng_), n01(camera_rng_)};
  const double stereo_drop = u01(stereo_rng_), stereo_noise = n01(stereo_rng_);
  const double uwb_drop = u01(uwb_rng_), uwb_noise = n01(uwb_rng_);

  if (f.true_range_m <= uwb_.max_range_m && uwb_drop >= uwb_.dropout) {
    f.d_uwb_m = f.true_range_m + uwb_.noise_m * uwb_noise;
  }

  if (blackout) {
    f.visibility = Visibility::kBlackout;
    return f;
  }
  if (f.true_range_m > camera_.max_detection_range_m) {
    f.visibility = Visibility::kTooFar;
    return f;
  }
  // Body slab facing the camera: feet and head top, ±0.25 m sideways.
  const Eigen::Matrix3d R_wc = pose.q_world_camera.toRotationMatrix();
  Eigen::Vector3d side = (p_world - cam).cross(Eigen::Vector3d::UnitZ());
  side = side.norm() > 1e-9 ? Eigen::Vector3d(0.25 * side.normalized()) : Eigen::Vector3d(0.25, 0.0, 0.0);
  const Eigen::Vector3d head = feet_world + Eigen::Vector3d(0.0, 0.0, height_m);
  double u0 = 1e18, v0 = 1e18, u1 = -1e18, v1 = -1e18;
  for (const Eigen::Vector3d& q : {Eigen::Vector3d(feet_world + side), Eigen::Vector3d(feet_world - side),
                                   Eigen::Vector3d(head + side), Eigen::Vector3d(head - side)}) {
    const auto px = camera_model_.project(R_wc.transpose() * (q - cam));
    if (!px || !camera_model_.inImage(*px)) {
      f.visibility = Visibility::kOutOfView;
      return f;
    }
    u0 = std::min(u0, px->x());
    u1 = std::max(u1, px->x());
    v0 = std::min(v0, px->y());
    v1 = std::max(v1, px->y());
  }
  if (v1 - v0 < camera_.min_box_height_px) {
    f.visibility = Visibility::kTooFar;
    return f;
  }
  // Partial occlusion: rays to five points up the body; a thin member or wire blocks one or
  // two of them, a tower leg or a wall most. Detected when at least min_visible_fraction are free.
  int free_rays = 0;
  for (double h : {0.1, 0.3, 0.5, 0.7, 0.9}) {
    const Eigen::Vector3d target = feet_world + Eigen::Vector3d(0.0, 0.0, h * height_m);
    if (!occluded(cam, target, camera_.occlusion_ignore_near_worker_m)) ++free_rays;
  }
  (void)p_world;
  if (free_rays < std::ceil(camera_.min_visible_fraction * 5.0 - 1e-9)) {
    f.visibility = Visibility::kOccluded;
    return f;
  }
  if (cam_drop < camera_.detection_dropout) {
    f.visibility = Visibility::kDropout;
    return f;
  }
  const double s = camera_.pixel_noise_px;
  u0 += s * edge_noise[0];
  u1 += s * edge_noise[1];
  v0 += s * edge_noise[2];
  v1 += s * edge_noise[3];
  f.box = estimation::Box{u0, v0, std::max(1.0, u1 - u0), std::max(1.0, v1 - v0)};
  f.visibility = Visibility::kVisible;
  if (f.true_range_m <= stereo_.max_range_m && stereo_drop >= stereo_.dropout) {
    f.d_stereo_m = f.true_range_m + stereo_.noise_m * stereo_noise;
  }
  return f;
}

}  // namespace gesture_formation::sim

#pragma once
/// \file
/// \brief Synthetic sensing of the worker from ground truth (docs/design.md §5), feeding the real
/// estimator (estimation::makeMeasurement + HumanKalman):
/// - the worker's **box** in the leader's camera: the body (a 0.5 m wide upright slab from the
///   feet to the head top, facing the camera) projected through the plumb_bob camera model
///   into the distorted image; detected only when the whole box lies in the image, the
///   worker is within `max_detection_range_m`, the box is at least `min_box_height_px`
///   tall, enough lines of sight (to five points up the body, `min_visible_fraction`) are
///   free in the occupancy map (ray cast at half-voxel steps, ignoring the last
///   `occlusion_ignore_near_worker_m` — the structure the worker stands on; a conductor,
///   inflated to ~0.5 m by the voxels, blocks one or two rays, a tower leg most), and a
///   Bernoulli dropout does not hit; each box edge gets
///   Gaussian pixel noise;
/// - **stereo** distance: true camera–mid-body range + N(0, σ) when detected, within range,
///   not dropped (paper σ_z,stereo 0.3 m);
/// - **UWB** distance: true range + N(0, σ) within range, not dropped (paper σ_z,UWB 0.1 m).
/// Thread safety: none (owns RNGs). Deterministic for its RNGs.

#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/estimation/camera_model.hpp"
#include "gesture_formation/estimation/measurement_model.hpp"
#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::planning {
class OccupancyMap;
}

namespace gesture_formation::sim {

struct CameraSensorConfig {
  estimation::CameraIntrinsics camera;    ///< D435 colour 640×480 by default
  double rate_hz = 15.0;                  ///< frames per second, (0, 60]
  double pixel_noise_px = 2.0;            ///< σ of each box edge [px], ≥ 0
  double detection_dropout = 0.05;        ///< probability a visible worker is missed, [0, 1)
  double max_detection_range_m = 35.0;    ///< > 0
  double min_box_height_px = 12.0;        ///< ≥ 1
  double occlusion_ignore_near_worker_m = 0.6;  ///< ≥ 0
  /// Share of the five rays (to 10, 30, 50, 70, 90 % of the body height) that must be free, (0, 1].
  double min_visible_fraction = 0.6;
  std::vector<std::string> validate(const std::string& prefix = "") const;
};

struct RangeSensorConfig {
  double noise_m = 0.1;       ///< σ [m], ≥ 0
  double max_range_m = 30.0;  ///< > 0
  double dropout = 0.05;      ///< probability of no reading, [0, 1]
  std::vector<std::string> validate(const std::string& prefix = "") const;
};

/// \brief The one range of each number of the simulated sensors (mission.sensors.camera.*,
/// mission.sensors.stereo.* / uwb.*).
const common::FieldTable<CameraSensorConfig>& cameraSensorFields();
const common::FieldTable<RangeSensorConfig>& rangeSensorFields();

/// \brief Why the camera did not deliver a box.
enum class Visibility { kVisible, kOutOfView, kTooFar, kOccluded, kDropout, kBlackout };
const char* toString(Visibility v);

/// \brief One camera frame's synthetic output.
struct SensorFrame {
  Visibility visibility = Visibility::kOutOfView;
  estimation::Box box;       ///< valid when visible
  double d_uwb_m = std::numeric_limits<double>::quiet_NaN();
  double d_stereo_m = std::numeric_limits<double>::quiet_NaN();
  double true_range_m = 0.0;
  bool visible() const { return visibility == Visibility::kVisible; }
};

/// \brief Pose of the camera optical frame (z forward, x right, y down) for a camera at
/// `p_world` with heading φ and pitch ξ (docs/conventions.md).
estimation::CameraPose cameraPose(const Eigen::Vector3d& p_world, double heading_rad, double pitch_rad);

class SyntheticSensors {
 public:
  /// \brief `map` may be null (no occlusion); it must outlive this object.
  SyntheticSensors(const CameraSensorConfig& camera, const RangeSensorConfig& stereo, const RangeSensorConfig& uwb,
                   const planning::OccupancyMap* map, std::mt19937_64 camera_rng, std::mt19937_64 stereo_rng,
                   std::mt19937_64 uwb_rng);

  /// \brief The frame seen from the **true** camera pose of a worker with feet at
  /// `feet_world`, mid-body `p_world` and height `height_m`. `blackout` forces no box
  /// (fault injection: worker lost).
  SensorFrame observe(const estimation::CameraPose& true_pose, const Eigen::Vector3d& feet_world,
                      const Eigen::Vector3d& p_world, double height_m, bool blackout = false);

  /// \brief True when the segment from `a` to `b` (shortened by `ignore_end_m` at b) crosses
  /// an occupied voxel.
  bool occluded(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double ignore_end_m) const;

  const estimation::CameraModel& camera() const { return camera_model_; }

 private:
  CameraSensorConfig camera_;
  RangeSensorConfig stereo_, uwb_;
  const planning::OccupancyMap* map_;
  estimation::CameraModel camera_model_;
  std::mt19937_64 camera_rng_, stereo_rng_, uwb_rng_;
};

}  // namespace gesture_formation::sim

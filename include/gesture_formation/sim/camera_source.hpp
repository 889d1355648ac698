#pragma once
/// \file
/// \brief The formation's cameras as the mission runs them (docs/simulation.md §1 "sensing",
/// §8): one call per camera frame gives the leader's box and ranges for the estimator, each
/// camera's gesture classification for the vote, and the skeletons for the 3-D confirmation.
/// Two implementations behind this one interface, so that sim::runMission has no camera
/// branches: the synthetic camera (LeaderCamera, leader_camera.hpp: boxes and skeletons made
/// from ground truth; the default) and the rendered camera (RenderedCamera,
/// rendered_camera.hpp, library gesture_formation_sim_render: rendered images through the
/// real perception pipeline).
/// Thread safety: an implementation is used by one mission thread.

#include <optional>
#include <vector>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "gesture_formation/gesture/gesture_classifier.hpp"
#include "gesture_formation/gesture/skeleton_synth.hpp"
#include "gesture_formation/gesture/view_triangulation.hpp"
#include "gesture_formation/sim/multirotor.hpp"
#include "gesture_formation/sim/perception_truth.hpp"
#include "gesture_formation/sim/synthetic_sensors.hpp"
#include "gesture_formation/sim/worker_model.hpp"

namespace gesture_formation::sim {

class MissionClassifier;

/// \brief One follower camera's view in the same frame (gesture voting, docs/gestures.md §4.1).
struct FollowerView {
  bool visible = false;  ///< the worker is in its field of view, not occluded, detected
  std::optional<gesture::Classification> classification;  ///< as LeaderCameraFrame::classification
  gesture::CalibratedSkeleton calibrated;  ///< its skeleton with the true pose of the camera that rendered it (visible, view_fusion.confirm_3d only)
};

/// \brief One frame of the leader's camera.
/// \brief One UAV camera's depth image of a frame: REP 118 float depth (metres along the optical
/// axis, NaN: no return), the camera's optical-frame pose and the frame's time.
struct CameraDepth {
  std::size_t camera = 0;  ///< 0: the leader's camera, k ≥ 1: the k-th follower's of CameraSource::frame
  double t_s = 0.0;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  estimation::CameraIntrinsics intrinsics;  ///< of depth_m's pixels (no distortion)
  cv::Mat depth_m;  ///< CV_32FC1
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

struct LeaderCameraFrame {
  SensorFrame sensors;         ///< box (when visible) and ranges after the injected faults
  /// The leader camera's calibration, with every frame as a driver's CameraInfo: the estimator's
  /// camera model (estimation::CameraModelSource, as the WorkerEstimator nodelet's).
  estimation::CameraIntrinsics intrinsics;
  gesture::SynthFrame skeleton;  ///< what the worker looked like from the camera
  gesture::CalibratedSkeleton calibrated;  ///< skeleton with the true pose of the camera that rendered it (WorkerModel::calibrated; view_fusion.confirm_3d only)
  int range_outliers = 0;      ///< gross range errors injected into this frame
  /// The classifier's output: the worker was detected, the FIFO is full, a classifier was
  /// given and it succeeded.
  std::optional<gesture::Classification> classification;
  /// The followers' cameras at the same instant (empty unless followers were given).
  std::vector<FollowerView> followers;
  /// Every depth image this frame produced, one per UAV camera that rendered one (rendered
  /// cameras only; the synthetic camera has none): what sim::SiteMapping integrates into that
  /// UAV's live map in place of its ray-cast depth (SiteMapping::offerDepth).
  std::vector<CameraDepth> depth;
};

/// \brief The formation's cameras (leader + followers' views) for sim::runMission.
class CameraSource {
 public:
  virtual ~CameraSource() = default;
  /// \brief The frame at `t_s` (called at the camera rate, times increasing) of the camera on
  /// the leader's true state `leader`, and — when followers are given — of follower i+1's
  /// camera on `followers[i]` (`online[i]` false: its computer is down, no view), of the worker
  /// whose truth at t_s is `worker_state` (`worker` advances its motions: it must be the model
  /// that gave worker_state). `classifier` may be null (no gesture pipeline). Pass the same
  /// number of followers at every call.
  virtual LeaderCameraFrame frame(double t_s, const MultirotorState& leader, const std::vector<MultirotorState>& followers,
                                  const std::vector<bool>& online, const WorkerState& worker_state, WorkerModel& worker,
                                  MissionClassifier* classifier) = 0;
  /// \brief Time of the last frame in which the leader's camera found the worker (−1e9: never).
  virtual double lastVisibleS() const = 0;
  /// \brief Per-frame perception against the truth (rendered cameras); null when the camera
  /// has none (the synthetic camera).
  virtual const std::vector<PerceptionRecord>* perceptionRecords() const { return nullptr; }
};

}  // namespace gesture_formation::sim

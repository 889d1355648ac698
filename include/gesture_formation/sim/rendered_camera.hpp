#pragma once
/// \file
/// \brief The rendered camera (docs/simulation.md §8; issue 32): a CameraSource whose frames are
/// rendered images of the mission (sim::SceneRenderer over render::Renderer: the world, the other UAVs, the worker mesh
/// posed every frame from the worker model's own 3-D body, WorkerModel::bodyAt) at each UAV's
/// **true** camera pose, put through the real perception pipeline of that UAV
/// (perception::PerceptionPipeline: detector ⇄ tracker, skeleton network, FIFO) and the
/// gesture classifier on the FIFO's window. The leader's box for the estimator is the
/// tracker's box; its stereo range is estimation::stereoDistance on the rendered depth inside
/// that box (as the Perception nodelet computes it); UWB stays synthetic (SyntheticSensors, a
/// radio sensor). No ground-truth box, keypoint or distance reaches the estimator or the
/// classifier. The truth (WorkerTruth: visible box, projected joints) is recorded beside the
/// pipeline's output per frame and UAV (PerceptionRecord), and each UAV's annotated stream may
/// be written as a video.
///
/// What frame() returns differs from the synthetic camera in two fields: `sensors.visibility` is
/// kVisible when the pipeline found the worker, kBlackout in an injected camera blackout (no frame),
/// else kDropout (the pipeline did not find the worker); `skeleton` carries only the frame's truth
/// label (its keypoints stay empty: no synthetic skeleton leaves this class).
///
/// Library gesture_formation_sim_render (sim + render + perception); the onboard nodelets
/// never link it. Determinism: the same seed gives the same images and the same pipeline
/// outputs on one machine (wall-clock timings aside).
/// Thread safety: none; one mission thread (the Renderer's GL context is made current at each call).

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/estimation/stereo_distance.hpp"
#include "gesture_formation/perception/perception_pipeline.hpp"
#include "gesture_formation/render/renderer.hpp"
#include "gesture_formation/sim/camera_source.hpp"
#include "gesture_formation/sim/mission_config.hpp"
#include "gesture_formation/sim/scene_renderer.hpp"

namespace gesture_formation::planning {
class OccupancyMap;
struct Scenario;
}  // namespace gesture_formation::planning


namespace gesture_formation::sim {

struct CameraResult;  // what one camera made of one frame (rendered_camera.cpp)

struct RenderedCameraConfig {
  /// Folder holding the worker asset (mannequin/wooden_mannequin.glb) and the perception
  /// networks (the relative paths of perception.models_root are resolved against it).
  std::string models_root = "third_party_models";
  perception::PerceptionConfig perception;  ///< every camera's pipeline (models_root replaced by the above)
  /// The stereo range from the rendered depth; max_depth_m is the mission's stereo.max_range_m
  /// unless set here (> 0).
  estimation::StereoDistanceConfig stereo;
  bool stereo_max_from_mission = true;  ///< max_depth_m ← mission stereo.max_range_m
  std::string video_dir;  ///< non-empty: each UAV's annotated stream as DIR/uav<i>_<name>.avi (MJPG)
  /// The UAVs' pipelines of one frame run on up to this many threads (each UAV runs its own
  /// pipeline on its own computer), 1..16; the results do not depend on it.
  int threads = 1;
  /// Every problem, each naming the field and value.
  std::vector<std::string> validate() const;
};

/// \brief Turns the pipeline's FIFO tensor ([N][51], box-normalised) into the classifier's
/// window: each frame a Skeleton2D on the unit box (u = v = 0, w = h = 1) whose
/// gesture::boxNormalizedFeatures are exactly the FIFO's values. Empty window when the
/// tensor does not hold gesture::kWindowFrames frames.
gesture::SkeletonWindow windowFromFifo(const std::vector<float>& tensor);

class RenderedCamera : public CameraSource {
 public:
  /// \brief Opens the renderer (EGL + the worker asset), uploads `scenario`'s world, builds one
  /// perception pipeline per UAV of `mission` and the video writers. Fails naming what is
  /// missing and how to get it (no EGL device, the asset, a network file) — there is no
  /// fall-back to the synthetic camera. `mission`, `map` (UWB line of sight; may be null)
  /// must outlive this. `unmapped`: the site's obstacles that the prior map lacks, drawn where
  /// they are at each frame's time (SceneRenderer::setUnmappedObstacles).
  static common::Result<std::unique_ptr<RenderedCamera>> create(const RenderedCameraConfig& config,
                                                                const MissionConfig& mission,
                                                                const planning::Scenario& scenario,
                                                                const planning::OccupancyMap* map, std::uint64_t seed,
                                                                const std::vector<UnmappedObstacle>& unmapped = {});
  ~RenderedCamera() override;
  RenderedCamera(const RenderedCamera&) = delete;
  RenderedCamera& operator=(const RenderedCamera&) = delete;

  LeaderCameraFrame frame(double t_s, const MultirotorState& leader, const std::vector<MultirotorState>& followers,
                          const std::vector<bool>& online, const WorkerState& worker_state, WorkerModel& worker,
                          MissionClassifier* classifier) override;
  double lastVisibleS() const override;
  const std::vector<PerceptionRecord>* perceptionRecords() const override { return &records_; }
  /// \brief The GL renderer in use (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)").
  std::string glRenderer() const;

  struct Camera;  ///< one UAV's pipeline, FIFO window and video (defined in the .cpp)

 private:
  RenderedCamera(const MissionConfig& mission, const planning::OccupancyMap* map, std::uint64_t seed);
  using CameraPoses = SceneRenderer::Poses;
  /// Renders UAV `i`'s camera at `T_world_camera` (serial: one GL context).
  CameraResult renderCamera(std::size_t i, double t_s, const Eigen::Isometry3d& T_world_camera, double extra_render_ms);
  /// UAV `i`'s pipeline on its rendered image (touches only camera i and `r`: may run concurrently).
  void runPipeline(std::size_t i, double t_s, CameraResult& r);
  /// Every wanted camera: rendered, through its pipeline, recorded against the truth.
  void processCameras(double t_s, const WorkerState& ws, std::vector<CameraResult>& results, const std::vector<bool>& wanted,
                      const CameraPoses& cameras, double pose_ms);
  /// The leader's sensor frame: the pipeline's box, the stereo range in it, synthetic UWB, faults.
  SensorFrame leaderSensors(double t_s, const CameraResult& leader, bool blackout, const MultirotorState& state,
                            const WorkerState& ws, int& range_outliers);

  const MissionConfig& cfg_;
  estimation::CameraIntrinsics intrinsics_;  ///< the mission's camera, distortion 0 (rectified)
  RenderedCameraConfig config_;
  std::unique_ptr<SceneRenderer> scene_;  ///< the world, the worker mesh, the UAVs (shared with the SimCamera nodelet)
  std::vector<std::unique_ptr<Camera>> cameras_;  ///< [0] leader, [i] follower i
  SyntheticSensors uwb_;        ///< the leader's UWB range (its box and stereo outputs are not used)
  std::mt19937_64 fault_rng_;
  std::uint64_t seed_;
  std::vector<PerceptionRecord> records_;
  std::string error_;  ///< the first rendering / pipeline failure during the mission

 public:
  /// \brief The first failure of a frame (rendering, perception) during the mission; empty when
  /// none. A failed frame counts as "worker not found"; the caller must report it.
  const std::string& error() const { return error_; }
};

}  // namespace gesture_formation::sim

#pragma once
/// \file
/// \brief The leader's camera in simulation, as `gfctl simulate` (sim::runMission) and the
/// ROS SimWorld nodelet both run it: one frame = the worker's box, stereo and UWB ranges seen
/// from the leader's **true** camera pose (SyntheticSensors) with the mission's injected
/// sensor faults (camera blackouts, UWB / stereo dropouts, range outliers), the worker's
/// skeleton from that viewpoint (WorkerModel::skeletonAt), and — when the worker is detected —
/// the skeleton FIFO (cleared after a gap of more than kSkeletonGapS) and the gesture
/// classifier on a full window (docs/simulation.md §1 "sensing", "gestures").
/// Plus StepSchedule, the fixed-step schedule of the camera frames and timeline samples.
/// Deterministic for the seed: the random streams are (seed, kCamera / kStereo / kUwb /
/// kFault), and every frame draws the same number of fault numbers.
/// Thread safety: none (owns RNGs and the FIFO).

#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/gesture/gesture_classifier.hpp"
#include "gesture_formation/sim/camera_source.hpp"
#include "gesture_formation/sim/mission_config.hpp"
#include "gesture_formation/sim/multirotor.hpp"
#include "gesture_formation/sim/synthetic_sensors.hpp"
#include "gesture_formation/sim/worker_model.hpp"

namespace gesture_formation::planning {
class OccupancyMap;
}  // namespace gesture_formation::planning

namespace gesture_formation::sim {

/// \brief The gesture classifier as the mission calls it (the ONNX LSTM in the product).
class MissionClassifier {
 public:
  virtual ~MissionClassifier() = default;
  virtual common::Result<gesture::Classification> classify(const gesture::SkeletonWindow& window) = 0;
  /// \brief The windows of one camera frame (one per UAV that sees the worker), classified:
  /// element i is what classify(*windows[i]) gives (nullopt when it fails). The default calls
  /// classify() in order; an implementation may classify them concurrently — each UAV runs
  /// its own classifier on its own computer — but must return exactly the same values.
  virtual std::vector<std::optional<gesture::Classification>> classifyAll(
      const std::vector<const gesture::SkeletonWindow*>& windows);
};
/// \brief The most threads loadOnnxClassifier accepts (one per UAV's camera is the useful most).
inline constexpr int kMaxClassifierThreads = 16;
/// \brief Loads the ONNX LSTM (gesture::GestureClassifier). `threads` ≥ 1: classifyAll runs
/// on up to that many threads, each with its own copy of the network (OpenCV's Net is not
/// re-entrant); the results do not depend on it (docs/simulation.md §3).
common::Result<std::unique_ptr<MissionClassifier>> loadOnnxClassifier(const std::string& onnx_path, int threads = 1);

/// \brief Fires at steps k = round(n · period_s / step_s), n = 0, 1, 2, … of a clock that
/// advances in fixed steps of step_s (k = 0 at t = 0).
class StepSchedule {
 public:
  StepSchedule(double period_s, double step_s) : period_s_(period_s), step_s_(step_s) {}
  /// \brief True when step `k` is due (call with non-decreasing k; a due step is consumed).
  bool due(long k) {
    if (k < next_k_) return false;
    ++count_;
    next_k_ = std::lround(static_cast<double>(count_) * period_s_ / step_s_);
    return true;
  }

 private:
  double period_s_, step_s_;
  long next_k_ = 0, count_ = 0;
};

/// \brief The leader's injected range faults of `faults` at `t_s` (UWB / stereo dropout windows,
/// range outliers) applied to `frame`'s ranges; draws 6 numbers from `rng` every call (so the
/// stream never depends on the outcome). Returns the number of outliers injected. Shared by
/// every CameraSource.
int applyRangeFaults(const FaultConfig& faults, double t_s, SensorFrame& frame, std::mt19937_64& rng);

/// \brief The synthetic camera (the default CameraSource): boxes, ranges and skeletons from
/// ground truth (SyntheticSensors, WorkerModel::skeletonsAt).
class LeaderCamera : public CameraSource {
 public:
  /// \brief Time between skeletons after which the FIFO restarts (temporal consistency).
  static constexpr double kSkeletonGapS = 0.5;

  /// \brief `config` must outlive this; `map` (occlusion; may be null) too.
  LeaderCamera(const MissionConfig& config, const planning::OccupancyMap* map, std::uint64_t seed);

  /// \brief The frame at `t_s` (call at the camera rate, times increasing) of the camera on
  /// the leader's true state `leader`, of the worker whose truth at t_s is `worker_state`
  /// (`worker` advances its motions: it must be the model that gave worker_state).
  /// `classifier` may be null (no gesture pipeline).
  LeaderCameraFrame frame(double t_s, const MultirotorState& leader, const WorkerState& worker_state,
                          WorkerModel& worker, MissionClassifier* classifier);
  /// \brief The same frame also seen by the followers' cameras (`followers[i]`: follower i+1's
  /// true state; `online[i]` false: its computer is down, no view). The followers' cameras
  /// see the same performance (WorkerModel::skeletonsAt) with their own field of view,
  /// occlusion, detection dropouts (streams kFollowerCamera + i) and FIFO; the injected
  /// leader faults (camera blackouts, range faults) are the leader's only. With no followers
  /// this is exactly frame() above. Pass the same number of followers at every call.
  LeaderCameraFrame frame(double t_s, const MultirotorState& leader, const std::vector<MultirotorState>& followers,
                          const std::vector<bool>& online, const WorkerState& worker_state, WorkerModel& worker,
                          MissionClassifier* classifier) override;

  /// \brief Time of the last frame in which the worker was detected (−1e9: never).
  double lastVisibleS() const override { return last_visible_s_; }

 private:
  const MissionConfig& cfg_;
  SyntheticSensors sensors_;
  std::mt19937_64 fault_rng_;
  gesture::SkeletonWindow window_;
  double last_visible_s_ = -1e9;
  struct FollowerCamera {
    SyntheticSensors sensors;
    gesture::SkeletonWindow window;
    double last_visible_s = -1e9;
  };
  const planning::OccupancyMap* map_;
  std::uint64_t seed_;
  std::vector<FollowerCamera> follower_cams_;
};

}  // namespace gesture_formation::sim

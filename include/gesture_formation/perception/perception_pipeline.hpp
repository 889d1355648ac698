#pragma once
/// \file
/// \brief The whole detection layer for one camera (docs/design.md §2): person detector ⇄ visual
/// tracker → skeleton extractor on the worker's box → FIFO of N normalised skeletons.

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/perception/blazepose_detector.hpp"
#include "gesture_formation/perception/movenet_multipose_detector.hpp"
#include "gesture_formation/perception/dnn_model.hpp"
#include "gesture_formation/perception/skeleton_extractor.hpp"
#include "gesture_formation/perception/skeleton_fifo.hpp"
#include "gesture_formation/perception/worker_tracker.hpp"

namespace gesture_formation::perception {

/// \brief Configuration of the pipeline. Model paths are relative to `models_root` unless
/// absolute; the defaults are the committed files under third_party_models/.
struct PerceptionConfig {
  std::string models_root = "third_party_models";  ///< directory holding the model folders
  DetectorKind detector = DetectorKind::kMoveNetMultipose;       ///< default: finds distant people
  SkeletonKind skeleton = SkeletonKind::kMoveNetLightning;       ///< default: 2× faster, see docs
  BlazePoseDetectorConfig blazepose_detector;
  MoveNetMultiposeConfig multipose;
  MoveNetLightningConfig lightning;
  BlazePoseLandmarkConfig blazepose_landmark;
  WorkerTrackerConfig tracker;
  int fifo_frames = kDefaultFifoFrames;  ///< N, ≥ 1
  DnnDevice dnn_device = DnnDevice::kCpu;  ///< where every network of the pipeline runs (dnn_model.hpp)

  /// Every problem of every sub-config, each naming the field and value.
  std::vector<std::string> validate() const;
};

/// \brief One frame's output.
struct PerceptionFrame {
  TrackStep track;               ///< box, id, detections, detector/tracker timings
  bool has_skeleton = false;     ///< `skeleton` is valid (worker found and extraction ran)
  Skeleton skeleton{};           ///< image pixels
  double skeleton_ms = 0.0;      ///< skeleton extraction wall time [ms]
  double total_ms = 0.0;         ///< whole step wall time [ms]
  bool fifo_full = false;        ///< the FIFO holds N frames of the current id
};

/// \brief Detector–tracker–skeleton pipeline. Thread safety: not reentrant.
class PerceptionPipeline {
 public:
  /// Builds every stage; fails with all configuration problems or the first model error.
  static common::Result<std::unique_ptr<PerceptionPipeline>> create(const PerceptionConfig& config);

  /// \brief Processes the next frame. The FIFO is cleared when the worker is lost or the
  /// identity changes (a window never mixes two people or a gap).
  common::Result<PerceptionFrame> step(const cv::Mat& frame_bgr);

  /// The classifier input [N][51] (empty until N frames of one identity are buffered).
  std::vector<float> classifierInput() const { return fifo_.tensor(); }
  const SkeletonFifo& fifo() const { return fifo_; }
  WorkerTracker& tracker() { return *tracker_; }
  SkeletonExtractor& skeletonExtractor() { return *skeleton_; }
  void reset();

 private:
  PerceptionPipeline(std::unique_ptr<WorkerTracker> tracker, std::unique_ptr<SkeletonExtractor> skeleton, int n);
  std::unique_ptr<WorkerTracker> tracker_;
  std::unique_ptr<SkeletonExtractor> skeleton_;
  SkeletonFifo fifo_;
};

/// \brief Builds the configured detector (for tests and benchmarks).
common::Result<std::unique_ptr<PersonDetector>> makePersonDetector(const PerceptionConfig& config);
/// \brief Builds the configured skeleton extractor.
common::Result<std::unique_ptr<SkeletonExtractor>> makeSkeletonExtractor(const PerceptionConfig& config);

}  // namespace gesture_formation::perception

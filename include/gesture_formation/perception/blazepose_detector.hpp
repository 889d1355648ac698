#pragma once
/// \file
/// \brief MediaPipe BlazePose person detector (pose_detection, 224×224 SSD) through OpenCV
/// DNN: anchor generation, box/keypoint decoding and weighted NMS exactly as
/// docs/perception_models.md §"BlazePose detector" and
/// third_party_models/blazepose_detector/anchors.json.
///
/// The network detects the *face* box plus 4 body keypoints (0 mid-hip centre, 1 full-body
/// circle point, 2 mid-shoulder centre, 3 upper-body circle point). The person box reported
/// in `Detection::box_px` is the axis-aligned square around the full-body circle
/// (centre kp0, radius |kp1 − kp0|), clipped to the image; `Detection::roi` is MediaPipe's
/// rotated landmark ROI (side 2·|kp1 − kp0|·1.25).

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/perception/dnn_model.hpp"
#include "gesture_formation/perception/person_detector.hpp"

namespace gesture_formation::perception {

/// \brief One SSD anchor, normalised to the 224×224 input.
struct Anchor {
  float x_center = 0.0f, y_center = 0.0f, w = 1.0f, h = 1.0f;
};

/// \brief The 2254 anchors of pose_detection (MediaPipe SsdAnchorsCalculator with the
/// options of anchors.json: strides 8,16,32,32,32, 2 anchors per layer, fixed size 1).
std::vector<Anchor> blazePoseAnchors();

/// \brief A decoded raw detection, normalised to the 224×224 letterboxed input.
struct BlazePoseRaw {
  int anchor = -1;
  float score = 0.0f;
  cv::Rect2f face_box;              ///< normalised (x, y, w, h)
  std::array<cv::Point2f, 4> kp{};  ///< normalised keypoints 0..3
};

/// \brief Decodes every anchor with score ≥ `min_score` (best first; ties by anchor index).
/// `regressors`: 2254×12 floats, `classificators`: 2254 floats (raw network outputs).
std::vector<BlazePoseRaw> decodeBlazePose(const float* regressors, const float* classificators,
                                          const std::vector<Anchor>& anchors, float min_score);

/// \brief MediaPipe's WEIGHTED non-maximum suppression: the best remaining detection and all
/// remaining ones overlapping it with IoU > `iou_threshold` are replaced by their
/// score-weighted mean (box and keypoints; score of the best). Input best first.
std::vector<BlazePoseRaw> weightedNms(const std::vector<BlazePoseRaw>& sorted, float iou_threshold);

/// \brief Configuration of `BlazePoseDetector`.
struct BlazePoseDetectorConfig {
  /// ONNX file, relative to the models root unless absolute.
  std::string model_path = "blazepose_detector/pose_detection.onnx";
  DnnDevice device = DnnDevice::kCpu;  ///< where the network runs (PerceptionConfig::dnn_device sets it)
  float min_score = 0.5f;      ///< anchors below are dropped, (0, 1); MediaPipe 0.5
  float nms_iou = 0.3f;        ///< weighted-NMS IoU threshold, (0, 1); MediaPipe 0.3
  int max_detections = 5;      ///< people kept after NMS, ≥ 1 (MediaPipe keeps 1)

  /// Every problem, each naming the field and value. Empty when valid.
  std::vector<std::string> validate() const;
};

/// \brief BlazePose SSD person detector. Thread safety: not reentrant (owns a Net).
class BlazePoseDetector final : public PersonDetector {
 public:
  /// Loads the model; fails with the reason (invalid config, missing/corrupt file).
  static common::Result<std::unique_ptr<BlazePoseDetector>> create(const BlazePoseDetectorConfig& config,
                                                                   const std::string& models_root);

  common::Result<std::vector<Detection>> detect(const cv::Mat& image_bgr) override;
  std::string name() const override { return "blazepose"; }

  /// Raw outputs of the last `detect` (for tests): regressors [1,2254,12], classificators [1,2254,1].
  const std::vector<cv::Mat>& lastOutputs() const { return outputs_; }

 private:
  BlazePoseDetector(BlazePoseDetectorConfig config, cv::dnn::Net net);
  BlazePoseDetectorConfig config_;
  cv::dnn::Net net_;
  std::vector<Anchor> anchors_;
  std::vector<cv::Mat> outputs_;
};

}  // namespace gesture_formation::perception

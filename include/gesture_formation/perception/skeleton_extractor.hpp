#pragma once
/// \file
/// \brief `SkeletonExtractor`: 17 COCO keypoints of the person inside a box (docs/design.md §2).
/// Two implementations: MoveNet lightning on a square crop (the default —
/// docs/perception.md says why) and BlazePose landmark full (33 points mapped to COCO-17).

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/perception/dnn_model.hpp"
#include "gesture_formation/perception/types.hpp"

namespace gesture_formation::perception {

/// \brief Interface of a skeleton extractor. Thread safety: not reentrant (owns a Net).
class SkeletonExtractor {
 public:
  virtual ~SkeletonExtractor() = default;
  SkeletonExtractor() = default;
  SkeletonExtractor(const SkeletonExtractor&) = delete;
  SkeletonExtractor& operator=(const SkeletonExtractor&) = delete;

  /// \brief Keypoints of the person in `box_px` of `image_bgr` (8-bit, 3 channels), in
  /// image pixels with confidences 0..1. The crop may extend past the image border (zero
  /// padding). Fails with a reason for a bad image, an empty/non-finite box or a network
  /// error.
  virtual common::Result<Skeleton> extract(const cv::Mat& image_bgr, const cv::Rect2f& box_px) = 0;

  /// \brief As `extract`, from a rotated ROI (e.g. BlazePose detector's). The default
  /// implementation uses the ROI's axis-aligned square.
  virtual common::Result<Skeleton> extractRoi(const cv::Mat& image_bgr, const RotatedSquare& roi);

  virtual std::string name() const = 0;
};

/// Which extractor to build.
enum class SkeletonKind { kMoveNetLightning, kBlazePoseLandmark };
common::Result<SkeletonKind> parseSkeletonKind(const std::string& text);
std::string toString(SkeletonKind kind);

// ---- MoveNet lightning ----------------------------------------------------------------

/// \brief MoveNet lightning raw heads (NCHW, batch dropped), grid 48×48.
struct LightningHeads {
  const float* kpt_heatmap = nullptr;      ///< [17][48][48]
  const float* center_weighted = nullptr;  ///< [1][48][48]
  const float* kpt_regress = nullptr;      ///< [34][48][48]
  const float* kpt_offset = nullptr;       ///< [34][48][48]
};

/// \brief The graph's final output: 17 × (y, x, score), y/x normalised to the 192×192 input
/// (docs/perception_models.md §"MoveNet lightning").
std::array<std::array<float, 3>, kNumKeypoints> decodeLightning(const LightningHeads& heads);

/// \brief Configuration of `MoveNetLightningExtractor`.
struct MoveNetLightningConfig {
  std::string model_path = "movenet_lightning/movenet_lightning.onnx";  ///< relative to the models root
  DnnDevice device = DnnDevice::kCpu;  ///< where the network runs (PerceptionConfig::dnn_device sets it)
  /// Side of the square crop as a multiple of max(box w, box h), ≥ 1; MoveNet's own
  /// cropping uses a margin of about 1.2–1.3.
  float crop_scale = 1.25f;
  float keypoint_min_score = 0.0f;  ///< confidences below are set to 0 (missing), [0, 1)

  std::vector<std::string> validate() const;
};

/// \brief MoveNet lightning (192×192) on a square crop centred on the box.
class MoveNetLightningExtractor final : public SkeletonExtractor {
 public:
  static constexpr int kInputSide = 192;
  static common::Result<std::unique_ptr<MoveNetLightningExtractor>> create(const MoveNetLightningConfig& config,
                                                                           const std::string& models_root);
  common::Result<Skeleton> extract(const cv::Mat& image_bgr, const cv::Rect2f& box_px) override;
  common::Result<Skeleton> extractRoi(const cv::Mat& image_bgr, const RotatedSquare& roi) override;
  std::string name() const override { return "movenet_lightning"; }

  /// Runs the network on an already cropped 192×192 BGR image; normalised (y, x, score).
  common::Result<std::array<std::array<float, 3>, kNumKeypoints>> runOnCrop(const cv::Mat& crop_bgr);
  /// Raw outputs of the last run: center_weighted, kpt_heatmap, kpt_offset, kpt_regress.
  const std::vector<cv::Mat>& lastOutputs() const { return outputs_; }
  static const std::vector<std::string>& outputNames();

 private:
  MoveNetLightningExtractor(MoveNetLightningConfig config, cv::dnn::Net net);
  MoveNetLightningConfig config_;
  cv::dnn::Net net_;
  std::vector<cv::Mat> outputs_;
  cv::Mat crop_;
};

// ---- BlazePose landmark full ------------------------------------------------------------

/// \brief BlazePose body landmark index of each COCO-17 keypoint
/// (docs/perception_models.md: 0,2,5,7,8,11,12,13,14,15,16,23,24,25,26,27,28).
const std::array<int, kNumKeypoints>& blazePoseToCoco();

/// \brief Configuration of `BlazePoseLandmarkExtractor`.
struct BlazePoseLandmarkConfig {
  std::string model_path = "blazepose_landmark_full/pose_landmark_full.onnx";  ///< relative to the models root
  DnnDevice device = DnnDevice::kCpu;  ///< where the network runs (PerceptionConfig::dnn_device sets it)
  /// ROI side as a multiple of max(box w, box h) when called with a box, ≥ 1.
  float crop_scale = 1.25f;
  float min_pose_flag = 0.5f;  ///< below: no person in the ROI → all confidences 0, [0, 1)

  std::vector<std::string> validate() const;
};

/// \brief BlazePose landmark full (256×256 rotated ROI) mapped to COCO-17; confidence =
/// sigmoid(visibility).
class BlazePoseLandmarkExtractor final : public SkeletonExtractor {
 public:
  static constexpr int kInputSide = 256;
  static common::Result<std::unique_ptr<BlazePoseLandmarkExtractor>> create(const BlazePoseLandmarkConfig& config,
                                                                            const std::string& models_root);
  common::Result<Skeleton> extract(const cv::Mat& image_bgr, const cv::Rect2f& box_px) override;
  common::Result<Skeleton> extractRoi(const cv::Mat& image_bgr, const RotatedSquare& roi) override;
  std::string name() const override { return "blazepose_landmark"; }

  /// Raw outputs of the last run: heatmap, landmarks, pose_flag, segmentation, world_landmarks.
  const std::vector<cv::Mat>& lastOutputs() const { return outputs_; }
  static const std::vector<std::string>& outputNames();
  /// Runs the network on an already warped 256×256 BGR ROI (for tests).
  common::Result<bool> runOnCrop(const cv::Mat& crop_bgr);

 private:
  BlazePoseLandmarkExtractor(BlazePoseLandmarkConfig config, cv::dnn::Net net);
  BlazePoseLandmarkConfig config_;
  cv::dnn::Net net_;
  std::vector<cv::Mat> outputs_;
  cv::Mat crop_;
};

}  // namespace gesture_formation::perception

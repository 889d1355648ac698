#pragma once
/// \file
/// \brief MoveNet multipose (256×256, up to 6 people with boxes and 17 keypoints) as a person
/// detector through OpenCV DNN. Decoding exactly as docs/perception_models.md
/// §"MoveNet multipose" (the TF graph's post-processing, reimplemented).

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/perception/dnn_model.hpp"
#include "gesture_formation/perception/person_detector.hpp"

namespace gesture_formation::perception {

/// \brief One multipose candidate, normalised to the S×S network input (the graph's
/// [1,6,56] row): keypoints (y, x, score), box (ymin, xmin, ymax, xmax), person score.
struct MultiposeCandidate {
  std::array<float, kNumKeypoints> y{}, x{}, score{};
  float ymin = 0.0f, xmin = 0.0f, ymax = 0.0f, xmax = 0.0f;
  float person_score = 0.0f;
};

/// \brief Raw heads of the multipose network (NCHW, batch dropped), grid H = W = S/4.
struct MultiposeHeads {
  const float* center_heatmap = nullptr;  ///< [1][H][W]
  const float* box_scale = nullptr;       ///< [2][H][W]
  const float* box_offset = nullptr;      ///< [2][H][W]
  const float* kpt_heatmap = nullptr;     ///< [17][H][W]
  const float* kpt_regress = nullptr;     ///< [34][H][W]
  const float* kpt_offset = nullptr;      ///< [34][H][W]
  int grid = 64;                          ///< H = W
};

/// \brief The 6 candidates in TopK order of the centre score (not sorted by person score).
std::vector<MultiposeCandidate> decodeMultipose(const MultiposeHeads& heads);

/// \brief Configuration of `MoveNetMultiposeDetector`.
struct MoveNetMultiposeConfig {
  /// ONNX file, relative to the models root unless absolute. Input size is fixed at 256.
  std::string model_path = "movenet_multipose/movenet_multipose.onnx";
  DnnDevice device = DnnDevice::kCpu;  ///< where the network runs (PerceptionConfig::dnn_device sets it)
  float min_person_score = 0.2f;  ///< candidates below are not people, (0, 1)
  float min_box_px = 4.0f;        ///< boxes narrower or lower than this [image px] are dropped, ≥ 0
  float keypoint_min_score = 0.0f;  ///< keypoint confidences below are set to 0, [0, 1)

  /// Every problem, each naming the field and value. Empty when valid.
  std::vector<std::string> validate() const;
};

/// \brief MoveNet multipose person detector. Thread safety: not reentrant (owns a Net).
class MoveNetMultiposeDetector final : public PersonDetector {
 public:
  static constexpr int kInputSide = 256;  ///< network input [px]

  /// Loads the model; fails with the reason (invalid config, missing/corrupt file).
  static common::Result<std::unique_ptr<MoveNetMultiposeDetector>> create(const MoveNetMultiposeConfig& config,
                                                                          const std::string& models_root);

  common::Result<std::vector<Detection>> detect(const cv::Mat& image_bgr) override;
  std::string name() const override { return "movenet_multipose"; }

  /// Raw outputs of the last `detect`, in the order box_offset, box_scale, center_heatmap,
  /// kpt_heatmap, kpt_offset, kpt_regress (for tests).
  const std::vector<cv::Mat>& lastOutputs() const { return outputs_; }
  static const std::vector<std::string>& outputNames();

 private:
  MoveNetMultiposeDetector(MoveNetMultiposeConfig config, cv::dnn::Net net);
  MoveNetMultiposeConfig config_;
  cv::dnn::Net net_;
  std::vector<cv::Mat> outputs_;
};

}  // namespace gesture_formation::perception

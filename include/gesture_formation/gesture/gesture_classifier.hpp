#pragma once
/// \file
/// \brief The gesture classifier: an LSTM over the last N = 9 box-normalised skeletons
/// (docs/design.md §2), trained by tools/train_gesture_lstm.py and run by OpenCV DNN from ONNX.

#include <array>
#include <deque>
#include <string>

#include <opencv2/dnn.hpp>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/gesture/skeleton.hpp"

namespace gesture_formation::gesture {

/// \brief Classifier output: the argmax id and the five class probabilities.
struct Classification {
  int gesture_id = kNone;
  std::array<float, kNumGestureClasses> probabilities{};
};

/// \brief FIFO of the last kWindowFrames skeletons. Thread safety: none.
class SkeletonWindow {
 public:
  void push(const Skeleton2D& s) {
    frames_.push_back(s);
    if (frames_.size() > static_cast<std::size_t>(kWindowFrames)) frames_.pop_front();
  }
  void clear() { frames_.clear(); }
  bool full() const { return frames_.size() == static_cast<std::size_t>(kWindowFrames); }
  std::size_t size() const { return frames_.size(); }
  /// Writes kWindowFrames × kFeaturesPerFrame floats, oldest frame first. Requires full().
  void features(float* out) const {
    for (std::size_t i = 0; i < frames_.size(); ++i) boxNormalizedFeatures(frames_[i], out + i * kFeaturesPerFrame);
  }

 private:
  std::deque<Skeleton2D> frames_;
};

/// \brief Runs the ONNX LSTM (input [1, 9, 51] float, output [1, 5] probabilities).
/// Thread safety: classify() is not reentrant (one cv::dnn::Net per thread).
class GestureClassifier {
 public:
  /// Loads and checks the model (a test inference on zeros must give 5 probabilities).
  static common::Result<GestureClassifier> load(const std::string& onnx_path);

  /// Classifies one window: kWindowFrames × kFeaturesPerFrame floats, oldest frame first.
  common::Result<Classification> classify(const float* window);
  /// Classifies the window's content; fails when the window is not full.
  common::Result<Classification> classify(const SkeletonWindow& window);

 private:
  explicit GestureClassifier(cv::dnn::Net net) : net_(std::move(net)) {}
  cv::dnn::Net net_;
};

}  // namespace gesture_formation::gesture

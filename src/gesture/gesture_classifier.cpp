#include "gesture_formation/gesture/gesture_classifier.hpp"

#include <cmath>
#include <fstream>
#include <vector>

namespace gesture_formation::gesture {

common::Result<GestureClassifier> GestureClassifier::load(const std::string& onnx_path) {
  using R = common::Result<GestureClassifier>;
  if (!std::ifstream(onnx_path).good()) return R::fail("gesture model '" + onnx_path + "': cannot open file");
  cv::dnn::Net net;
  try {
    net = cv::dnn::readNetFromONNX(onnx_path);
  } catch (const cv::Exception& e) {
    return R::fail("gesture model '" + onnx_path + "': OpenCV cannot load it: " + e.what());
  }
  if (net.empty()) return R::fail("gesture model '" + onnx_path + "': empty network");
  net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  GestureClassifier c(net);
  std::vector<float> zeros(static_cast<std::size_t>(kWindowFrames * kFeaturesPerFrame), 0.0f);
  const auto probe = c.classify(zeros.data());
  if (!probe) return R::fail("gesture model '" + onnx_path + "': " + probe.reason());
  return R::ok(c);
}

common::Result<Classification> GestureClassifier::classify(const float* window) {
  using R = common::Result<Classification>;
  const int sizes[] = {1, kWindowFrames, kFeaturesPerFrame};
  // OpenCV copies the input into its own blob; the const_cast never writes.
  cv::Mat blob(3, sizes, CV_32F, const_cast<float*>(window));
  cv::Mat out;
  try {
    net_.setInput(blob);
    out = net_.forward();
  } catch (const cv::Exception& e) {
    return R::fail(std::string("inference failed: ") + e.what());
  }
  if (out.total() != static_cast<std::size_t>(kNumGestureClasses) || out.type() != CV_32F) {
    return R::fail("model output has " + std::to_string(out.total()) + " values, expected " +
                   std::to_string(kNumGestureClasses));
  }
  Classification c;
  const float* p = out.ptr<float>();
  for (int i = 0; i < kNumGestureClasses; ++i) {
    if (!std::isfinite(p[i])) return R::fail("model output is not finite");
    c.probabilities[static_cast<std::size_t>(i)] = p[i];
    if (p[i] > c.probabilities[static_cast<std::size_t>(c.gesture_id)]) c.gesture_id = i;
  }
  return R::ok(c);
}

common::Result<Classification> GestureClassifier::classify(const SkeletonWindow& window) {
  if (!window.full()) {
    return common::Result<Classification>::fail("window holds " + std::to_string(window.size()) + " of " +
                                                 std::to_string(kWindowFrames) + " frames");
  }
  float features[kWindowFrames * kFeaturesPerFrame];
  window.features(features);
  return classify(features);
}

}  // namespace gesture_formation::gesture

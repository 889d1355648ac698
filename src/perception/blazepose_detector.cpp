#include "gesture_formation/perception/blazepose_detector.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "gesture_formation/perception/dnn_model.hpp"

namespace gesture_formation::perception {

namespace {
constexpr int kInputSide = 224;
constexpr int kNumAnchors = 2254;
constexpr int kNumCoords = 12;
constexpr float kPi = 3.14159265358979f;
}  // namespace

std::vector<Anchor> blazePoseAnchors() {
  // MediaPipe SsdAnchorsCalculator, options of anchors.json: layers of equal stride are
  // grouped; each layer gives 1 anchor per aspect ratio (1.0) + 1 interpolated anchor.
  const int strides[] = {8, 16, 32, 32, 32};
  const int num_layers = 5;
  std::vector<Anchor> anchors;
  anchors.reserve(kNumAnchors);
  int layer = 0;
  while (layer < num_layers) {
    int last = layer;
    int per_cell = 0;
    while (last < num_layers && strides[last] == strides[layer]) {
      per_cell += 2;
      ++last;
    }
    const int fm = static_cast<int>(std::ceil(static_cast<double>(kInputSide) / strides[layer]));
    for (int y = 0; y < fm; ++y) {
      for (int x = 0; x < fm; ++x) {
        for (int a = 0; a < per_cell; ++a) {
          anchors.push_back({(static_cast<float>(x) + 0.5f) / static_cast<float>(fm),
                             (static_cast<float>(y) + 0.5f) / static_cast<float>(fm), 1.0f, 1.0f});
        }
      }
    }
    layer = last;
  }
  return anchors;
}

std::vector<BlazePoseRaw> decodeBlazePose(const float* regressors, const float* classificators,
                                          const std::vector<Anchor>& anchors, float min_score) {
  std::vector<BlazePoseRaw> out;
  const float s = static_cast<float>(kInputSide);
  for (std::size_t i = 0; i < anchors.size(); ++i) {
    const float logit = std::clamp(classificators[i], -100.0f, 100.0f);
    const float score = 1.0f / (1.0f + std::exp(-logit));
    if (!(score >= min_score)) continue;
    const float* r = regressors + i * kNumCoords;
    const Anchor& a = anchors[i];
    const float xc = r[0] / s * a.w + a.x_center;
    const float yc = r[1] / s * a.h + a.y_center;
    const float w = r[2] / s * a.w;
    const float h = r[3] / s * a.h;
    BlazePoseRaw d;
    d.anchor = static_cast<int>(i);
    d.score = score;
    d.face_box = cv::Rect2f(xc - w / 2, yc - h / 2, w, h);
    for (int k = 0; k < 4; ++k) {
      d.kp[static_cast<std::size_t>(k)] = {r[4 + 2 * k] / s * a.w + a.x_center, r[5 + 2 * k] / s * a.h + a.y_center};
    }
    out.push_back(d);
  }
  std::stable_sort(out.begin(), out.end(), [](const BlazePoseRaw& a, const BlazePoseRaw& b) { return a.score > b.score; });
  return out;
}

std::vector<BlazePoseRaw> weightedNms(const std::vector<BlazePoseRaw>& sorted, float iou_threshold) {
  std::vector<BlazePoseRaw> remaining = sorted, out;
  while (!remaining.empty()) {
    const BlazePoseRaw best = remaining.front();
    std::vector<BlazePoseRaw> rest;
    float total = 0.0f, x0 = 0.0f, y0 = 0.0f, x1 = 0.0f, y1 = 0.0f;
    std::array<cv::Point2f, 4> kp{};
    for (const auto& d : remaining) {
      if (iou(best.face_box, d.face_box) > iou_threshold || d.anchor == best.anchor) {
        total += d.score;
        x0 += d.score * d.face_box.x;
        y0 += d.score * d.face_box.y;
        x1 += d.score * (d.face_box.x + d.face_box.width);
        y1 += d.score * (d.face_box.y + d.face_box.height);
        for (std::size_t k = 0; k < 4; ++k) kp[k] += d.score * d.kp[k];
      } else {
        rest.push_back(d);
      }
    }
    BlazePoseRaw merged = best;
    if (total > 0.0f) {
      merged.face_box = cv::Rect2f(x0 / total, y0 / total, (x1 - x0) / total, (y1 - y0) / total);
      for (std::size_t k = 0; k < 4; ++k) merged.kp[k] = kp[k] / total;
    }
    out.push_back(merged);
    remaining.swap(rest);
  }
  return out;
}

std::vector<std::string> BlazePoseDetectorConfig::validate() const {
  std::vector<std::string> e;
  if (model_path.empty()) e.push_back("blazepose_detector.model_path must not be empty");
  if (!(min_score > 0.0f && min_score < 1.0f)) {
    e.push_back("blazepose_detector.min_score must be in (0, 1), got " + std::to_string(min_score));
  }
  if (!(nms_iou > 0.0f && nms_iou < 1.0f)) {
    e.push_back("blazepose_detector.nms_iou must be in (0, 1), got " + std::to_string(nms_iou));
  }
  if (max_detections < 1) {
    e.push_back("blazepose_detector.max_detections must be >= 1, got " + std::to_string(max_detections));
  }
  return e;
}

common::Result<std::unique_ptr<BlazePoseDetector>> BlazePoseDetector::create(const BlazePoseDetectorConfig& config,
                                                                             const std::string& models_root) {
  using R = common::Result<std::unique_ptr<BlazePoseDetector>>;
  const auto problems = config.validate();
  if (!problems.empty()) return R::fail(problems.front());
  auto net = loadOnnxModel(resolveModelPath(models_root, config.model_path), {"regressors", "classificators"}, config.device);
  if (!net) return R::fail(net.reason());
  return R::ok(std::unique_ptr<BlazePoseDetector>(new BlazePoseDetector(config, *net)));
}

BlazePoseDetector::BlazePoseDetector(BlazePoseDetectorConfig config, cv::dnn::Net net)
    : config_(std::move(config)), net_(std::move(net)), anchors_(blazePoseAnchors()) {}

common::Result<std::vector<Detection>> BlazePoseDetector::detect(const cv::Mat& image_bgr) {
  using R = common::Result<std::vector<Detection>>;
  const std::string bad = checkBgrImage(image_bgr);
  if (!bad.empty()) return R::fail("blazepose detector: " + bad);
  cv::Mat input;
  const Letterbox lb = letterboxImage(image_bgr, kInputSide, input);
  try {
    const cv::Mat blob = cv::dnn::blobFromImage(input, 1.0 / 127.5, cv::Size(kInputSide, kInputSide),
                                                cv::Scalar(127.5, 127.5, 127.5), /*swapRB=*/true, false, CV_32F);
    net_.setInput(blob);
    net_.forward(outputs_, std::vector<std::string>{"regressors", "classificators"});
  } catch (const cv::Exception& e) {
    return R::fail("blazepose detector: network forward failed: " + e.msg);
  }
  if (outputs_.size() != 2 || outputs_[0].total() != static_cast<std::size_t>(kNumAnchors * kNumCoords) ||
      outputs_[1].total() != static_cast<std::size_t>(kNumAnchors)) {
    return R::fail("blazepose detector: unexpected output sizes (wrong model file?)");
  }
  const auto raw = decodeBlazePose(outputs_[0].ptr<float>(), outputs_[1].ptr<float>(), anchors_, config_.min_score);
  auto merged = weightedNms(raw, config_.nms_iou);
  if (merged.size() > static_cast<std::size_t>(config_.max_detections)) merged.resize(static_cast<std::size_t>(config_.max_detections));

  std::vector<Detection> out;
  const cv::Rect2f image_rect(0.0f, 0.0f, static_cast<float>(image_bgr.cols), static_cast<float>(image_bgr.rows));
  for (const auto& m : merged) {
    const auto to_img = [&](const cv::Point2f& p) { return lb.toImage(p * static_cast<float>(kInputSide)); };
    const cv::Point2f hip = to_img(m.kp[0]), full = to_img(m.kp[1]);
    const float r = static_cast<float>(cv::norm(full - hip));
    Detection d;
    d.score = m.score;
    d.box_px = cv::Rect2f(hip.x - r, hip.y - r, 2 * r, 2 * r) & image_rect;
    d.has_roi = true;
    d.roi.center_px = hip;
    d.roi.side_px = 2.0f * r * 1.25f;
    float rot = 0.5f * kPi - std::atan2(-(full.y - hip.y), full.x - hip.x);
    rot = rot - 2.0f * kPi * std::floor((rot + kPi) / (2.0f * kPi));
    d.roi.rotation_rad = rot;
    if (d.box_px.width > 0 && d.box_px.height > 0) out.push_back(d);
  }
  return R::ok(std::move(out));
}

}  // namespace gesture_formation::perception

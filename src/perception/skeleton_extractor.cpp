#include "gesture_formation/perception/skeleton_extractor.hpp"

#include <algorithm>
#include <cmath>

#include "gesture_formation/perception/dnn_model.hpp"

namespace gesture_formation::perception {

namespace {
constexpr int kLightningGrid = 48;
constexpr float kLightningDistanceBias = 1.7998047f;  // fp16 1.8 in the graph
constexpr float kLightningInvGrid = 0.020828247f;     // fp16 1/48 in the graph

/// Square ROI around a box: centre of the box, side = max(w, h) · scale.
common::Result<RotatedSquare> squareAround(const cv::Rect2f& box, float scale) {
  if (!(std::isfinite(box.x) && std::isfinite(box.y) && std::isfinite(box.width) && std::isfinite(box.height)) ||
      !(box.width > 0.0f && box.height > 0.0f)) {
    return common::Result<RotatedSquare>::fail("box must be finite with w > 0 and h > 0, got (" + std::to_string(box.x) +
                                               ", " + std::to_string(box.y) + ", " + std::to_string(box.width) + ", " +
                                               std::to_string(box.height) + ")");
  }
  RotatedSquare r;
  r.center_px = {box.x + box.width / 2, box.y + box.height / 2};
  r.side_px = std::max(box.width, box.height) * scale;
  return common::Result<RotatedSquare>::ok(r);
}

std::string checkRoi(const RotatedSquare& roi) {
  if (!(std::isfinite(roi.center_px.x) && std::isfinite(roi.center_px.y) && std::isfinite(roi.rotation_rad) &&
        std::isfinite(roi.side_px) && roi.side_px > 0.0f)) {
    return "ROI must be finite with side > 0, got side " + std::to_string(roi.side_px);
  }
  return {};
}

float sigmoid(float v) { return 1.0f / (1.0f + std::exp(-v)); }
}  // namespace

common::Result<Skeleton> SkeletonExtractor::extractRoi(const cv::Mat& image_bgr, const RotatedSquare& roi) {
  const std::string bad = checkRoi(roi);
  if (!bad.empty()) return common::Result<Skeleton>::fail(name() + ": " + bad);
  const float h = roi.side_px / 2;
  return extract(image_bgr, cv::Rect2f(roi.center_px.x - h, roi.center_px.y - h, roi.side_px, roi.side_px));
}

common::Result<SkeletonKind> parseSkeletonKind(const std::string& text) {
  if (text == "movenet_lightning") return common::Result<SkeletonKind>::ok(SkeletonKind::kMoveNetLightning);
  if (text == "blazepose_landmark") return common::Result<SkeletonKind>::ok(SkeletonKind::kBlazePoseLandmark);
  return common::Result<SkeletonKind>::fail("skeleton must be movenet_lightning or blazepose_landmark, got '" + text + "'");
}

std::string toString(SkeletonKind kind) {
  return kind == SkeletonKind::kMoveNetLightning ? "movenet_lightning" : "blazepose_landmark";
}

// ---- MoveNet lightning ------------------------------------------------------------------

std::array<std::array<float, 3>, kNumKeypoints> decodeLightning(const LightningHeads& h) {
  constexpr int g = kLightningGrid;
  const auto at = [](const float* base, int channel, int y, int x) { return base[(channel * g + y) * g + x]; };
  int c = 0;
  for (int i = 1; i < g * g; ++i) {
    if (h.center_weighted[i] > h.center_weighted[c]) c = i;
  }
  const int cy = c / g, cx = c % g;
  std::array<std::array<float, 3>, kNumKeypoints> out{};
  for (int k = 0; k < kNumKeypoints; ++k) {
    const float ry = static_cast<float>(cy) + at(h.kpt_regress, 2 * k, cy, cx);
    const float rx = static_cast<float>(cx) + at(h.kpt_regress, 2 * k + 1, cy, cx);
    int best = 0;
    float best_v = -1e30f;
    for (int y = 0; y < g; ++y) {
      for (int x = 0; x < g; ++x) {
        const float dy = static_cast<float>(y) - ry, dx = static_cast<float>(x) - rx;
        const float v = at(h.kpt_heatmap, k, y, x) / (std::sqrt(dy * dy + dx * dx) + kLightningDistanceBias);
        if (v > best_v) {
          best_v = v;
          best = y * g + x;
        }
      }
    }
    const int ky = best / g, kx = best % g;
    auto& o = out[static_cast<std::size_t>(k)];
    o[0] = (static_cast<float>(ky) + at(h.kpt_offset, 2 * k, ky, kx)) * kLightningInvGrid;
    o[1] = (static_cast<float>(kx) + at(h.kpt_offset, 2 * k + 1, ky, kx)) * kLightningInvGrid;
    o[2] = at(h.kpt_heatmap, k, ky, kx);
  }
  return out;
}

std::vector<std::string> MoveNetLightningConfig::validate() const {
  std::vector<std::string> e;
  if (model_path.empty()) e.push_back("lightning.model_path must not be empty");
  if (!(crop_scale >= 1.0f && crop_scale < 10.0f)) {
    e.push_back("lightning.crop_scale must be in [1, 10), got " + std::to_string(crop_scale));
  }
  if (!(keypoint_min_score >= 0.0f && keypoint_min_score < 1.0f)) {
    e.push_back("lightning.keypoint_min_score must be in [0, 1), got " + std::to_string(keypoint_min_score));
  }
  return e;
}

const std::vector<std::string>& MoveNetLightningExtractor::outputNames() {
  static const std::vector<std::string> names = {"center_weighted", "kpt_heatmap", "kpt_offset", "kpt_regress"};
  return names;
}

common::Result<std::unique_ptr<MoveNetLightningExtractor>> MoveNetLightningExtractor::create(
    const MoveNetLightningConfig& config, const std::string& models_root) {
  using R = common::Result<std::unique_ptr<MoveNetLightningExtractor>>;
  const auto problems = config.validate();
  if (!problems.empty()) return R::fail(problems.front());
  auto net = loadOnnxModel(resolveModelPath(models_root, config.model_path), outputNames(), config.device);
  if (!net) return R::fail(net.reason());
  return R::ok(std::unique_ptr<MoveNetLightningExtractor>(new MoveNetLightningExtractor(config, *net)));
}

MoveNetLightningExtractor::MoveNetLightningExtractor(MoveNetLightningConfig config, cv::dnn::Net net)
    : config_(std::move(config)), net_(std::move(net)) {}

common::Result<std::array<std::array<float, 3>, kNumKeypoints>> MoveNetLightningExtractor::runOnCrop(const cv::Mat& crop) {
  using R = common::Result<std::array<std::array<float, 3>, kNumKeypoints>>;
  const std::string bad = checkBgrImage(crop, "crop");
  if (!bad.empty()) return R::fail("movenet_lightning: " + bad);
  try {
    const cv::Mat blob = cv::dnn::blobFromImage(crop, 1.0, cv::Size(kInputSide, kInputSide), cv::Scalar(), true, false, CV_32F);
    net_.setInput(blob);
    net_.forward(outputs_, outputNames());
  } catch (const cv::Exception& e) {
    return R::fail("movenet_lightning: network forward failed: " + e.msg);
  }
  constexpr std::size_t cells = kLightningGrid * kLightningGrid;
  if (outputs_.size() != 4 || outputs_[0].total() != cells || outputs_[1].total() != 17 * cells ||
      outputs_[2].total() != 34 * cells || outputs_[3].total() != 34 * cells) {
    return R::fail("movenet_lightning: unexpected output sizes (wrong model file?)");
  }
  LightningHeads heads;
  heads.center_weighted = outputs_[0].ptr<float>();
  heads.kpt_heatmap = outputs_[1].ptr<float>();
  heads.kpt_offset = outputs_[2].ptr<float>();
  heads.kpt_regress = outputs_[3].ptr<float>();
  return R::ok(decodeLightning(heads));
}

common::Result<Skeleton> MoveNetLightningExtractor::extract(const cv::Mat& image_bgr, const cv::Rect2f& box_px) {
  const auto roi = squareAround(box_px, config_.crop_scale);
  if (!roi) return common::Result<Skeleton>::fail("movenet_lightning: " + roi.reason());
  return extractRoi(image_bgr, *roi);
}

common::Result<Skeleton> MoveNetLightningExtractor::extractRoi(const cv::Mat& image_bgr, const RotatedSquare& roi) {
  using R = common::Result<Skeleton>;
  const std::string bad = checkBgrImage(image_bgr);
  if (!bad.empty()) return R::fail("movenet_lightning: " + bad);
  const std::string bad_roi = checkRoi(roi);
  if (!bad_roi.empty()) return R::fail("movenet_lightning: " + bad_roi);
  warpSquare(image_bgr, roi.center_px, roi.side_px, roi.rotation_rad, kInputSide, crop_);
  const auto kps = runOnCrop(crop_);
  if (!kps) return R::fail(kps.reason());
  Skeleton s{};
  const float side = static_cast<float>(kInputSide);
  for (std::size_t k = 0; k < static_cast<std::size_t>(kNumKeypoints); ++k) {
    const auto& o = (*kps)[k];
    if (!(o[2] > 0.0f) || o[2] < config_.keypoint_min_score) continue;
    const cv::Point2f p = squareToImage({o[1] * side, o[0] * side}, roi.center_px, roi.side_px, roi.rotation_rad, kInputSide);
    s[k] = {p.x, p.y, std::min(o[2], 1.0f)};
  }
  return R::ok(s);
}

// ---- BlazePose landmark full --------------------------------------------------------------

const std::array<int, kNumKeypoints>& blazePoseToCoco() {
  static const std::array<int, kNumKeypoints> map = {0, 2, 5, 7, 8, 11, 12, 13, 14, 15, 16, 23, 24, 25, 26, 27, 28};
  return map;
}

std::vector<std::string> BlazePoseLandmarkConfig::validate() const {
  std::vector<std::string> e;
  if (model_path.empty()) e.push_back("blazepose_landmark.model_path must not be empty");
  if (!(crop_scale >= 1.0f && crop_scale < 10.0f)) {
    e.push_back("blazepose_landmark.crop_scale must be in [1, 10), got " + std::to_string(crop_scale));
  }
  if (!(min_pose_flag >= 0.0f && min_pose_flag < 1.0f)) {
    e.push_back("blazepose_landmark.min_pose_flag must be in [0, 1), got " + std::to_string(min_pose_flag));
  }
  return e;
}

const std::vector<std::string>& BlazePoseLandmarkExtractor::outputNames() {
  static const std::vector<std::string> names = {"heatmap", "landmarks", "pose_flag", "segmentation", "world_landmarks"};
  return names;
}

common::Result<std::unique_ptr<BlazePoseLandmarkExtractor>> BlazePoseLandmarkExtractor::create(
    const BlazePoseLandmarkConfig& config, const std::string& models_root) {
  using R = common::Result<std::unique_ptr<BlazePoseLandmarkExtractor>>;
  const auto problems = config.validate();
  if (!problems.empty()) return R::fail(problems.front());
  auto net = loadOnnxModel(resolveModelPath(models_root, config.model_path), outputNames(), config.device);
  if (!net) return R::fail(net.reason());
  return R::ok(std::unique_ptr<BlazePoseLandmarkExtractor>(new BlazePoseLandmarkExtractor(config, *net)));
}

BlazePoseLandmarkExtractor::BlazePoseLandmarkExtractor(BlazePoseLandmarkConfig config, cv::dnn::Net net)
    : config_(std::move(config)), net_(std::move(net)) {}

common::Result<bool> BlazePoseLandmarkExtractor::runOnCrop(const cv::Mat& crop) {
  using R = common::Result<bool>;
  const std::string bad = checkBgrImage(crop, "crop");
  if (!bad.empty()) return R::fail("blazepose_landmark: " + bad);
  try {
    const cv::Mat blob = cv::dnn::blobFromImage(crop, 1.0 / 255.0, cv::Size(kInputSide, kInputSide), cv::Scalar(), true, false, CV_32F);
    net_.setInput(blob);
    net_.forward(outputs_, outputNames());
  } catch (const cv::Exception& e) {
    return R::fail("blazepose_landmark: network forward failed: " + e.msg);
  }
  if (outputs_.size() != 5 || outputs_[1].total() != 195 || outputs_[2].total() != 1) {
    return R::fail("blazepose_landmark: unexpected output sizes (wrong model file?)");
  }
  return R::ok(true);
}

common::Result<Skeleton> BlazePoseLandmarkExtractor::extract(const cv::Mat& image_bgr, const cv::Rect2f& box_px) {
  const auto roi = squareAround(box_px, config_.crop_scale);
  if (!roi) return common::Result<Skeleton>::fail("blazepose_landmark: " + roi.reason());
  return extractRoi(image_bgr, *roi);
}

common::Result<Skeleton> BlazePoseLandmarkExtractor::extractRoi(const cv::Mat& image_bgr, const RotatedSquare& roi) {
  using R = common::Result<Skeleton>;
  const std::string bad = checkBgrImage(image_bgr);
  if (!bad.empty()) return R::fail("blazepose_landmark: " + bad);
  const std::string bad_roi = checkRoi(roi);
  if (!bad_roi.empty()) return R::fail("blazepose_landmark: " + bad_roi);
  warpSquare(image_bgr, roi.center_px, roi.side_px, roi.rotation_rad, kInputSide, crop_);
  const auto ran = runOnCrop(crop_);
  if (!ran) return R::fail(ran.reason());
  Skeleton s{};
  const float flag = outputs_[2].ptr<float>()[0];
  if (!(flag >= config_.min_pose_flag)) return R::ok(s);  // nobody in the ROI: all missing
  const float* lm = outputs_[1].ptr<float>();
  for (std::size_t k = 0; k < static_cast<std::size_t>(kNumKeypoints); ++k) {
    const float* l = lm + 5 * blazePoseToCoco()[k];
    const cv::Point2f p = squareToImage({l[0], l[1]}, roi.center_px, roi.side_px, roi.rotation_rad, kInputSide);
    s[k] = {p.x, p.y, sigmoid(l[3])};
  }
  return R::ok(s);
}

}  // namespace gesture_formation::perception

#include "gesture_formation/perception/movenet_multipose_detector.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "gesture_formation/perception/dnn_model.hpp"

namespace gesture_formation::perception {

namespace {
constexpr int kCandidates = 6;
constexpr float kPeakTolerance = 1.013279e-6f;       // graph constant of the centre NMS
constexpr float kKeypointSigmaFactor = 0.300048828125f;  // fp16 0.3 in the graph
constexpr float kKeypointScoreThreshold = 0.126953125f;  // fp16 0.127 in the graph
}  // namespace

std::vector<MultiposeCandidate> decodeMultipose(const MultiposeHeads& h) {
  const int g = h.grid;
  const int n = g * g;
  const auto at = [g](const float* base, int channel, int y, int x) { return base[(channel * g + y) * g + x]; };

  // 1. centre NMS (5×5 max pool, stride 1, SAME, padding ignored), top 6.
  std::vector<float> peak(static_cast<std::size_t>(n));
  for (int y = 0; y < g; ++y) {
    for (int x = 0; x < g; ++x) {
      float m = -1e30f;
      for (int yy = std::max(0, y - 2); yy <= std::min(g - 1, y + 2); ++yy) {
        for (int xx = std::max(0, x - 2); xx <= std::min(g - 1, x + 2); ++xx) m = std::max(m, at(h.center_heatmap, 0, yy, xx));
      }
      const float v = at(h.center_heatmap, 0, y, x);
      peak[static_cast<std::size_t>(y * g + x)] = std::fabs(v - m) < kPeakTolerance ? v : 0.0f;
    }
  }
  std::vector<int> order(static_cast<std::size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::partial_sort(order.begin(), order.begin() + kCandidates, order.end(), [&](int a, int b) {
    const float va = peak[static_cast<std::size_t>(a)], vb = peak[static_cast<std::size_t>(b)];
    return va > vb || (va == vb && a < b);
  });

  std::vector<MultiposeCandidate> out(kCandidates);
  struct Geo {
    int cy, cx;
    float v, ymin, xmin, ymax, xmax;
  };
  std::array<Geo, kCandidates> geo{};
  const float gf = static_cast<float>(g);
  for (int i = 0; i < kCandidates; ++i) {
    const int c = order[static_cast<std::size_t>(i)];
    Geo& q = geo[static_cast<std::size_t>(i)];
    q.cy = c / g;
    q.cx = c % g;
    q.v = peak[static_cast<std::size_t>(c)];
    // 2. box in grid units
    const float sh = std::max(at(h.box_scale, 0, q.cy, q.cx), 0.0f) / 2.0f;
    const float sw = std::max(at(h.box_scale, 1, q.cy, q.cx), 0.0f) / 2.0f;
    const float by = static_cast<float>(q.cy) + at(h.box_offset, 0, q.cy, q.cx);
    const float bx = static_cast<float>(q.cx) + at(h.box_offset, 1, q.cy, q.cx);
    q.ymin = std::clamp(by - sh, 0.0f, gf);
    q.ymax = std::clamp(by + sh, 0.0f, gf);
    q.xmin = std::clamp(bx - sw, 0.0f, gf);
    q.xmax = std::clamp(bx + sw, 0.0f, gf);
  }
  const float denom = gf * kKeypointSigmaFactor;
  // w_ik(y, x) for candidate i, keypoint k (0 outside candidate i's box).
  const auto weight = [&](int i, int k, int y, int x, float ry, float rx) {
    const Geo& q = geo[static_cast<std::size_t>(i)];
    const float fy = static_cast<float>(y), fx = static_cast<float>(x);
    if (!(q.ymin <= fy && fy < q.ymax && q.xmin <= fx && fx < q.xmax)) return 0.0f;
    const float d2 = (fy - ry) * (fy - ry) + (fx - rx) * (fx - rx);
    return at(h.kpt_heatmap, k, y, x) * std::exp(-d2 / denom);
  };
  std::array<std::array<float, 2>, kCandidates> reg{};
  for (int k = 0; k < kNumKeypoints; ++k) {
    for (int i = 0; i < kCandidates; ++i) {
      const Geo& q = geo[static_cast<std::size_t>(i)];
      reg[static_cast<std::size_t>(i)] = {static_cast<float>(q.cy) + at(h.kpt_regress, 2 * k, q.cy, q.cx),
                                          static_cast<float>(q.cx) + at(h.kpt_regress, 2 * k + 1, q.cy, q.cx)};
    }
    for (int i = 0; i < kCandidates; ++i) {
      const Geo& q = geo[static_cast<std::size_t>(i)];
      const float ry = reg[static_cast<std::size_t>(i)][0], rx = reg[static_cast<std::size_t>(i)][1];
      int best = 0;
      float best_w = -1.0f;
      // Cells outside the box weigh 0: scan the box first, then fall back to the first cell.
      const int y0 = std::max(0, static_cast<int>(std::ceil(q.ymin))), y1 = std::min(g - 1, static_cast<int>(std::ceil(q.ymax)) - 1);
      const int x0 = std::max(0, static_cast<int>(std::ceil(q.xmin))), x1 = std::min(g - 1, static_cast<int>(std::ceil(q.xmax)) - 1);
      for (int y = y0; y <= y1; ++y) {
        for (int x = x0; x <= x1; ++x) {
          const float w = weight(i, k, y, x, ry, rx);
          if (w > best_w) {
            best_w = w;
            best = y * g + x;
          }
        }
      }
      // The graph's argmax over all cells: a cell outside the box has weight 0, so if the
      // best weight is ≤ 0 the first cell of the grid with that weight wins.
      if (!(best_w > 0.0f)) best = 0;
      const int ky = best / g, kx = best % g;
      float s = 0.0f;
      for (int j = 0; j < kCandidates; ++j) {
        s = std::max(s, weight(j, k, ky, kx, reg[static_cast<std::size_t>(j)][0], reg[static_cast<std::size_t>(j)][1]));
      }
      MultiposeCandidate& c = out[static_cast<std::size_t>(i)];
      const auto kk = static_cast<std::size_t>(k);
      c.y[kk] = (static_cast<float>(ky) + at(h.kpt_offset, 2 * k, ky, kx)) / gf;
      c.x[kk] = (static_cast<float>(kx) + at(h.kpt_offset, 2 * k + 1, ky, kx)) / gf;
      c.score[kk] = s;
    }
  }
  for (int i = 0; i < kCandidates; ++i) {
    const Geo& q = geo[static_cast<std::size_t>(i)];
    MultiposeCandidate& c = out[static_cast<std::size_t>(i)];
    c.ymin = std::clamp(q.ymin / gf, 0.0f, 1.0f);
    c.xmin = std::clamp(q.xmin / gf, 0.0f, 1.0f);
    c.ymax = std::clamp(q.ymax / gf, 0.0f, 1.0f);
    c.xmax = std::clamp(q.xmax / gf, 0.0f, 1.0f);
    float sum = 0.0f;
    int count = 0;
    for (int k = 0; k < kNumKeypoints; ++k) {
      const float s = c.score[static_cast<std::size_t>(k)];
      if (s > kKeypointScoreThreshold) {
        sum += q.v * s;
        ++count;
      }
    }
    c.person_score = sum / static_cast<float>(std::max(1, count));
  }
  return out;
}

std::vector<std::string> MoveNetMultiposeConfig::validate() const {
  std::vector<std::string> e;
  if (model_path.empty()) e.push_back("multipose.model_path must not be empty");
  if (!(min_person_score > 0.0f && min_person_score < 1.0f)) {
    e.push_back("multipose.min_person_score must be in (0, 1), got " + std::to_string(min_person_score));
  }
  if (!(min_box_px >= 0.0f)) e.push_back("multipose.min_box_px must be >= 0, got " + std::to_string(min_box_px));
  if (!(keypoint_min_score >= 0.0f && keypoint_min_score < 1.0f)) {
    e.push_back("multipose.keypoint_min_score must be in [0, 1), got " + std::to_string(keypoint_min_score));
  }
  return e;
}

const std::vector<std::string>& MoveNetMultiposeDetector::outputNames() {
  static const std::vector<std::string> names = {"box_offset", "box_scale", "center_heatmap",
                                                 "kpt_heatmap", "kpt_offset", "kpt_regress"};
  return names;
}

common::Result<std::unique_ptr<MoveNetMultiposeDetector>> MoveNetMultiposeDetector::create(
    const MoveNetMultiposeConfig& config, const std::string& models_root) {
  using R = common::Result<std::unique_ptr<MoveNetMultiposeDetector>>;
  const auto problems = config.validate();
  if (!problems.empty()) return R::fail(problems.front());
  auto net = loadOnnxModel(resolveModelPath(models_root, config.model_path), outputNames(), config.device);
  if (!net) return R::fail(net.reason());
  return R::ok(std::unique_ptr<MoveNetMultiposeDetector>(new MoveNetMultiposeDetector(config, *net)));
}

MoveNetMultiposeDetector::MoveNetMultiposeDetector(MoveNetMultiposeConfig config, cv::dnn::Net net)
    : config_(std::move(config)), net_(std::move(net)) {}

common::Result<std::vector<Detection>> MoveNetMultiposeDetector::detect(const cv::Mat& image_bgr) {
  using R = common::Result<std::vector<Detection>>;
  const std::string bad = checkBgrImage(image_bgr);
  if (!bad.empty()) return R::fail("multipose detector: " + bad);
  cv::Mat input;
  const Letterbox lb = letterboxImage(image_bgr, kInputSide, input);
  try {
    const cv::Mat blob = cv::dnn::blobFromImage(input, 1.0, cv::Size(kInputSide, kInputSide), cv::Scalar(), true, false, CV_32F);
    net_.setInput(blob);
    net_.forward(outputs_, outputNames());
  } catch (const cv::Exception& e) {
    return R::fail("multipose detector: network forward failed: " + e.msg);
  }
  constexpr int g = kInputSide / 4;
  const std::size_t cells = static_cast<std::size_t>(g * g);
  const std::size_t expected[] = {2 * cells, 2 * cells, cells, 17 * cells, 34 * cells, 34 * cells};
  if (outputs_.size() != 6) return R::fail("multipose detector: unexpected number of outputs");
  for (std::size_t i = 0; i < 6; ++i) {
    if (outputs_[i].total() != expected[i]) return R::fail("multipose detector: unexpected size of output " + outputNames()[i]);
  }
  MultiposeHeads heads;
  heads.box_offset = outputs_[0].ptr<float>();
  heads.box_scale = outputs_[1].ptr<float>();
  heads.center_heatmap = outputs_[2].ptr<float>();
  heads.kpt_heatmap = outputs_[3].ptr<float>();
  heads.kpt_offset = outputs_[4].ptr<float>();
  heads.kpt_regress = outputs_[5].ptr<float>();
  heads.grid = g;
  const auto candidates = decodeMultipose(heads);

  std::vector<Detection> out;
  const float s = static_cast<float>(kInputSide);
  const cv::Rect2f image_rect(0.0f, 0.0f, static_cast<float>(image_bgr.cols), static_cast<float>(image_bgr.rows));
  for (const auto& c : candidates) {
    if (!(c.person_score >= config_.min_person_score)) continue;
    const cv::Point2f p0 = lb.toImage({c.xmin * s, c.ymin * s}), p1 = lb.toImage({c.xmax * s, c.ymax * s});
    Detection d;
    d.score = c.person_score;
    d.box_px = cv::Rect2f(p0, p1) & image_rect;
    if (d.box_px.width < config_.min_box_px || d.box_px.height < config_.min_box_px) continue;
    d.has_keypoints = true;
    for (std::size_t k = 0; k < static_cast<std::size_t>(kNumKeypoints); ++k) {
      const cv::Point2f p = lb.toImage({c.x[k] * s, c.y[k] * s});
      const bool keep = c.score[k] >= config_.keypoint_min_score && c.score[k] > 0.0f;
      d.keypoints[k] = keep ? Keypoint{p.x, p.y, c.score[k]} : Keypoint{};
    }
    out.push_back(d);
  }
  std::stable_sort(out.begin(), out.end(), [](const Detection& a, const Detection& b) { return a.score > b.score; });
  return R::ok(std::move(out));
}

}  // namespace gesture_formation::perception

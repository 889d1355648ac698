#include "gesture_formation/perception/appearance.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::perception {

const common::FieldTable<AppearanceConfig>& appearanceFields() {
  using C = AppearanceConfig;
  using common::Range;
  static const common::FieldTable<AppearanceConfig> t{{
      {"tracker.appearance.enabled", Range::closed(0, 1), [](C& c) { return &c.enabled; }},
      {"tracker.appearance.hue_bins", Range::closed(2, 64), [](C& c) { return &c.hue_bins; }},
      {"tracker.appearance.sat_bins", Range::closed(1, 32), [](C& c) { return &c.sat_bins; }},
      {"tracker.appearance.val_bins", Range::closed(1, 32), [](C& c) { return &c.val_bins; }},
      {"tracker.appearance.min_similarity", Range::closed(0.0, 1.0), [](C& c) { return &c.min_similarity; }},
      {"tracker.appearance.tracker_min_similarity", Range::closed(0.0, 1.0),
       [](C& c) { return &c.tracker_min_similarity; }},
      {"tracker.appearance.update_rate", Range::openClosed(0.0, 1.0), [](C& c) { return &c.update_rate; }},
      {"tracker.appearance.min_updates", Range::atLeast(1.0), [](C& c) { return &c.min_updates; }},
  }};
  return t;
}

std::vector<std::string> AppearanceConfig::validate() const {
  return common::problemLines(appearanceFields().rangeProblems(*this));
}

cv::Mat AppearanceModel::describe(const cv::Mat& frame, const cv::Rect2f& box) const {
  if (frame.empty() || frame.type() != CV_8UC3) return {};
  // The body's inner region: the central 60 % of the width, 10-95 % of the height.
  const cv::Rect2f inner(box.x + 0.2f * box.width, box.y + 0.1f * box.height, 0.6f * box.width, 0.85f * box.height);
  const cv::Rect r = cv::Rect(cv::Point(static_cast<int>(std::floor(inner.x)), static_cast<int>(std::floor(inner.y))),
                              cv::Point(static_cast<int>(std::ceil(inner.x + inner.width)),
                                        static_cast<int>(std::ceil(inner.y + inner.height)))) &
                     cv::Rect(0, 0, frame.cols, frame.rows);
  if (r.width < 2 || r.height < 2) return {};
  cv::Mat hsv;
  cv::cvtColor(frame(r), hsv, cv::COLOR_BGR2HSV);
  const int channels[] = {0, 1, 2};
  const int sizes[] = {config_.hue_bins, config_.sat_bins, config_.val_bins};
  const float hue[] = {0.0f, 180.0f}, sat[] = {0.0f, 256.0f}, val[] = {0.0f, 256.0f};
  const float* ranges[] = {hue, sat, val};
  cv::Mat hist;
  cv::calcHist(&hsv, 1, channels, cv::Mat(), hist, 3, sizes, ranges);
  const double total = cv::sum(hist)[0];
  if (!(total > 0.0)) return {};
  hist /= total;
  return hist;
}

double AppearanceModel::similarity(const cv::Mat& descriptor) const {
  if (!established() || descriptor.empty() || model_.empty()) return 1.0;
  const double d = cv::compareHist(model_, descriptor, cv::HISTCMP_BHATTACHARYYA);
  return std::clamp(1.0 - d, 0.0, 1.0);
}

bool AppearanceModel::accepts(const cv::Mat& descriptor, double threshold) const {
  return similarity(descriptor) >= threshold;
}

void AppearanceModel::update(const cv::Mat& descriptor) {
  if (config_.enabled == 0 || descriptor.empty()) return;
  if (model_.empty() || model_.size != descriptor.size) {
    model_ = descriptor.clone();
    updates_ = 1;
    return;
  }
  // Running mean: equal weights until 1/update_rate frames, then exponential forgetting.
  const double w = std::max(static_cast<double>(config_.update_rate), 1.0 / (updates_ + 1));
  model_ = (1.0 - w) * model_ + w * descriptor;
  ++updates_;
}

}  // namespace gesture_formation::perception

#include "gesture_formation/estimation/stereo_distance.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::estimation {

const common::FieldTable<StereoDistanceConfig>& stereoDistanceFields() {
  using C = StereoDistanceConfig;
  using common::Range;
  static const common::FieldTable<StereoDistanceConfig> t{{
      {"min_depth_m", Range::closed(0.0, 100.0), [](C& c) { return &c.min_depth_m; }},
      {"max_depth_m", Range::closed(0.01, 100.0), [](C& c) { return &c.max_depth_m; }},
      {"min_valid_pixels", Range::atLeast(1), [](C& c) { return &c.min_valid_pixels; }},
      {"min_valid_fraction", Range::closed(0.0, 1.0), [](C& c) { return &c.min_valid_fraction; }},
      {"depth_scale_m", Range::closed(1e-6, 1.0), [](C& c) { return &c.depth_scale_m; }},
  }};
  return t;
}

std::vector<common::ConfigError> stereoDistanceProblems(const StereoDistanceConfig& config) {
  std::vector<common::ConfigError> e = stereoDistanceFields().rangeProblems(config);
  common::checkRule(e, config.max_depth_m > config.min_depth_m, "max_depth_m", config.max_depth_m,
                    "must be > min_depth_m");
  stereoDistanceFields().sortByTableOrder(e);
  return e;
}

common::Result<double> stereoDistance(const cv::Mat& depth, const Box& box, const CameraModel& camera,
                                      const StereoDistanceConfig& config) {
  using R = common::Result<double>;
  if (depth.empty()) return R::fail("depth image is empty");
  if (depth.type() != CV_16UC1 && depth.type() != CV_32FC1) {
    return R::fail("depth image must be CV_16UC1 or CV_32FC1, got type " + std::to_string(depth.type()));
  }
  if (!std::isfinite(box.u) || !std::isfinite(box.v) || !(box.w > 0) || !(box.h > 0) || !std::isfinite(box.w) ||
      !std::isfinite(box.h)) {
    return R::fail("invalid box");
  }
  const int x0 = std::max(0, static_cast<int>(std::floor(box.u)));
  const int y0 = std::max(0, static_cast<int>(std::floor(box.v)));
  const int x1 = std::min(depth.cols, static_cast<int>(std::ceil(box.u + box.w)));
  const int y1 = std::min(depth.rows, static_cast<int>(std::ceil(box.v + box.h)));
  if (x1 <= x0 || y1 <= y0) return R::fail("box does not intersect the depth image");

  std::vector<float> values;
  values.reserve(static_cast<std::size_t>((x1 - x0) * (y1 - y0)));
  const bool is16 = depth.type() == CV_16UC1;
  const double scale = config.depth_scale_m;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const double d = is16 ? depth.at<std::uint16_t>(y, x) * scale : static_cast<double>(depth.at<float>(y, x));
      if (std::isfinite(d) && d > 0.0 && d >= config.min_depth_m && d <= config.max_depth_m) {
        values.push_back(static_cast<float>(d));
      }
    }
  }
  const std::size_t total = static_cast<std::size_t>((x1 - x0) * (y1 - y0));
  if (values.size() < static_cast<std::size_t>(config.min_valid_pixels) ||
      static_cast<double>(values.size()) < config.min_valid_fraction * static_cast<double>(total)) {
    return R::fail("too few valid depth pixels (" + std::to_string(values.size()) + " of " + std::to_string(total) +
                   ")");
  }
  // Median: for an even count, the mean of the two middle values.
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid), values.end());
  double median = values[mid];
  if (values.size() % 2 == 0) {
    const float lower = *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(mid));
    median = 0.5 * (median + static_cast<double>(lower));
  }
  const auto ray = camera.rayThroughPixel(box.centre());
  if (!ray || !(ray->z() > 0.0)) return R::fail("cannot compute the ray through the box centre");
  return R::ok(median / ray->z());
}

}  // namespace gesture_formation::estimation

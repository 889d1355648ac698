#include "gesture_formation/estimation/camera_model.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::estimation {

using common::Range;

const common::FieldTable<CameraIntrinsics>& cameraIntrinsicsFields() {
  using C = CameraIntrinsics;
  static const common::FieldTable<CameraIntrinsics> t{{
      {"camera.fx", Range::positive(), [](C& c) { return &c.fx; }},
      {"camera.fy", Range::positive(), [](C& c) { return &c.fy; }},
      {"camera.cx", Range::any(), [](C& c) { return &c.cx; }},
      {"camera.cy", Range::any(), [](C& c) { return &c.cy; }},
      {"camera.width", Range::positive(), [](C& c) { return &c.width_px; }},
      {"camera.height", Range::positive(), [](C& c) { return &c.height_px; }},
  }};
  return t;
}

std::vector<std::string> CameraIntrinsics::validate() const {
  std::vector<common::ConfigError> e = cameraIntrinsicsFields().rangeProblems(*this);
  for (std::size_t i = 0; i < distortion.size(); ++i) {
    common::checkRule(e, std::isfinite(distortion[i]), "camera.distortion[" + std::to_string(i) + "]", distortion[i],
                      "must be finite");
  }
  return common::problemLines(e);
}

common::Result<CameraIntrinsics> readoutIntrinsics(const CameraIntrinsics& full, const SensorReadout& r) {
  using R = common::Result<CameraIntrinsics>;
  std::vector<std::string> problems;
  auto field = [](const char* name, int value) { return std::string(name) + " " + std::to_string(value); };
  if (r.binning_x < 0) problems.push_back(field("binning_x", r.binning_x) + " is negative");
  if (r.binning_y < 0) problems.push_back(field("binning_y", r.binning_y) + " is negative");
  if (r.roi_x_offset < 0) problems.push_back(field("roi.x_offset", r.roi_x_offset) + " is negative");
  if (r.roi_y_offset < 0) problems.push_back(field("roi.y_offset", r.roi_y_offset) + " is negative");
  if (r.roi_width < 0) problems.push_back(field("roi.width", r.roi_width) + " is negative");
  if (r.roi_height < 0) problems.push_back(field("roi.height", r.roi_height) + " is negative");
  if (!problems.empty()) {
    std::string all;
    for (const auto& p : problems) all += (all.empty() ? "" : "; ") + p;
    return R::fail(all);
  }
  const bool whole = r.roi_width == 0 && r.roi_height == 0;
  if (!whole && (r.roi_width == 0 || r.roi_height == 0)) {
    return R::fail("roi " + std::to_string(r.roi_width) + "x" + std::to_string(r.roi_height) +
                   ": one side 0 and the other not (0x0 is the full image)");
  }
  if (whole && (r.roi_x_offset != 0 || r.roi_y_offset != 0)) {
    return R::fail("roi offset (" + std::to_string(r.roi_x_offset) + ", " + std::to_string(r.roi_y_offset) +
                   ") with no region (roi 0x0 is the full image)");
  }
  const int w = whole ? full.width_px : r.roi_width, h = whole ? full.height_px : r.roi_height;
  if (std::int64_t{r.roi_x_offset} + w > full.width_px || std::int64_t{r.roi_y_offset} + h > full.height_px) {
    return R::fail("roi (" + std::to_string(r.roi_x_offset) + ", " + std::to_string(r.roi_y_offset) + ") " +
                   std::to_string(w) + "x" + std::to_string(h) + " lies outside the " + std::to_string(full.width_px) + "x" +
                   std::to_string(full.height_px) + " sensor");
  }
  const int bx = std::max(1, r.binning_x), by = std::max(1, r.binning_y);
  CameraIntrinsics k = full;
  k.width_px = w / bx;
  k.height_px = h / by;
  if (k.width_px < 1 || k.height_px < 1) {
    return R::fail("binning " + std::to_string(bx) + "x" + std::to_string(by) + " of a " + std::to_string(w) + "x" +
                   std::to_string(h) + " region leaves no pixel");
  }
  k.fx = full.fx / bx;
  k.fy = full.fy / by;
  k.cx = (full.cx - r.roi_x_offset - 0.5 * (bx - 1)) / bx;
  k.cy = (full.cy - r.roi_y_offset - 0.5 * (by - 1)) / by;
  return R::ok(k);
}

}  // namespace gesture_formation::estimation

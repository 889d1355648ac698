#include "gesture_formation/estimation/camera_model.hpp"

#include <cmath>
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

}  // namespace gesture_formation::estimation

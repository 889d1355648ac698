#pragma once
/// \file
/// \brief Where the worker estimator's camera model comes from (docs/estimation.md §"Camera model"):
/// the camera's own calibration as its driver publishes it with every image (`camera_info`,
/// sensor_msgs/CameraInfo onboard; the rendered or synthetic camera's intrinsics in simulation),
/// or — only as an explicit override — the estimator configuration's `camera` section (`config`).
/// With `camera_info`, a detection is refused until intrinsics have arrived: estimating with a
/// camera model that is not the camera's own places the worker wrong without any sign of it.
/// Thread safety: none (the caller's lock).

#include <optional>
#include <string>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/estimation/camera_model.hpp"

namespace gesture_formation::estimation {

enum class IntrinsicsSource { kCameraInfo, kConfig };

inline const char* toString(IntrinsicsSource s) { return s == IntrinsicsSource::kConfig ? "config" : "camera_info"; }

/// \brief "camera_info" | "config"; fails naming the value.
inline common::Result<IntrinsicsSource> parseIntrinsicsSource(const std::string& name) {
  if (name == "camera_info") return common::Result<IntrinsicsSource>::ok(IntrinsicsSource::kCameraInfo);
  if (name == "config") return common::Result<IntrinsicsSource>::ok(IntrinsicsSource::kConfig);
  return common::Result<IntrinsicsSource>::fail("'" + name + "': expected camera_info or config");
}

class CameraModelSource {
 public:
  /// \brief `config_camera`: the configuration's camera section (used with kConfig only).
  CameraModelSource(IntrinsicsSource source, const CameraIntrinsics& config_camera) : source_(source) {
    if (source == IntrinsicsSource::kConfig) model_.emplace(config_camera);
  }

  /// \brief The camera's intrinsics as they arrived (every image's CameraInfo): the model from now
  /// on (kCameraInfo). True when the model changed; ignored (false) with kConfig; invalid
  /// intrinsics fail naming the field and keep the model held.
  common::Result<bool> receive(const CameraIntrinsics& k) {
    const auto problems = k.validate();
    if (!problems.empty()) return common::Result<bool>::fail(problems.front());
    if (source_ == IntrinsicsSource::kConfig) return common::Result<bool>::ok(false);
    if (model_ && same(model_->intrinsics(), k)) return common::Result<bool>::ok(false);
    model_.emplace(k);
    return common::Result<bool>::ok(true);
  }

  /// \brief The model for a measurement; null while kCameraInfo has received nothing yet.
  const CameraModel* model() const { return model_ ? &*model_ : nullptr; }
  IntrinsicsSource source() const { return source_; }
  /// \brief Why a detection cannot be used now (empty: it can).
  std::string refusal() const {
    return model_ ? std::string()
                  : "no camera intrinsics received yet (intrinsics_source camera_info: the camera driver's CameraInfo)";
  }

  static bool same(const CameraIntrinsics& a, const CameraIntrinsics& b) {
    return a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy && a.distortion == b.distortion &&
           a.width_px == b.width_px && a.height_px == b.height_px;
  }

 private:
  IntrinsicsSource source_;
  std::optional<CameraModel> model_;
};

}  // namespace gesture_formation::estimation

#pragma once
/// \file
/// \brief `PersonDetector`: finds people in a BGR image (docs/design.md §2). Two implementations:
/// `BlazePoseDetector` (SSD anchors + weighted NMS, near-field) and
/// `MoveNetMultiposeDetector` (CenterNet-style, finds small distant people; the default —
/// docs/perception.md says why).

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/perception/types.hpp"

namespace gesture_formation::perception {

/// \brief Interface of a person detector.
/// Thread safety: an instance is not reentrant (it owns a cv::dnn::Net); use one per thread.
class PersonDetector {
 public:
  virtual ~PersonDetector() = default;
  PersonDetector() = default;
  PersonDetector(const PersonDetector&) = delete;
  PersonDetector& operator=(const PersonDetector&) = delete;

  /// \brief People in `image_bgr` (8-bit, 3 channels), best score first, boxes in the
  /// image's pixels. An empty vector means nobody was found; a failure carries the reason
  /// (bad image, network error).
  virtual common::Result<std::vector<Detection>> detect(const cv::Mat& image_bgr) = 0;

  /// Short name for logs and tables: "movenet_multipose", "blazepose".
  virtual std::string name() const = 0;
};

/// Which detector to build.
enum class DetectorKind { kMoveNetMultipose, kBlazePose };

/// \brief Parses "movenet_multipose" / "blazepose".
common::Result<DetectorKind> parseDetectorKind(const std::string& text);
std::string toString(DetectorKind kind);

}  // namespace gesture_formation::perception

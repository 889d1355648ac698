#pragma once
/// \file
/// \brief Value types of the perception module: person detections and COCO-17 skeletons in
/// image pixels (docs/design.md §2, §8.7).
///
/// Pixel convention (docs/conventions.md, as OpenCV): u/x right, v/y down, origin at the
/// top-left image corner, pixel centres at integer coordinates. A box is (u, v, w, h) =
/// top-left corner and size [px] of the *input* image the caller passed (never of a network
/// input).

#include <array>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace gesture_formation::perception {

/// Number of COCO keypoints (docs/design.md §8.7 order: nose, l/r eye, l/r ear, l/r shoulder,
/// l/r elbow, l/r wrist, l/r hip, l/r knee, l/r ankle). "Left" is the person's left.
constexpr int kNumKeypoints = 17;

/// COCO-17 keypoint indices.
enum CocoKeypoint : int {
  kNose = 0, kLeftEye, kRightEye, kLeftEar, kRightEar, kLeftShoulder, kRightShoulder, kLeftElbow, kRightElbow,
  kLeftWrist, kRightWrist, kLeftHip, kRightHip, kLeftKnee, kRightKnee, kLeftAnkle, kRightAnkle
};

/// \brief Names of the COCO-17 keypoints in index order (for CSV headers and messages).
const std::array<const char*, kNumKeypoints>& cocoKeypointNames();

/// \brief The 16 limbs drawn for a COCO-17 skeleton, as keypoint index pairs.
const std::vector<std::pair<int, int>>& cocoLimbs();

/// \brief One keypoint: position in image pixels and confidence in [0, 1].
/// A missing keypoint has c = 0 (its x, y are then meaningless and reported as 0).
struct Keypoint {
  float x = 0.0f;  ///< [px], image u
  float y = 0.0f;  ///< [px], image v
  float c = 0.0f;  ///< confidence 0..1
};

/// \brief 17 COCO keypoints of one person in one image.
using Skeleton = std::array<Keypoint, kNumKeypoints>;

/// \brief A rotated square region of interest in image pixels (MediaPipe's person ROI).
struct RotatedSquare {
  cv::Point2f center_px{0.0f, 0.0f};  ///< centre [px]
  float side_px = 0.0f;               ///< side length [px], > 0 when valid
  float rotation_rad = 0.0f;          ///< rotation of the square, clockwise in the image [rad]
};

/// \brief One detected person.
struct Detection {
  cv::Rect2f box_px;   ///< person box (u, v, w, h) in input-image pixels
  float score = 0.0f;  ///< detector confidence 0..1
  /// True when `keypoints` holds the detector's own keypoints (MoveNet multipose).
  bool has_keypoints = false;
  Skeleton keypoints{};
  /// True when `roi` holds a body ROI for a landmark model (BlazePose detector).
  bool has_roi = false;
  RotatedSquare roi;
};

/// \brief Intersection over union of two boxes; 0 when either is empty.
float iou(const cv::Rect2f& a, const cv::Rect2f& b);

}  // namespace gesture_formation::perception

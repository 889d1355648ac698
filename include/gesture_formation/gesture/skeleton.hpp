#pragma once
/// \file
/// \brief The 2-D skeleton exchanged between perception, the gesture classifier and the
/// simulator: the worker's box and the 17 COCO keypoints (docs/design.md §2, §8.7).

#include <array>
#include <cstddef>
#include <vector>

namespace gesture_formation::gesture {

/// COCO-17 keypoint order (docs/design.md §8.7).
enum Keypoint : int {
  kNose = 0, kLeftEye, kRightEye, kLeftEar, kRightEar, kLeftShoulder, kRightShoulder, kLeftElbow, kRightElbow,
  kLeftWrist, kRightWrist, kLeftHip, kRightHip, kLeftKnee, kRightKnee, kLeftAnkle, kRightAnkle
};
constexpr int kNumKeypoints = 17;
/// Values per keypoint in the classifier input: x, y (box-normalised) and confidence.
constexpr int kValuesPerKeypoint = 3;
constexpr int kFeaturesPerFrame = kNumKeypoints * kValuesPerKeypoint;  // 51
/// Frames per classifier window (N, docs/design.md §2).
constexpr int kWindowFrames = 9;

/// Gesture ids (docs/design.md §2).
enum GestureId : int { kNone = 0, kCrossArms = 1, kExtendArmSide = 2, kPalmsTogether = 3, kRaiseArmUp = 4 };
constexpr int kNumGestureClasses = 5;

/// \brief One image's skeleton: box (u, v, w, h) [px, top-left + size] and keypoints in image
/// pixels with confidence 0..1 (0 = missing; its coordinates are then meaningless).
struct Skeleton2D {
  double u = 0.0, v = 0.0, w = 0.0, h = 0.0;
  std::array<double, kNumKeypoints> x{};
  std::array<double, kNumKeypoints> y{};
  std::array<double, kNumKeypoints> c{};
};

/// \brief The classifier's per-frame features: x' = (x − u)/w, y' = (y − v)/h, c; a
/// missing keypoint (c = 0) gives (0, 0, 0). `out` must hold kFeaturesPerFrame floats.
inline void boxNormalizedFeatures(const Skeleton2D& s, float* out) {
  for (int k = 0; k < kNumKeypoints; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const bool present = s.c[i] > 0.0 && s.w > 0.0 && s.h > 0.0;
    out[3 * k + 0] = present ? static_cast<float>((s.x[i] - s.u) / s.w) : 0.0f;
    out[3 * k + 1] = present ? static_cast<float>((s.y[i] - s.v) / s.h) : 0.0f;
    out[3 * k + 2] = present ? static_cast<float>(s.c[i]) : 0.0f;
  }
}

}  // namespace gesture_formation::gesture

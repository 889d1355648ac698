#pragma once
/// \file
/// \brief The FIFO of the last N skeletons normalised to the worker box — the gesture
/// classifier's input (docs/design.md §2: N = 9).
///
/// Normalisation per frame, with that frame's box (u, v, w, h) [px]:
///   x' = (x − u)/w,  y' = (y − v)/h,  c' = c.
/// A missing keypoint (c = 0, or a box with w ≤ 0 or h ≤ 0) gives (0, 0, 0). The same
/// convention as gesture::boxNormalizedFeatures.

#include <cstddef>
#include <deque>
#include <vector>

#include <opencv2/core.hpp>

#include "gesture_formation/perception/types.hpp"

namespace gesture_formation::perception {

constexpr int kValuesPerKeypoint = 3;                                  ///< x', y', c
constexpr int kFeaturesPerFrame = kNumKeypoints * kValuesPerKeypoint;  ///< 51
constexpr int kDefaultFifoFrames = 9;                                  ///< N (docs/design.md §2)

/// \brief Writes the 51 normalised features (x', y', c per keypoint, COCO order) of one
/// skeleton into `out`.
void normalizeToBox(const Skeleton& skeleton, const cv::Rect2f& box_px, float* out);

/// \brief Fixed-capacity FIFO of normalised skeletons. Thread safety: none.
class SkeletonFifo {
 public:
  /// `capacity` = N ≥ 1 (clamped to 1 if smaller).
  explicit SkeletonFifo(int capacity = kDefaultFifoFrames);

  /// Appends one frame (normalised immediately); drops the oldest when full.
  void push(const Skeleton& skeleton, const cv::Rect2f& box_px);
  void clear() { frames_.clear(); }
  int size() const { return static_cast<int>(frames_.size()); }
  int capacity() const { return capacity_; }
  bool full() const { return size() == capacity_; }

  /// \brief Contiguous [N][51] floats, oldest frame first (row-major: frame, keypoint, x'/y'/c).
  /// Empty until the FIFO is full.
  std::vector<float> tensor() const;

 private:
  int capacity_;
  std::deque<std::array<float, kFeaturesPerFrame>> frames_;
};

}  // namespace gesture_formation::perception

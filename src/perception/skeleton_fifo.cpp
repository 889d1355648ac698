#include "gesture_formation/perception/skeleton_fifo.hpp"

#include <algorithm>

namespace gesture_formation::perception {

void normalizeToBox(const Skeleton& s, const cv::Rect2f& box, float* out) {
  const bool box_ok = box.width > 0.0f && box.height > 0.0f;
  for (int k = 0; k < kNumKeypoints; ++k) {
    const Keypoint& p = s[static_cast<std::size_t>(k)];
    const bool present = box_ok && p.c > 0.0f;
    out[3 * k + 0] = present ? (p.x - box.x) / box.width : 0.0f;
    out[3 * k + 1] = present ? (p.y - box.y) / box.height : 0.0f;
    out[3 * k + 2] = present ? p.c : 0.0f;
  }
}

SkeletonFifo::SkeletonFifo(int capacity) : capacity_(std::max(1, capacity)) {}

void SkeletonFifo::push(const Skeleton& skeleton, const cv::Rect2f& box_px) {
  std::array<float, kFeaturesPerFrame> f{};
  normalizeToBox(skeleton, box_px, f.data());
  frames_.push_back(f);
  while (static_cast<int>(frames_.size()) > capacity_) frames_.pop_front();
}

std::vector<float> SkeletonFifo::tensor() const {
  std::vector<float> out;
  if (!full()) return out;
  out.reserve(static_cast<std::size_t>(capacity_ * kFeaturesPerFrame));
  for (const auto& f : frames_) out.insert(out.end(), f.begin(), f.end());
  return out;
}

}  // namespace gesture_formation::perception

// FIFO of the last N skeletons normalised to the box: the classifier's [N][51] input.
#include <gtest/gtest.h>

#include "gesture_formation/perception/skeleton_fifo.hpp"

namespace gesture_formation::perception {
namespace {

Skeleton makeSkeleton(float base) {
  Skeleton s{};
  for (int k = 0; k < kNumKeypoints; ++k) s[static_cast<std::size_t>(k)] = {base + k, 2.0f * base + k, 0.5f};
  return s;
}

TEST(SkeletonFifoTest, NormalisesToTheBox) {
  Skeleton s{};
  s[kNose] = {150.0f, 120.0f, 0.9f};      // box (100, 100, 50, 200): x' = 1, y' = 0.1
  s[kLeftWrist] = {100.0f, 300.0f, 0.4f};  // x' = 0, y' = 1
  s[kRightAnkle] = {125.0f, 200.0f, 0.0f}; // missing → (0, 0, 0)
  float f[kFeaturesPerFrame];
  normalizeToBox(s, cv::Rect2f(100, 100, 50, 200), f);
  EXPECT_FLOAT_EQ(f[3 * kNose + 0], 1.0f);
  EXPECT_FLOAT_EQ(f[3 * kNose + 1], 0.1f);
  EXPECT_FLOAT_EQ(f[3 * kNose + 2], 0.9f);
  EXPECT_FLOAT_EQ(f[3 * kLeftWrist + 0], 0.0f);
  EXPECT_FLOAT_EQ(f[3 * kLeftWrist + 1], 1.0f);
  EXPECT_FLOAT_EQ(f[3 * kLeftWrist + 2], 0.4f);
  for (int j = 0; j < 3; ++j) EXPECT_EQ(f[3 * kRightAnkle + j], 0.0f);
  // A degenerate box makes every keypoint missing.
  normalizeToBox(s, cv::Rect2f(100, 100, 0, 200), f);
  for (float v : f) EXPECT_EQ(v, 0.0f);
}

TEST(SkeletonFifoTest, TensorIsOldestFirstAndOnlyWhenFull) {
  SkeletonFifo fifo(9);
  const cv::Rect2f box(0, 0, 100, 100);
  for (int i = 0; i < 8; ++i) {
    fifo.push(makeSkeleton(static_cast<float>(i)), box);
    EXPECT_TRUE(fifo.tensor().empty());
  }
  fifo.push(makeSkeleton(8.0f), box);
  fifo.push(makeSkeleton(9.0f), box);  // drops frame 0
  ASSERT_TRUE(fifo.full());
  const auto t = fifo.tensor();
  ASSERT_EQ(t.size(), 9u * 51u);
  for (int n = 0; n < 9; ++n) {
    const float base = static_cast<float>(n + 1);  // frames 1..9 in time order
    for (int k = 0; k < kNumKeypoints; ++k) {
      const std::size_t i = static_cast<std::size_t>(n * kFeaturesPerFrame + 3 * k);
      EXPECT_FLOAT_EQ(t[i], (base + k) / 100.0f);
      EXPECT_FLOAT_EQ(t[i + 1], (2.0f * base + k) / 100.0f);
      EXPECT_FLOAT_EQ(t[i + 2], 0.5f);
    }
  }
  fifo.clear();
  EXPECT_EQ(fifo.size(), 0);
  EXPECT_TRUE(fifo.tensor().empty());
}

}  // namespace
}  // namespace gesture_formation::perception

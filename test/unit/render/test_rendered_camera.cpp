// sim::windowFromFifo (docs/simulation.md §8): the classifier's window made from the perception
// pipeline's FIFO has exactly the FIFO's features — the LSTM sees what the Perception nodelet
// would give it.
#include <gtest/gtest.h>

#include <random>

#include "gesture_formation/perception/skeleton_fifo.hpp"
#include "gesture_formation/sim/rendered_camera.hpp"

namespace gf = gesture_formation;

TEST(RenderedCameraTest, WindowFromFifoHasExactlyTheFifosFeatures) {
  gf::perception::SkeletonFifo fifo(gf::gesture::kWindowFrames);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 600.0f), c(0.0f, 1.0f);
  for (int f = 0; f < 12; ++f) {
    gf::perception::Skeleton sk{};
    for (auto& k : sk) {
      k.x = u(rng);
      k.y = u(rng);
      k.c = c(rng) < 0.15f ? 0.0f : c(rng);  // some missing keypoints
    }
    fifo.push(sk, cv::Rect2f(u(rng) * 0.5f, u(rng) * 0.5f, 20.0f + u(rng) * 0.2f, 60.0f + u(rng) * 0.4f));
  }
  const std::vector<float> tensor = fifo.tensor();
  ASSERT_EQ(tensor.size(), static_cast<std::size_t>(gf::gesture::kWindowFrames * gf::gesture::kFeaturesPerFrame));
  const gf::gesture::SkeletonWindow w = gf::sim::windowFromFifo(tensor);
  ASSERT_TRUE(w.full());
  std::vector<float> features(tensor.size(), -1.0f);
  w.features(features.data());
  for (std::size_t i = 0; i < tensor.size(); ++i) ASSERT_EQ(features[i], tensor[i]) << "feature " << i;
  EXPECT_FALSE(gf::sim::windowFromFifo({1.0f, 2.0f}).full());  // not a full FIFO: no window
}

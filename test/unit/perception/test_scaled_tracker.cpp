// ScaledTracker (perception/scaled_tracker.hpp): the visual tracker on a shrunk frame follows a large
// box and reports it in the frame's own pixels; small boxes are tracked at full resolution; the
// setting's checks name the key.
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/perception/perception_pipeline.hpp"
#include "gesture_formation/perception/scaled_tracker.hpp"

namespace gesture_formation::perception {
namespace {

/// A 640×480 frame: smooth random background and a textured 'person' (its own random pattern) at `box`.
cv::Mat sceneWith(const cv::Rect& box, const cv::Mat& background, const cv::Mat& person) {
  cv::Mat frame = background.clone();
  person.copyTo(frame(box));
  return frame;
}

cv::Mat randomTexture(cv::Size size, int blur, std::uint64_t seed) {
  cv::RNG rng(seed);
  cv::Mat m(size, CV_8UC3);
  rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(m, m, cv::Size(blur, blur), 0);
  return m;
}

class ScaledTrackerFollows : public ::testing::TestWithParam<TrackerKind> {};

// A 120 × 240 px person moving 4 px right and 1 px down per frame for 30 frames: tracked on a frame
// shrunk to a box of at most 64 px (integer factor 4: 30 × 60 px), every reported box overlaps the
// truth (IoU ≥ 0.6), in frame px.
TEST_P(ScaledTrackerFollows, ALargeBoxOnTheShrunkFrame) {
  const cv::Mat background = randomTexture({640, 480}, 9, 1);
  const cv::Mat person = randomTexture({120, 240}, 5, 2);
  ScaledTracker tracker(GetParam(), 64.0f);
  cv::Rect truth(200, 100, 120, 240);
  ASSERT_TRUE(tracker.init(sceneWith(truth, background, person), truth));
  EXPECT_EQ(tracker.scale(), 0.25);
  for (int k = 1; k <= 30; ++k) {
    truth.x += 4;
    truth.y += 1;
    cv::Rect2f box;
    ASSERT_TRUE(tracker.update(sceneWith(truth, background, person), box)) << "frame " << k;
    EXPECT_GE(iou(box, cv::Rect2f(truth)), 0.6f) << "frame " << k << ": (" << box.x << ", " << box.y << ", " << box.width << ", "
                                                 << box.height << ")";
  }
}

INSTANTIATE_TEST_SUITE_P(Trackers, ScaledTrackerFollows, ::testing::Values(TrackerKind::kKcf, TrackerKind::kCsrt),
                         [](const auto& info) { return toString(info.param); });

TEST(ScaledTrackerTest, SmallBoxesAndZeroAreFullResolution) {
  const cv::Mat background = randomTexture({640, 480}, 9, 3);
  const cv::Mat person = randomTexture({40, 90}, 5, 4);
  const cv::Rect box(300, 200, 40, 90);
  ScaledTracker small(TrackerKind::kKcf, 96.0f);
  ASSERT_TRUE(small.init(sceneWith(box, background, person), box));
  EXPECT_EQ(small.scale(), 1.0);
  ScaledTracker full(TrackerKind::kKcf, 0.0f);
  const cv::Rect large(100, 100, 200, 300);
  ASSERT_TRUE(full.init(sceneWith(large, background, randomTexture({200, 300}, 5, 5)), large));
  EXPECT_EQ(full.scale(), 1.0);
  // Full resolution gives the wrapped tracker's own box: integer pixels of the frame.
  cv::Rect2f b;
  ASSERT_TRUE(full.update(sceneWith(large, background, randomTexture({200, 300}, 5, 5)), b));
  EXPECT_EQ(b.x, std::round(b.x));
  EXPECT_EQ(b.width, std::round(b.width));
}

TEST(ScaledTrackerTest, UpdateWithoutInitFails) {
  ScaledTracker t(TrackerKind::kKcf, 96.0f);
  cv::Rect2f b;
  EXPECT_FALSE(t.active());
  EXPECT_FALSE(t.update(cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(90)), b));
}

TEST(ScaledTrackerTest, ConfigNamesTheKeyAndValue) {
  WorkerTrackerConfig c;
  EXPECT_EQ(c.track_max_side_px, 96.0f);
  EXPECT_TRUE(c.validate().empty());
  c.track_max_side_px = 0.0f;  // full resolution
  EXPECT_TRUE(c.validate().empty());
  c.track_max_side_px = 5.0f;
  auto e = c.validate();
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("tracker.track_max_side_px"), std::string::npos) << e[0];
  EXPECT_NE(e[0].find("5"), std::string::npos) << e[0];
  c.track_max_side_px = -1.0f;
  e = c.validate();
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("tracker.track_max_side_px"), std::string::npos) << e[0];
  c.track_max_side_px = 5000.0f;
  EXPECT_FALSE(c.validate().empty());
  // The nodelet's parameter uses the table's range; the table itself refuses what validate() refuses
  // outside [0, 4096].
  const common::Range& range = *workerTrackerFields().rangeOf("tracker.track_max_side_px");
  EXPECT_TRUE(range.contains(0.0));
  EXPECT_TRUE(range.contains(96.0));
  EXPECT_FALSE(range.contains(-1.0));
  EXPECT_FALSE(range.contains(5000.0));
}

}  // namespace
}  // namespace gesture_formation::perception

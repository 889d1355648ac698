// The whole pipeline on real frames: FIFO fills with one identity; bad input and bad models.
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "gesture_formation/perception/perception_pipeline.hpp"
#include "perception_test_util.hpp"

namespace gesture_formation::perception {
namespace {

TEST(PerceptionPipelineTest, FillsTheClassifierInputOnVtest) {
  const std::string path = test::debianData() + "/vtest.avi";
  GF_REQUIRE_FILE(path);
  PerceptionConfig cfg;
  cfg.models_root = test::modelsRoot();
  auto p = PerceptionPipeline::create(cfg);
  ASSERT_TRUE(p) << p.reason();
  cv::VideoCapture cap(path);
  cv::Mat frame, small;
  int full_frames = 0;
  for (int i = 0; i < 30 && cap.read(frame); ++i) {
    cv::resize(frame, small, cv::Size(640, 480), 0, 0, cv::INTER_AREA);
    auto r = (*p)->step(small);
    ASSERT_TRUE(r) << r.reason();
    if (r->fifo_full) {
      ++full_frames;
      const auto x = (*p)->classifierInput();
      ASSERT_EQ(x.size(), 9u * 51u);
      // Present keypoints of a person inside its box normalise to about [0, 1].
      for (std::size_t j = 0; j < x.size(); j += 3) {
        if (x[j + 2] > 0.3f) {
          EXPECT_GT(x[j], -0.5f);
          EXPECT_LT(x[j], 1.5f);
          EXPECT_GT(x[j + 1], -0.5f);
          EXPECT_LT(x[j + 1], 1.5f);
        }
      }
    }
  }
  EXPECT_GT(full_frames, 10);
}

TEST(PerceptionPipelineTest, BadInputAndModelsGiveReasons) {
  PerceptionConfig cfg;
  cfg.models_root = test::modelsRoot();
  auto p = PerceptionPipeline::create(cfg);
  ASSERT_TRUE(p) << p.reason();
  auto empty = (*p)->step(cv::Mat());
  ASSERT_FALSE(empty);
  EXPECT_NE(empty.reason().find("empty"), std::string::npos);
  auto gray = (*p)->step(cv::Mat(480, 640, CV_8UC1));
  ASSERT_FALSE(gray);
  EXPECT_NE(gray.reason().find("3 channels"), std::string::npos);

  PerceptionConfig bad_root = cfg;
  bad_root.models_root = "/nonexistent_models";
  auto missing = PerceptionPipeline::create(bad_root);
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.reason().find("/nonexistent_models/movenet_multipose/movenet_multipose.onnx"), std::string::npos)
      << missing.reason();

  PerceptionConfig bad_cfg = cfg;
  bad_cfg.tracker.detect_every_k = 0;
  bad_cfg.lightning.crop_scale = 0.5f;
  auto invalid = PerceptionPipeline::create(bad_cfg);
  ASSERT_FALSE(invalid);
  EXPECT_NE(invalid.reason().find("tracker.detect_every_k"), std::string::npos) << invalid.reason();
  EXPECT_NE(invalid.reason().find("lightning.crop_scale"), std::string::npos) << invalid.reason();
}

}  // namespace
}  // namespace gesture_formation::perception

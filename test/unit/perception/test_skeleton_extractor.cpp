// Skeleton extractors on real people: keypoints fall on the body (shoulders and wrists
// inside the hand-labelled box), left/right not swapped for a person facing the camera.
#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "gesture_formation/perception/perception_pipeline.hpp"
#include "gesture_formation/perception/skeleton_extractor.hpp"
#include "perception_test_util.hpp"

namespace gesture_formation::perception {
namespace {

using test::imagePath;
using test::label;
using test::modelsRoot;

std::unique_ptr<SkeletonExtractor> makeExtractor(SkeletonKind kind) {
  PerceptionConfig cfg;
  cfg.models_root = modelsRoot();
  cfg.skeleton = kind;
  auto e = makeSkeletonExtractor(cfg);
  EXPECT_TRUE(e) << e.reason();
  return e ? std::move(e.value()) : nullptr;
}

struct Case {
  SkeletonKind kind;
  const char* image;
  const char* person;
  bool facing_camera;
};

class SkeletonOnRealPeople : public ::testing::TestWithParam<Case> {};

TEST_P(SkeletonOnRealPeople, KeypointsOnTheBody) {
  const Case c = GetParam();
  const std::string path = imagePath(c.image);
  GF_REQUIRE_FILE(path);
  auto ext = makeExtractor(c.kind);
  ASSERT_TRUE(ext);
  const cv::Mat img = cv::imread(path, cv::IMREAD_COLOR);
  const cv::Rect2f box = label(c.image, c.person);
  auto s = ext->extract(img, box);
  ASSERT_TRUE(s) << s.reason();
  // Shoulders and wrists lie inside the person's box (2 px slack for the label) and are confident.
  const cv::Rect2f slack(box.x - 2, box.y - 2, box.width + 4, box.height + 4);
  for (int k : {kLeftShoulder, kRightShoulder, kLeftWrist, kRightWrist}) {
    const Keypoint& p = (*s)[static_cast<std::size_t>(k)];
    EXPECT_TRUE(slack.contains({p.x, p.y})) << cocoKeypointNames()[static_cast<std::size_t>(k)] << " at (" << p.x << ", "
                                            << p.y << ")";
    // 0.2: the astronaut's hands are at the bottom edge, half hidden (BlazePose gives 0.23).
    EXPECT_GT(p.c, 0.2f) << cocoKeypointNames()[static_cast<std::size_t>(k)];
  }
  // Head above the shoulders; shoulders above the hips (upright people).
  const auto& sk = *s;
  EXPECT_LT(sk[kNose].y, std::min(sk[kLeftShoulder].y, sk[kRightShoulder].y));
  if (c.facing_camera) {
    // Facing the camera, the person's left side is on the image's right.
    EXPECT_GT(sk[kLeftShoulder].x, sk[kRightShoulder].x);
    EXPECT_GT(sk[kLeftEye].x, sk[kRightEye].x);
    EXPECT_GT(sk[kLeftHip].x, sk[kRightHip].x);
  }
  // Confidences in [0, 1].
  for (const auto& p : sk) {
    EXPECT_GE(p.c, 0.0f);
    EXPECT_LE(p.c, 1.0f);
  }
}

INSTANTIATE_TEST_SUITE_P(
    RealImages, SkeletonOnRealPeople,
    ::testing::Values(Case{SkeletonKind::kMoveNetLightning, "astronaut.png", "astronaut", true},
                      Case{SkeletonKind::kBlazePoseLandmark, "astronaut.png", "astronaut", true},
                      Case{SkeletonKind::kMoveNetLightning, "basketball1.png", "left_man", true},
                      Case{SkeletonKind::kBlazePoseLandmark, "basketball1.png", "left_man", true},
                      Case{SkeletonKind::kMoveNetLightning, "messi5.jpg", "messi", false},
                      Case{SkeletonKind::kBlazePoseLandmark, "messi5.jpg", "messi", false}),
    [](const auto& info) {
      std::string n = toString(info.param.kind) + "_" + info.param.person;
      return n;
    });

TEST(SkeletonExtractorTest, KeypointsFollowTheImageShift) {
  // The same person padded by (40, 30) px and the box moved with it: the crops are
  // identical, so every keypoint moves by exactly (40, 30) — the crop → image mapping has
  // no offset error. The astronaut's square crop (1.25 × 489 px) extends past the image
  // border in both cases (zero padding).
  const std::string path = imagePath("astronaut.png");
  const cv::Mat img = cv::imread(path, cv::IMREAD_COLOR);
  cv::Mat padded;
  cv::copyMakeBorder(img, padded, 30, 0, 40, 0, cv::BORDER_CONSTANT, cv::Scalar::all(0));
  const cv::Rect2f box = label("astronaut.png", "astronaut");
  for (SkeletonKind kind : {SkeletonKind::kMoveNetLightning, SkeletonKind::kBlazePoseLandmark}) {
    auto ext = makeExtractor(kind);
    ASSERT_TRUE(ext);
    auto s = ext->extract(img, box);
    auto s2 = ext->extract(padded, cv::Rect2f(box.x + 40, box.y + 30, box.width, box.height));
    ASSERT_TRUE(s && s2);
    for (std::size_t k = 0; k < static_cast<std::size_t>(kNumKeypoints); ++k) {
      EXPECT_NEAR((*s)[k].x + 40.0f, (*s2)[k].x, 0.5f) << toString(kind) << " " << cocoKeypointNames()[k];
      EXPECT_NEAR((*s)[k].y + 30.0f, (*s2)[k].y, 0.5f) << toString(kind) << " " << cocoKeypointNames()[k];
      EXPECT_NEAR((*s)[k].c, (*s2)[k].c, 1e-3f);
    }
  }
}

TEST(SkeletonExtractorTest, BadInputGivesReasons) {
  for (SkeletonKind kind : {SkeletonKind::kMoveNetLightning, SkeletonKind::kBlazePoseLandmark}) {
    auto ext = makeExtractor(kind);
    ASSERT_TRUE(ext);
    const cv::Mat ok(100, 100, CV_8UC3, cv::Scalar(0));
    auto empty = ext->extract(cv::Mat(), {10, 10, 20, 40});
    ASSERT_FALSE(empty);
    EXPECT_NE(empty.reason().find("empty"), std::string::npos) << empty.reason();
    auto gray = ext->extract(cv::Mat(100, 100, CV_8UC1), {10, 10, 20, 40});
    ASSERT_FALSE(gray);
    EXPECT_NE(gray.reason().find("3 channels"), std::string::npos) << gray.reason();
    auto u16 = ext->extract(cv::Mat(100, 100, CV_16UC3), {10, 10, 20, 40});
    ASSERT_FALSE(u16);
    EXPECT_NE(u16.reason().find("8-bit"), std::string::npos) << u16.reason();
    auto zero_box = ext->extract(ok, {10, 10, 0, 40});
    ASSERT_FALSE(zero_box);
    EXPECT_NE(zero_box.reason().find("box"), std::string::npos) << zero_box.reason();
    auto nan_box = ext->extract(ok, {std::nanf(""), 10, 20, 40});
    ASSERT_FALSE(nan_box);
  }
  BlazePoseLandmarkConfig cfg;
  cfg.model_path = "does/not/exist.onnx";
  auto missing = BlazePoseLandmarkExtractor::create(cfg, modelsRoot());
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.reason().find("does/not/exist.onnx"), std::string::npos) << missing.reason();
}

TEST(SkeletonExtractorTest, BlazePoseToCocoMapping) {
  const auto& m = blazePoseToCoco();
  const std::array<int, kNumKeypoints> expected = {0, 2, 5, 7, 8, 11, 12, 13, 14, 15, 16, 23, 24, 25, 26, 27, 28};
  EXPECT_EQ(m, expected);
}

}  // namespace
}  // namespace gesture_formation::perception

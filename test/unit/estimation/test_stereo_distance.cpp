#include <gtest/gtest.h>

#include "gesture_formation/estimation/stereo_distance.hpp"

using namespace gesture_formation::estimation;

namespace {
const CameraModel kCam{CameraIntrinsics{}};
}

TEST(StereoDistanceTest, MedianOfValidDepthsConvertedToRange) {
  cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(0));
  // Box centred 123 px right of the principal point, person at 5 m optical depth, a few
  // background pixels at 9 m and holes (0) that must be ignored.
  const Box box{320.0 + 123.0 - 20.0, 200.0, 40.0, 80.0};
  depth(cv::Rect(423, 200, 40, 80)).setTo(5000);
  depth(cv::Rect(423, 200, 40, 10)).setTo(9000);
  depth(cv::Rect(423, 270, 40, 10)).setTo(0);
  StereoDistanceConfig cfg;
  const auto d = stereoDistance(depth, box, kCam, cfg);
  ASSERT_TRUE(d) << d.reason();
  const double x = 123.0 / 615.0, y = 0.0;  // centre (443, 240)
  EXPECT_NEAR(*d, 5.0 * std::sqrt(1 + x * x + y * y), 1e-9);
}

TEST(StereoDistanceTest, FloatDepthIgnoresNaN) {
  cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(std::nanf("")));
  depth(cv::Rect(300, 200, 40, 80)).setTo(3.0f);
  const Box box{300.0, 200.0, 40.0, 80.0};
  const auto d = stereoDistance(depth, box, kCam, StereoDistanceConfig{});
  ASSERT_TRUE(d) << d.reason();
  EXPECT_NEAR(*d, 3.0 / kCam.rayThroughPixel(box.centre())->z(), 1e-6);
}

TEST(StereoDistanceTest, EvenCountMedianIsMeanOfMiddleValues) {
  cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(0.0f));
  // 20 px at 2 m and 20 px at 4 m, centred on the optical axis → median 3 m.
  depth(cv::Rect(310, 230, 20, 1)).setTo(2.0f);
  depth(cv::Rect(310, 231, 20, 1)).setTo(4.0f);
  StereoDistanceConfig cfg;
  cfg.min_valid_fraction = 0.0;
  const auto d = stereoDistance(depth, Box{310.0, 230.0, 20.0, 20.0}, kCam, cfg);
  ASSERT_TRUE(d) << d.reason();
  EXPECT_NEAR(*d, 3.0 / kCam.rayThroughPixel(Eigen::Vector2d(320, 240))->z(), 1e-6);
}

TEST(StereoDistanceTest, TooFewValidPixelsIsUnavailable) {
  cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(0));
  depth(cv::Rect(300, 200, 3, 3)).setTo(4000);
  const auto d = stereoDistance(depth, Box{300, 200, 40, 80}, kCam, StereoDistanceConfig{});
  ASSERT_FALSE(d);
  EXPECT_NE(d.reason().find("too few valid depth pixels (9 of 3200)"), std::string::npos) << d.reason();
}

TEST(StereoDistanceTest, OutOfRangeDepthsIgnored) {
  cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(60000));  // 60 m > max 20 m
  const auto d = stereoDistance(depth, Box{300, 200, 40, 80}, kCam, StereoDistanceConfig{});
  EXPECT_FALSE(d);
}

TEST(StereoDistanceTest, BadImagesAndBoxesRejected) {
  const Box box{300, 200, 40, 80};
  EXPECT_FALSE(stereoDistance(cv::Mat(), box, kCam, StereoDistanceConfig{}));
  const auto wrong = stereoDistance(cv::Mat(480, 640, CV_8UC3), box, kCam, StereoDistanceConfig{});
  ASSERT_FALSE(wrong);
  EXPECT_NE(wrong.reason().find("CV_16UC1 or CV_32FC1"), std::string::npos);
  cv::Mat depth(480, 640, CV_16UC1, cv::Scalar(3000));
  EXPECT_FALSE(stereoDistance(depth, Box{700, 600, 40, 80}, kCam, StereoDistanceConfig{}));
  EXPECT_FALSE(stereoDistance(depth, Box{300, 200, 0, 80}, kCam, StereoDistanceConfig{}));
  EXPECT_FALSE(stereoDistance(depth, Box{std::nan(""), 200, 10, 80}, kCam, StereoDistanceConfig{}));
}

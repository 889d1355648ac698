#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include <opencv2/calib3d.hpp>

#include "gesture_formation/estimation/camera_model.hpp"

using namespace gesture_formation::estimation;

namespace {
CameraIntrinsics distorted() {
  CameraIntrinsics k;
  k.fx = 610.0;
  k.fy = 612.0;
  k.cx = 318.0;
  k.cy = 243.0;
  k.distortion = {0.12, -0.25, 0.001, -0.002, 0.08};
  return k;
}
}  // namespace

TEST(CameraModelTest, PrincipalPointRayIsOpticalAxis) {
  const CameraModel cam(distorted());
  const auto ray = cam.rayThroughPixel(Eigen::Vector2d(318.0, 243.0));
  ASSERT_TRUE(ray);
  EXPECT_NEAR((*ray - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
}

TEST(CameraModelTest, PinholeRayHandDerived) {
  const CameraModel cam{CameraIntrinsics{}};  // fx = fy = 615, (320, 240), no distortion
  const auto ray = cam.rayThroughPixel(Eigen::Vector2d(320.0 + 615.0, 240.0));
  ASSERT_TRUE(ray);
  EXPECT_NEAR(ray->x(), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(ray->z(), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(ray->y(), 0.0, 1e-12);
}

TEST(CameraModelTest, ProjectThenRayRoundTripsWithDistortion) {
  const CameraModel cam(distorted());
  std::mt19937 rng(7);
  // Points inside the 640×480 field of view (|x/z| ≤ 0.52, |y/z| ≤ 0.39): a plumb_bob model
  // is only invertible over the region it was calibrated on; far outside, k3 folds it back.
  std::uniform_real_distribution<double> ux(-0.52, 0.52), uy(-0.39, 0.39), uz(1.0, 20.0);
  for (int i = 0; i < 500; ++i) {
    const double z = uz(rng);
    const Eigen::Vector3d p(ux(rng) * z, uy(rng) * z, z);
    const auto px = cam.project(p);
    ASSERT_TRUE(px);
    const auto ray = cam.rayThroughPixel(*px);
    ASSERT_TRUE(ray);
    EXPECT_NEAR((*ray - p.normalized()).norm(), 0.0, 1e-10);
  }
}

TEST(CameraModelTest, UndistortMatchesOpenCV) {
  const CameraIntrinsics k = distorted();
  const CameraModel cam(k);
  cv::Mat K = (cv::Mat_<double>(3, 3) << k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1);
  cv::Mat D(1, 5, CV_64F);
  for (int i = 0; i < 5; ++i) D.at<double>(i) = k.distortion[static_cast<std::size_t>(i)];
  std::vector<cv::Point2d> src, dst;
  for (double u = 10; u < 640; u += 57) {
    for (double v = 10; v < 480; v += 43) src.emplace_back(u, v);
  }
  cv::undistortPoints(src, dst, K, D, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-15));
  for (std::size_t i = 0; i < src.size(); ++i) {
    const auto xy = cam.undistortPixel(Eigen::Vector2d(src[i].x, src[i].y));
    ASSERT_TRUE(xy);
    EXPECT_NEAR(xy->x(), dst[i].x, 1e-9) << "pixel " << src[i];
    EXPECT_NEAR(xy->y(), dst[i].y, 1e-9) << "pixel " << src[i];
  }
}

TEST(CameraModelTest, NonFiniteAndBehindCameraRejected) {
  const CameraModel cam(distorted());
  EXPECT_FALSE(cam.rayThroughPixel(Eigen::Vector2d(std::nan(""), 3.0)));
  EXPECT_FALSE(cam.project(Eigen::Vector3d(0, 0, -1)));
  EXPECT_FALSE(cam.project(Eigen::Vector3d(0, 0, std::nan(""))));
}

TEST(CameraModelTest, ValidateNamesFields) {
  CameraIntrinsics k;
  k.fx = -1;
  k.width_px = 0;
  const auto e = k.validate();
  ASSERT_EQ(e.size(), 2u);
  EXPECT_NE(e[0].find("camera.fx"), std::string::npos);
  EXPECT_NE(e[1].find("camera.width"), std::string::npos);
}

// CameraInfo's calibration is the full sensor's (REP 104); a camera that bins or reads out a region
// publishes a smaller image, and a pixel of it must back-project through the intrinsics of that image.
TEST(CameraModelTest, ReadoutIntrinsicsMapFullSensorPixelsToTheBinnedRegion) {
  CameraIntrinsics full = distorted();
  full.fx = 1220.0;
  full.fy = 1224.0;
  full.cx = 636.0;
  full.cy = 486.0;
  full.width_px = 1280;
  full.height_px = 960;
  const CameraModel full_model(full);
  for (const SensorReadout& r : {SensorReadout{2, 2, 0, 0, 0, 0}, SensorReadout{0, 0, 320, 240, 640, 480},
                                SensorReadout{2, 3, 100, 60, 1000, 840}, SensorReadout{1, 1, 0, 0, 0, 0}}) {
    const auto k = readoutIntrinsics(full, r);
    ASSERT_TRUE(k) << k.reason();
    const int bx = std::max(1, r.binning_x), by = std::max(1, r.binning_y);
    EXPECT_EQ(k->width_px, (r.roi_width ? r.roi_width : 1280) / bx);
    EXPECT_EQ(k->height_px, (r.roi_height ? r.roi_height : 960) / by);
    EXPECT_EQ(k->distortion, full.distortion);
    const CameraModel model(*k);
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.3, -0.2, 4.0), Eigen::Vector3d(-0.8, 0.5, 6.0), Eigen::Vector3d(0.0, 0.0, 9.0)}) {
      const auto uv_full = full_model.project(p);
      const auto uv = model.project(p);
      ASSERT_TRUE(uv_full && uv);
      // full pixel u covers binned pixel (u - offset - (b - 1)/2) / b (pixel centres at integers)
      EXPECT_NEAR(uv->x(), (uv_full->x() - r.roi_x_offset - 0.5 * (bx - 1)) / bx, 1e-9);
      EXPECT_NEAR(uv->y(), (uv_full->y() - r.roi_y_offset - 0.5 * (by - 1)) / by, 1e-9);
    }
  }
  const SensorReadout none{};
  const auto same = readoutIntrinsics(full, none);
  ASSERT_TRUE(same);
  EXPECT_EQ(same->fx, full.fx);
  EXPECT_EQ(same->cx, full.cx);
  EXPECT_EQ(same->width_px, full.width_px);
}

TEST(CameraModelTest, ReadoutIntrinsicsRefuseAnImpossibleReadoutNamingIt) {
  CameraIntrinsics full;  // 640x480
  auto reason = [&](const SensorReadout& r) {
    const auto k = readoutIntrinsics(full, r);
    EXPECT_FALSE(k);
    return k ? std::string() : k.reason();
  };
  EXPECT_NE(reason({0, 0, 400, 0, 300, 480}).find("outside the 640x480 sensor"), std::string::npos);
  EXPECT_NE(reason({0, 0, 0, 0, 320, 0}).find("roi 320x0"), std::string::npos);
  EXPECT_NE(reason({0, 0, 10, 0, 0, 0}).find("roi offset (10, 0)"), std::string::npos);
  const std::string negative = reason({-2, 0, 0, -1, 0, 0});
  EXPECT_NE(negative.find("binning_x -2"), std::string::npos);
  EXPECT_NE(negative.find("roi.y_offset -1"), std::string::npos);
  EXPECT_NE(reason({1000, 1, 0, 0, 0, 0}).find("leaves no pixel"), std::string::npos);
  EXPECT_NE(reason({0, 0, 1 << 30, 0, 1 << 30, 480}).find("outside"), std::string::npos);  // no int overflow
}

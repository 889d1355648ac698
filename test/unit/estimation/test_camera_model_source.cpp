// estimation::CameraModelSource: the estimator's camera model from the camera's CameraInfo, or
// the configuration's camera section as an explicit override.
#include <gtest/gtest.h>

#include "gesture_formation/estimation/camera_model_source.hpp"

using namespace gesture_formation::estimation;

namespace {
CameraIntrinsics driverCamera() {
  CameraIntrinsics k;
  k.fx = 605.0;
  k.fy = 604.0;
  k.cx = 331.0;
  k.cy = 247.0;
  k.distortion = {0.1, -0.2, 0.0, 0.0, 0.05};
  return k;
}
}  // namespace

TEST(CameraModelSourceTest, CameraInfoSourceRefusesUntilIntrinsicsArriveThenUsesTheCamerasOwn) {
  CameraModelSource s(IntrinsicsSource::kCameraInfo, CameraIntrinsics{});
  EXPECT_EQ(s.model(), nullptr);
  EXPECT_NE(s.refusal().find("no camera intrinsics"), std::string::npos);
  const auto r = s.receive(driverCamera());
  ASSERT_TRUE(r);
  EXPECT_TRUE(*r);
  ASSERT_NE(s.model(), nullptr);
  EXPECT_TRUE(s.refusal().empty());
  EXPECT_DOUBLE_EQ(s.model()->intrinsics().cx, 331.0);
  EXPECT_DOUBLE_EQ(s.model()->intrinsics().distortion[0], 0.1);
  EXPECT_FALSE(*s.receive(driverCamera()));  // every image repeats it: no change
  auto recalibrated = driverCamera();
  recalibrated.fx = 600.0;
  EXPECT_TRUE(*s.receive(recalibrated));
  EXPECT_DOUBLE_EQ(s.model()->intrinsics().fx, 600.0);
}

TEST(CameraModelSourceTest, ConfigSourceKeepsTheConfigurationsCameraWhateverArrives) {
  CameraIntrinsics config;
  config.cx = 300.0;
  CameraModelSource s(IntrinsicsSource::kConfig, config);
  ASSERT_NE(s.model(), nullptr);
  EXPECT_FALSE(*s.receive(driverCamera()));
  EXPECT_DOUBLE_EQ(s.model()->intrinsics().cx, 300.0);
}

TEST(CameraModelSourceTest, InvalidIntrinsicsAreRefusedNamingTheFieldAndTheModelIsKept) {
  CameraModelSource s(IntrinsicsSource::kCameraInfo, CameraIntrinsics{});
  ASSERT_TRUE(s.receive(driverCamera()));
  auto bad = driverCamera();
  bad.fx = 0.0;  // an uncalibrated driver publishes K = 0
  const auto r = s.receive(bad);
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find("fx"), std::string::npos) << r.reason();
  EXPECT_DOUBLE_EQ(s.model()->intrinsics().fx, 605.0);
}

TEST(CameraModelSourceTest, SourceNamesParseAndOthersAreRefusedNamingTheValue) {
  EXPECT_EQ(*parseIntrinsicsSource("camera_info"), IntrinsicsSource::kCameraInfo);
  EXPECT_EQ(*parseIntrinsicsSource("config"), IntrinsicsSource::kConfig);
  const auto r = parseIntrinsicsSource("yaml");
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find("'yaml'"), std::string::npos);
}

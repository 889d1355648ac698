#include <gtest/gtest.h>

#include "gesture_formation/estimation/measurement_model.hpp"

using namespace gesture_formation::estimation;

namespace {

/// Camera at (0, 0, 2) looking along world +x: optical z → world x, optical x (right) →
/// world −y, optical y (down) → world −z.
CameraPose lookingAlongX() {
  Eigen::Matrix3d R;
  R.col(0) = Eigen::Vector3d(0, -1, 0);
  R.col(1) = Eigen::Vector3d(0, 0, -1);
  R.col(2) = Eigen::Vector3d(1, 0, 0);
  CameraPose pose;
  pose.t_world_camera = Eigen::Vector3d(0, 0, 2);
  pose.q_world_camera = Eigen::Quaterniond(R);
  return pose;
}

Box centredBox(double w, double h) { return Box{320.0 - w / 2, 240.0 - h / 2, w, h}; }

const CameraModel kCam{CameraIntrinsics{}};
const MeasurementNoise kNoise{};
constexpr double kMaxApparentM = 40.0;  // config/estimator.yaml

}  // namespace

TEST(MeasurementModelTest, UwbMeasurementHandDerived) {
  const auto m = makeMeasurement(kCam, lookingAlongX(), centredBox(40, 100), 10.0, 7.0, 1.75, kNoise, kMaxApparentM);
  ASSERT_TRUE(m) << m.reason();
  EXPECT_EQ(m->source, DistanceSource::kUwb);
  EXPECT_NEAR((m->z_world - Eigen::Vector3d(10, 0, 2)).norm(), 0.0, 1e-12);
  // Σ = R diag(σxy², σxy², σz²) Rᵀ: world x gets σz², y and z get σxy².
  EXPECT_NEAR(m->sigma_world(0, 0), 0.1 * 0.1, 1e-15);
  EXPECT_NEAR(m->sigma_world(1, 1), 0.05 * 0.05, 1e-15);
  EXPECT_NEAR(m->sigma_world(2, 2), 0.05 * 0.05, 1e-15);
  EXPECT_NEAR(m->sigma_world(0, 1), 0.0, 1e-15);
}

TEST(MeasurementModelTest, OffAxisBoxRotatesRay) {
  // Box centre 615 px right of the principal point → 45° to the right → world −y.
  Box b{320.0 + 615.0 - 10.0, 230.0, 20.0, 20.0};
  CameraIntrinsics k;
  k.width_px = 2000;  // let the centre be inside the image
  const CameraModel cam(k);
  const auto m = makeMeasurement(cam, lookingAlongX(), b, std::sqrt(2.0) * 5.0, std::nan(""), 1.75, kNoise, kMaxApparentM);
  ASSERT_TRUE(m) << m.reason();
  EXPECT_NEAR((m->z_world - Eigen::Vector3d(5, -5, 2)).norm(), 0.0, 1e-12);
}

TEST(MeasurementModelTest, ApparentDistanceOfWorkerAtKnownDistance) {
  for (double D : {4.0, 8.0, 12.0, 15.0, 25.0}) {
    const double H = 1.75;
    const double h_px = 2.0 * 615.0 * (H / 2.0) / D;  // top and bottom at ±H/2 on the optical axis
    const auto d = apparentDistance(kCam, centredBox(0.4 * h_px, h_px), H);
    ASSERT_TRUE(d);
    EXPECT_NEAR(*d, D, 1e-9) << "D=" << D;
  }
}

TEST(MeasurementModelTest, SourceSwitchingUwbStereoApparent) {
  const Box b = centredBox(30, 90);
  auto m = makeMeasurement(kCam, lookingAlongX(), b, 9.0, 8.0, 1.75, kNoise, kMaxApparentM);
  EXPECT_EQ(m->source, DistanceSource::kUwb);
  EXPECT_DOUBLE_EQ(m->distance_m, 9.0);
  m = makeMeasurement(kCam, lookingAlongX(), b, std::nan(""), 8.0, 1.75, kNoise, kMaxApparentM);
  EXPECT_EQ(m->source, DistanceSource::kStereo);
  EXPECT_DOUBLE_EQ(m->distance_m, 8.0);
  EXPECT_NEAR(m->sigma_world(0, 0), 0.09, 1e-15);
  m = makeMeasurement(kCam, lookingAlongX(), b, -1.0, INFINITY, 1.75, kNoise, kMaxApparentM);  // garbage → unavailable
  EXPECT_EQ(m->source, DistanceSource::kApparent);
  EXPECT_NEAR(m->distance_m, 1.75 * 615.0 / 90.0, 1e-9);
  EXPECT_NEAR(m->sigma_world(0, 0), 0.36, 1e-15);
}

TEST(MeasurementModelTest, BadInputRejectedWithReason) {
  const CameraPose good = lookingAlongX();
  struct Case {
    Box box;
    CameraPose pose;
    const char* expect;
  };
  CameraPose nan_pose = good;
  nan_pose.t_world_camera.x() = std::nan("");
  CameraPose not_unit = good;
  not_unit.q_world_camera.coeffs() *= 1.1;
  CameraPose inf_q = good;
  inf_q.q_world_camera.w() = INFINITY;
  const Case cases[] = {
      {Box{std::nan(""), 10, 20, 20}, good, "non-finite"},
      {Box{10, 10, 0, 20}, good, "size must be positive"},
      {Box{10, 10, 20, -5}, good, "size must be positive"},
      {Box{700, 10, 20, 20}, good, "outside the 640x480 image"},
      {Box{-100, 10, 20, 20}, good, "outside"},
      {centredBox(20, 20), nan_pose, "non-finite"},
      {centredBox(20, 20), not_unit, "not unit"},
      {centredBox(20, 20), inf_q, "non-finite"},
  };
  for (const auto& c : cases) {
    const auto m = makeMeasurement(kCam, c.pose, c.box, 5.0, std::nan(""), 1.75, kNoise, kMaxApparentM);
    ASSERT_FALSE(m);
    EXPECT_NE(m.reason().find(c.expect), std::string::npos) << m.reason();
  }
}

TEST(MeasurementModelTest, SlightlyNonUnitQuaternionIsNormalised) {
  CameraPose p = lookingAlongX();
  p.q_world_camera.coeffs() *= 1.0 + 5e-4;
  const auto m = makeMeasurement(kCam, p, centredBox(20, 60), 10.0, std::nan(""), 1.75, kNoise, kMaxApparentM);
  ASSERT_TRUE(m) << m.reason();
  EXPECT_NEAR((m->z_world - Eigen::Vector3d(10, 0, 2)).norm(), 0.0, 1e-12);
}

TEST(MeasurementModelTest, BoxPartlyOutsideButCentreInsideIsAccepted) {
  const auto m = makeMeasurement(kCam, lookingAlongX(), Box{-10, 100, 40, 100}, 10.0, std::nan(""), 1.75, kNoise, kMaxApparentM);
  EXPECT_TRUE(m) << m.reason();
}

// A worker 6 m away whose feet are below the image: the detector's box, cut at the bottom edge, is
// 89 of his 179 px and would put him at 12 m. Without a UWB or stereo range such a box gives no
// measurement; with one it still does (the ray is right, the range comes from the sensor).
TEST(MeasurementModelTest, ABoxClippedAtTheTopOrBottomEdgeGivesNoApparentDistance) {
  const double H = 1.75, nan = std::nan("");
  const Box clipped_bottom{300.0, 391.0, 40.0, 89.0};  // v + h = 480: the image's bottom edge
  const auto none = makeMeasurement(kCam, lookingAlongX(), clipped_bottom, nan, nan, H, kNoise, kMaxApparentM);
  ASSERT_FALSE(none);
  EXPECT_NE(none.reason().find("edge"), std::string::npos) << none.reason();
  const Box clipped_top{300.0, 0.0, 40.0, 89.0};
  EXPECT_FALSE(makeMeasurement(kCam, lookingAlongX(), clipped_top, nan, nan, H, kNoise, kMaxApparentM));
  const auto with_uwb = makeMeasurement(kCam, lookingAlongX(), clipped_bottom, 6.0, nan, H, kNoise, kMaxApparentM);
  ASSERT_TRUE(with_uwb) << with_uwb.reason();
  EXPECT_EQ(with_uwb->source, DistanceSource::kUwb);
  // One pixel inside both edges: a whole person, measured.
  const auto inside = makeMeasurement(kCam, lookingAlongX(), Box{300.0, 1.0, 40.0, 478.0}, nan, nan, H, kNoise, kMaxApparentM);
  ASSERT_TRUE(inside) << inside.reason();
  EXPECT_EQ(inside->source, DistanceSource::kApparent);
}

// A tiny box (a far or partial person, a spurious detection) put the worker a kilometre away: the
// apparent distance over max_apparent_distance_m gives no measurement; a range sensor still does.
TEST(MeasurementModelTest, AnApparentDistanceOverTheLimitGivesNoMeasurement) {
  const double H = 1.75, nan = std::nan("");
  const double fy = kCam.intrinsics().fy;
  const double h_at_limit = H * fy / kMaxApparentM;  // ~26.9 px at 615 px focal length
  const auto tiny = makeMeasurement(kCam, lookingAlongX(), centredBox(1.0, 1.0), nan, nan, H, kNoise, kMaxApparentM);
  ASSERT_FALSE(tiny);
  EXPECT_NE(tiny.reason().find("max_apparent_distance_m"), std::string::npos) << tiny.reason();
  EXPECT_FALSE(makeMeasurement(kCam, lookingAlongX(), centredBox(10.0, 0.95 * h_at_limit), nan, nan, H, kNoise, kMaxApparentM));
  const auto near_limit = makeMeasurement(kCam, lookingAlongX(), centredBox(10.0, 1.05 * h_at_limit), nan, nan, H, kNoise, kMaxApparentM);
  ASSERT_TRUE(near_limit) << near_limit.reason();
  EXPECT_EQ(near_limit->source, DistanceSource::kApparent);
  EXPECT_NEAR(near_limit->distance_m, kMaxApparentM / 1.05, 0.2);
  const auto stereo = makeMeasurement(kCam, lookingAlongX(), centredBox(1.0, 1.0), nan, 30.0, H, kNoise, kMaxApparentM);
  ASSERT_TRUE(stereo) << stereo.reason();
  EXPECT_EQ(stereo->source, DistanceSource::kStereo);
}

// The synthetic depth camera (sim::DepthRaycaster, docs/mapping.md §7): analytic depth of known
// solids, REP 103 / 118 axes of the optical frame, decimation and the "nothing within range" value.
#include <gtest/gtest.h>

#include <cmath>

#include "gesture_formation/mapping/depth_points.hpp"
#include "gesture_formation/sim/depth_raycaster.hpp"

namespace gf = gesture_formation;

namespace {

gf::estimation::CameraIntrinsics camera() {
  gf::estimation::CameraIntrinsics k;  // 640 × 480, fx = fy = 615, principal point at the centre
  return k;
}

gf::planning::OrientedBox box(const Eigen::Vector3d& centre, const Eigen::Vector3d& size) {
  gf::planning::OrientedBox b;
  b.center_world = centre;
  b.size_m = size;
  return b;
}

}  // namespace

TEST(DepthRaycasterTest, OpticalFrameFollowsRep103And118) {
  // Heading 0 (looking along +x), level: z forward = +x, x right = −y (east-north-up world), y down = −z.
  const Eigen::Isometry3d T = gf::sim::opticalPoseFromHeadingPitch(Eigen::Vector3d(1, 2, 3), 0.0, 0.0);
  EXPECT_TRUE(T.linear().col(2).isApprox(Eigen::Vector3d::UnitX(), 1e-12));
  EXPECT_TRUE(T.linear().col(0).isApprox(-Eigen::Vector3d::UnitY(), 1e-12));
  EXPECT_TRUE(T.linear().col(1).isApprox(-Eigen::Vector3d::UnitZ(), 1e-12));
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(1, 2, 3)));
  // Heading 90° (north), pitched 30° down: z forward = (0, cos 30°, −sin 30°), right = +x, a rotation.
  const Eigen::Isometry3d N = gf::sim::opticalPoseFromHeadingPitch(Eigen::Vector3d::Zero(), M_PI / 2, -M_PI / 6);
  EXPECT_TRUE(N.linear().col(2).isApprox(Eigen::Vector3d(0, std::cos(M_PI / 6), -0.5), 1e-12));
  EXPECT_TRUE(N.linear().col(0).isApprox(Eigen::Vector3d::UnitX(), 1e-12));
  EXPECT_NEAR(N.linear().determinant(), 1.0, 1e-12);
}

TEST(DepthRaycasterTest, BoxAtKnownDistanceGivesItsDepthAlongTheOpticalAxis) {
  // A wall 1 m thick whose near face is 5 m ahead of the camera (x = 5), wide and tall.
  gf::planning::PrimitiveSet solids;
  solids.boxes.push_back(box(Eigen::Vector3d(5.5, 0, 0), Eigen::Vector3d(1, 40, 40)));
  const gf::sim::DepthRaycaster caster(solids, std::nan(""));
  const auto k = camera();
  const cv::Mat d = caster.render(k, gf::sim::opticalPoseFromHeadingPitch(Eigen::Vector3d::Zero(), 0.0, 0.0), 1, 20.0);
  ASSERT_EQ(d.type(), CV_32FC1);
  ASSERT_EQ(d.cols, 640);
  ASSERT_EQ(d.rows, 480);
  // Depth is z (along the optical axis), the same 5 m at the centre and in the corners of a plane
  // facing the camera; the range along a corner ray is longer.
  EXPECT_NEAR(d.at<float>(240, 320), 5.0, 1e-5);
  EXPECT_NEAR(d.at<float>(0, 0), 5.0, 1e-5);
  EXPECT_NEAR(d.at<float>(479, 639), 5.0, 1e-5);
}

TEST(DepthRaycasterTest, ImageAxesPointRightAndDown) {
  // A box to the camera's right (−y in the world when looking along +x) and one below (−z): the
  // first fills only columns right of the centre, the second only rows below it.
  gf::planning::PrimitiveSet right, below;
  right.boxes.push_back(box(Eigen::Vector3d(4, -3, 0), Eigen::Vector3d(0.5, 4, 0.5)));
  below.boxes.push_back(box(Eigen::Vector3d(4, 0, -3), Eigen::Vector3d(0.5, 0.5, 4)));
  const auto k = camera();
  const Eigen::Isometry3d T = gf::sim::opticalPoseFromHeadingPitch(Eigen::Vector3d::Zero(), 0.0, 0.0);
  const cv::Mat dr = gf::sim::DepthRaycaster(right, std::nan("")).render(k, T, 1, 20.0);
  const cv::Mat db = gf::sim::DepthRaycaster(below, std::nan("")).render(k, T, 1, 20.0);
  EXPECT_TRUE(std::isfinite(dr.at<float>(240, 600)));
  EXPECT_TRUE(std::isinf(dr.at<float>(240, 40)));
  EXPECT_TRUE(std::isfinite(db.at<float>(460, 320)));
  EXPECT_TRUE(std::isinf(db.at<float>(20, 320)));
  // The back-projection of the mapping (mapping::depthToPoints) puts the hits where the box is.
  gf::mapping::DepthFrame f;
  f.depth_m = dr;
  f.T_world_camera = T;
  gf::mapping::MappingConfig mc;
  mc.max_range_m = 15.0;
  const auto pts = gf::mapping::depthToPoints(f, mc, 0.4);
  ASSERT_TRUE(static_cast<bool>(pts)) << pts.reason();
  ASSERT_FALSE(pts->hits_world.empty());
  for (const auto& p : pts->hits_world) EXPECT_LT(right.distance(p), 1e-4) << p.transpose();
}

TEST(DepthRaycasterTest, DecimationNothingInRangeAndTheGround) {
  gf::planning::PrimitiveSet none;
  const gf::sim::DepthRaycaster caster(none, 0.0);  // ground at z = 0
  const auto k = camera();
  // 2 m above the ground, level: the lower half sees the ground within 20 m, the upper half nothing.
  const cv::Mat d = caster.render(k, gf::sim::opticalPoseFromHeadingPitch(Eigen::Vector3d(0, 0, 2), 0.0, 0.0), 4, 20.0);
  EXPECT_TRUE(std::isnan(d.at<float>(1, 1)));    // off the decimation grid: no return
  EXPECT_TRUE(std::isinf(d.at<float>(100, 320)));  // sky: +Inf, REP 118 "too far"
  // Row v looks down by atan((v − cy)/fy): the ground at depth 2·fy/(v − cy).
  EXPECT_NEAR(d.at<float>(400, 320), 2.0 * 615.0 / (400 - 240), 1e-4);
  const float far_row = d.at<float>(244, 320);  // depth 307 m along the ray: beyond the range
  EXPECT_TRUE(std::isinf(far_row));
}

TEST(DepthRaycasterTest, CylinderHitsSideAndCaps) {
  gf::planning::Cylinder c;
  c.p0_world = Eigen::Vector3d(5, 0, -1);
  c.p1_world = Eigen::Vector3d(5, 0, 1);
  c.radius_m = 0.5;
  EXPECT_NEAR(gf::sim::rayCylinderHit(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), c), 4.5, 1e-12);  // side
  EXPECT_NEAR(gf::sim::rayCylinderHit(Eigen::Vector3d(5, 0.2, 5), -Eigen::Vector3d::UnitZ(), c), 4.0, 1e-12);  // top cap
  EXPECT_TRUE(std::isinf(gf::sim::rayCylinderHit(Eigen::Vector3d(0, 1, 0), Eigen::Vector3d::UnitX(), c)));  // passes by
  EXPECT_EQ(gf::sim::rayCylinderHit(Eigen::Vector3d(5, 0, 0), Eigen::Vector3d::UnitX(), c), 0.0);  // inside
  gf::planning::OrientedBox b = box(Eigen::Vector3d(5, 0, 0), Eigen::Vector3d(2, 2, 2));
  b.R_world_box = Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitZ()).toRotationMatrix();  // a corner towards the ray
  EXPECT_NEAR(gf::sim::rayBoxHit(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), b), 5.0 - std::sqrt(2.0), 1e-12);
}

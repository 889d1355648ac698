// The flight-stack odometry adapter and the frame checks (docs/ros.md, "Flight stacks"): each
// convention's frames pass, a wrong child_frame_id is refused naming field / expected / received,
// and a body-frame twist is rotated into the world frame as computed by hand.
#include <cmath>

#include <gtest/gtest.h>

#include "gesture_formation/onboard/frame_check.hpp"
#include "gesture_formation/onboard/odometry_adapter.hpp"

namespace gf = gesture_formation;
using gf::onboard::CameraMount;
using gf::onboard::FlightStackOdometry;
using gf::onboard::OdometryFrames;
using gf::onboard::OpticalAxis;

namespace {
constexpr double kPi = 3.14159265358979323846;
Eigen::Quaterniond yawPitchRoll(double yaw, double pitch, double roll) {
  return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX());
}
}  // namespace

// ---- frames ---------------------------------------------------------------------------------
struct ConventionCase {
  const char* name;
  OdometryFrames expected;
};
class OdometryFramesTest : public ::testing::TestWithParam<ConventionCase> {};

TEST_P(OdometryFramesTest, RightFramesPass) {
  const auto& c = GetParam();
  EXPECT_FALSE(gf::onboard::checkOdometryFrames("odometry_in", c.expected, c.expected.frame_id, c.expected.child_frame_id));
}

TEST_P(OdometryFramesTest, WrongChildFrameIsRefusedNamingFieldExpectedAndReceived) {
  const auto& c = GetParam();
  const auto e = gf::onboard::checkOdometryFrames("odometry_in", c.expected, c.expected.frame_id, "camera_link");
  ASSERT_TRUE(e);
  EXPECT_EQ(*e, "odometry_in child_frame_id: expected '" + c.expected.child_frame_id + "', received 'camera_link'");
}

TEST_P(OdometryFramesTest, WrongFixedFrameIsRefusedFirst) {
  const auto& c = GetParam();
  const auto e = gf::onboard::checkOdometryFrames("odometry_in", c.expected, "earth", "also_wrong");
  ASSERT_TRUE(e);
  EXPECT_EQ(*e, "odometry_in header.frame_id: expected '" + c.expected.frame_id + "', received 'earth'");
}

INSTANTIATE_TEST_SUITE_P(
    Conventions, OdometryFramesTest,
    ::testing::Values(ConventionCase{"mavros", {"map", "base_link"}},                   // local_position/odom
                      ConventionCase{"mrs", {"uav1/gps_garmin_origin", "uav1/fcu"}},  // odometry/odom_main
                      ConventionCase{"planner", gf::onboard::plannerOdometryFrames("world")}),
    [](const ::testing::TestParamInfo<ConventionCase>& i) { return std::string(i.param.name); });

TEST(FrameCheckTest, PlannerExpectsTheWorldFrameAsChild) {
  const OdometryFrames f = gf::onboard::plannerOdometryFrames("map");
  EXPECT_EQ(f.frame_id, "map");
  EXPECT_EQ(f.child_frame_id, "map");
  // MAVROS' odometry given to the planner directly: refused (its twist is in the body frame).
  const auto e = gf::onboard::checkOdometryFrames("odometry_in", f, "map", "base_link");
  ASSERT_TRUE(e);
  EXPECT_NE(e->find("child_frame_id: expected 'map', received 'base_link'"), std::string::npos);
}

TEST(FrameCheckTest, AnEmptyExpectedNameMatchesNothing) {
  EXPECT_TRUE(gf::onboard::checkFrame("header.frame_id", "", ""));
  EXPECT_FALSE(gf::onboard::checkFrame("header.frame_id", "map", "map"));
}

// ---- body → world twist (hand-computed) -------------------------------------------------------
TEST(OdometryAdapterTest, BodyTwistRotatedByYaw) {
  FlightStackOdometry o;
  o.q_world_body = yawPitchRoll(kPi / 2.0, 0.0, 0.0);  // nose to +y (north in ENU)
  o.v = Eigen::Vector3d(1.0, 0.0, 0.5);                // forward 1 m/s, up 0.5 m/s
  const auto s = gf::onboard::toPlannerState(o, CameraMount{});
  ASSERT_TRUE(s) << s.reason();
  EXPECT_NEAR(s->v_world.x(), 0.0, 1e-12);
  EXPECT_NEAR(s->v_world.y(), 1.0, 1e-12);
  EXPECT_NEAR(s->v_world.z(), 0.5, 1e-12);
}

TEST(OdometryAdapterTest, BodyTwistRotatedByYawThirtyDegreesAndSidewaysSpeed) {
  FlightStackOdometry o;
  o.q_world_body = yawPitchRoll(kPi / 6.0, 0.0, 0.0);
  o.v = Eigen::Vector3d(2.0, 1.0, 0.0);  // 2 m/s forward, 1 m/s to the left (FLU)
  const auto s = gf::onboard::toPlannerState(o, CameraMount{});
  ASSERT_TRUE(s);
  // x = 2 cos30 − 1 sin30 = 1.2320508; y = 2 sin30 + 1 cos30 = 1.8660254
  EXPECT_NEAR(s->v_world.x(), 1.2320508075688772, 1e-12);
  EXPECT_NEAR(s->v_world.y(), 1.8660254037844386, 1e-12);
  EXPECT_NEAR(s->v_world.z(), 0.0, 1e-12);
}

TEST(OdometryAdapterTest, BodyTwistRotatedByPitchNoseDown) {
  FlightStackOdometry o;
  o.q_world_body = yawPitchRoll(0.0, 10.0 * kPi / 180.0, 0.0);  // REP 103: +pitch about y = nose down
  o.v = Eigen::Vector3d(1.0, 0.0, 0.0);
  const auto s = gf::onboard::toPlannerState(o, CameraMount{});
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->v_world.x(), 0.98480775301220802, 1e-12);  // cos 10°
  EXPECT_NEAR(s->v_world.z(), -0.17364817766693033, 1e-12);  // −sin 10°: forward and down
}

TEST(OdometryAdapterTest, WorldTwistIsNotRotated) {
  FlightStackOdometry o;
  o.q_world_body = yawPitchRoll(1.0, 0.0, 0.0);
  o.v = Eigen::Vector3d(1.0, 2.0, 3.0);
  o.twist_in_body = false;
  const auto s = gf::onboard::toPlannerState(o, CameraMount{});
  ASSERT_TRUE(s);
  EXPECT_TRUE(s->v_world.isApprox(Eigen::Vector3d(1.0, 2.0, 3.0), 1e-15));
}

// ---- camera axis ---------------------------------------------------------------------------------
TEST(OdometryAdapterTest, FixedMountTiltedDownGivesNegativePitchAndTheBodyHeading) {
  FlightStackOdometry o;
  o.t_s = 12.5;
  o.p_world = Eigen::Vector3d(3.0, -4.0, 10.0);
  o.q_world_body = yawPitchRoll(kPi / 2.0, 0.0, 0.0);
  const CameraMount mount = CameraMount::fromRpy(0.0, 20.0 * kPi / 180.0, 0.0);  // tilted 20° down
  const auto s = gf::onboard::toPlannerState(o, mount);
  ASSERT_TRUE(s);
  EXPECT_DOUBLE_EQ(s->t_s, 12.5);
  EXPECT_TRUE(s->p_world.isApprox(o.p_world));
  EXPECT_NEAR(s->heading_rad, kPi / 2.0, 1e-12);
  EXPECT_NEAR(s->pitch_rad, -20.0 * kPi / 180.0, 1e-12);  // ξ positive up
}

TEST(OdometryAdapterTest, BodyRollDoesNotMoveAForwardCameraAxis) {
  FlightStackOdometry o;
  o.q_world_body = yawPitchRoll(-kPi / 4.0, 0.0, 0.3);  // rolled 0.3 rad: the x axis stays put
  const auto s = gf::onboard::toPlannerState(o, CameraMount{});
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->heading_rad, -kPi / 4.0, 1e-12);
  EXPECT_NEAR(s->pitch_rad, 0.0, 1e-12);
}

TEST(OdometryAdapterTest, GimbalPitchAddsToTheBodyPitch) {
  FlightStackOdometry o;
  o.q_world_body = yawPitchRoll(0.0, 0.1, 0.0);                       // flying forward, nose 0.1 rad down
  const CameraMount gimbal = CameraMount::fromRpy(0.0, -0.4, 0.0);  // gimbal 0.4 rad up relative to the body
  const auto s = gf::onboard::toPlannerState(o, gimbal);
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->pitch_rad, 0.3, 1e-12);
  EXPECT_NEAR(s->heading_rad, 0.0, 1e-12);
}

TEST(OdometryAdapterTest, OpticalFrameUsesItsZAxis) {
  // The usual camera_link → camera_optical_frame rotation (REP 103): RPY(−π/2, 0, −π/2) — z forward.
  CameraMount optical;
  optical.q_body_camera = yawPitchRoll(-kPi / 2.0, 0.0, -kPi / 2.0);
  optical.optical_axis = OpticalAxis::kZ;
  FlightStackOdometry o;
  o.q_world_body = yawPitchRoll(0.7, 0.0, 0.0);
  const auto s = gf::onboard::toPlannerState(o, optical);
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->heading_rad, 0.7, 1e-12);
  EXPECT_NEAR(s->pitch_rad, 0.0, 1e-12);
}

// ---- refusals ------------------------------------------------------------------------------------
TEST(OdometryAdapterTest, ZeroQuaternionRefusedNamingTheField) {
  FlightStackOdometry o;
  o.q_world_body = Eigen::Quaterniond(0.0, 0.0, 0.0, 0.0);
  const auto s = gf::onboard::toPlannerState(o, CameraMount{});
  ASSERT_FALSE(s);
  EXPECT_NE(s.reason().find("pose.orientation"), std::string::npos) << s.reason();
  EXPECT_NE(s.reason().find("not a rotation"), std::string::npos) << s.reason();
}

TEST(OdometryAdapterTest, NonFiniteTwistRefusedNamingTheField) {
  FlightStackOdometry o;
  o.v = Eigen::Vector3d(std::nan(""), 0.0, 0.0);
  const auto s = gf::onboard::toPlannerState(o, CameraMount{});
  ASSERT_FALSE(s);
  EXPECT_NE(s.reason().find("twist.linear"), std::string::npos) << s.reason();
}

TEST(OdometryAdapterTest, VerticalCameraAxisRefused) {
  FlightStackOdometry o;
  const auto s = gf::onboard::toPlannerState(o, CameraMount::fromRpy(0.0, kPi / 2.0, 0.0));  // straight down
  ASSERT_FALSE(s);
  EXPECT_NE(s.reason().find("vertical"), std::string::npos) << s.reason();
}

TEST(OdometryAdapterTest, SlightlyDenormalisedQuaternionIsNormalised) {
  FlightStackOdometry o;
  o.q_world_body = Eigen::Quaterniond(std::cos(0.25) * 1.01, 0.0, 0.0, std::sin(0.25) * 1.01);  // yaw 0.5 rad, |q| 1.01
  const auto s = gf::onboard::toPlannerState(o, CameraMount{});
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->heading_rad, 0.5, 1e-12);
}

// A replanning at t starts from the state at t: the odometry 0.3 s old is carried along its
// velocity (before, a plan at 3 m/s started 0.9 m behind the UAV); a stamp after t is taken as is.
TEST(OdometryAdapterTest, TheStateIsCarriedToTheReplanningTime) {
  gf::planning::UavKinematicState odom;
  odom.t_s = 10.0;
  odom.p_world = Eigen::Vector3d(1.0, 2.0, 5.0);
  odom.v_world = Eigen::Vector3d(3.0, 0.0, -0.5);
  odom.heading_rad = 0.4;
  odom.pitch_rad = -0.2;
  const auto s = gf::onboard::carriedTo(odom, 10.0, 10.3);
  EXPECT_NEAR((s.p_world - Eigen::Vector3d(1.9, 2.0, 4.85)).norm(), 0.0, 1e-12);
  EXPECT_EQ(s.v_world, odom.v_world);
  EXPECT_DOUBLE_EQ(s.heading_rad, 0.4);
  EXPECT_DOUBLE_EQ(s.pitch_rad, -0.2);
  EXPECT_DOUBLE_EQ(s.t_s, 10.3);
  const auto ahead = gf::onboard::carriedTo(odom, 10.05, 10.0);
  EXPECT_EQ(ahead.p_world, odom.p_world);
  EXPECT_DOUBLE_EQ(ahead.t_s, 10.0);
}

// Depth aligned to the colour image: same size, same frame where both name one (a leading '/' aside).
TEST(FrameCheckTest, DepthMustBeAlignedToTheColourImage) {
  EXPECT_FALSE(gesture_formation::onboard::depthAlignmentProblem(640, 480, "cam", 640, 480, "/cam"));
  EXPECT_FALSE(gesture_formation::onboard::depthAlignmentProblem(640, 480, "", 640, 480, "cam"));
  const auto frame = gesture_formation::onboard::depthAlignmentProblem(640, 480, "depth", 640, 480, "cam");
  ASSERT_TRUE(frame);
  EXPECT_EQ(*frame, "depth image 640x480 in 'depth', the colour image 640x480 in 'cam' (depth aligned to the colour image expected)");
  EXPECT_TRUE(gesture_formation::onboard::depthAlignmentProblem(848, 480, "cam", 640, 480, "cam"));
}

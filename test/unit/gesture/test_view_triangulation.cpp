// gesture/view_triangulation.hpp: 3-D skeleton from calibrated views and design.md §2's one-arm
// gestures tested in it (docs/gestures.md §6, the step after the 2-of-3 vote).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <random>

#include <Eigen/Geometry>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/gesture/skeleton_synth.hpp"
#include "gesture_formation/gesture/view_fusion.hpp"
#include "gesture_formation/gesture/view_triangulation.hpp"

namespace gf = gesture_formation;
using gf::common::degToRad;
using gf::gesture::CalibratedSkeleton;
using gf::gesture::Motion;
using gf::gesture::Skeleton3D;
using gf::gesture::SkeletonSynthesizer;
using gf::gesture::SynthConfig;
using gf::gesture::SynthSequence;
using gf::gesture::TriangulationConfig;

namespace {

/// The generator's viewpoint without its aim jitter (which the tests then meet as a pose error of
/// ~0.2–0.4°), the body frame being the world.
CalibratedSkeleton cameraAt(double d, double e_deg, double a_deg, double aim_z) {
  return gf::gesture::cameraAround(d, e_deg, a_deg, aim_z);
}

/// Projects a body exactly (no noise) into a camera: confidence 1 where it lands in the image.
void projectInto(const gf::gesture::Body3D& body, CalibratedSkeleton& cam) {
  const gf::estimation::CameraModel model(cam.intrinsics);
  for (int k = 0; k < gf::gesture::kNumKeypoints; ++k) {
    const auto i = static_cast<std::size_t>(k);
    const auto px = model.project(cam.R_world_camera.transpose() * (body.p[i] - cam.p_world_camera));
    cam.skeleton.c[i] = px ? 1.0 : 0.0;
    if (px) {
      cam.skeleton.x[i] = px->x();
      cam.skeleton.y[i] = px->y();
    }
  }
}

}  // namespace

TEST(ViewTriangulationTest, ExactViewsRecoverTheBodyAndItsFrame) {
  SkeletonSynthesizer synth(SynthConfig{}, 3);
  const gf::gesture::Body3D body = synth.pose(Motion::kExtendArmSide, 1.0, 0.0, true);
  std::vector<CalibratedSkeleton> views{cameraAt(10.0, 20.0, 0.0, 1.0), cameraAt(9.0, 30.0, 60.0, 1.0),
                                        cameraAt(12.0, 15.0, -60.0, 1.0)};
  for (auto& v : views) projectInto(body, v);
  const Skeleton3D s = gf::gesture::triangulate(views, TriangulationConfig{});
  for (int k = 0; k < gf::gesture::kNumKeypoints; ++k) {
    const auto i = static_cast<std::size_t>(k);
    ASSERT_TRUE(s.valid[i]) << "keypoint " << k;
    EXPECT_EQ(s.views[i], 3);
    EXPECT_LT((s.p_world[i] - body.p[i]).norm(), 1e-6) << "keypoint " << k;
    EXPECT_LT(s.reprojection_px[i], 1e-4);
  }
  // The body frame of the generator's body is the world frame (it stands upright, facing +x).
  const auto frame = gf::gesture::bodyFrameOf(s);
  ASSERT_TRUE(frame);
  EXPECT_LT((frame->R_world_body - Eigen::Matrix3d::Identity()).norm(), 0.05);
  // Its left arm is extended (abduction 70–110°, ±15° forward: ≤ 25° from +y), the right hangs.
  const auto left = gf::gesture::armGeometry(s, true), right = gf::gesture::armGeometry(s, false);
  ASSERT_TRUE(left.valid && right.valid);
  EXPECT_LE(left.from_outward_deg, 25.5);
  EXPECT_GT(left.reach_ratio, 0.99);
  EXPECT_GT(right.from_up_deg, 150.0);
  // It stands upright, feet under the hips.
  const gf::gesture::Stance stance = gf::gesture::stanceOf(s);
  ASSERT_TRUE(stance.valid);
  EXPECT_LT(stance.trunk_tilt_deg, 5.0);
  EXPECT_LT(stance.foot_offset_torso, 0.5);
  EXPECT_EQ(gf::gesture::oneArmGesture3D(s), gf::gesture::kExtendArmSide);
}

/// The skeleton with every left/right pair exchanged: how a skeleton network names the sides of a
/// person it sees from behind (by the image's sides).
void mirrorLabels(CalibratedSkeleton& cam) {
  auto& sk = cam.skeleton;
  for (const auto& [a, b] : {std::pair{1, 2}, std::pair{3, 4}, std::pair{5, 6}, std::pair{7, 8}, std::pair{9, 10},
                             std::pair{11, 12}, std::pair{13, 14}, std::pair{15, 16}}) {
    const auto i = static_cast<std::size_t>(a), j = static_cast<std::size_t>(b);
    std::swap(sk.x[i], sk.x[j]);
    std::swap(sk.y[i], sk.y[j]);
    std::swap(sk.c[i], sk.c[j]);
  }
}

TEST(ViewTriangulationTest, ResolveSidesTakesAViewThatNamedTheSidesFromBehindAsMirrored) {
  SkeletonSynthesizer synth(SynthConfig{}, 13);
  const gf::gesture::Body3D body = synth.pose(Motion::kExtendArmSide, 1.0, 0.0, true);
  // Leader in front-left, one follower behind the worker (150°), one beside (-90°).
  std::vector<CalibratedSkeleton> views{cameraAt(10.0, 20.0, 30.0, 1.0), cameraAt(9.0, 25.0, 150.0, 1.0),
                                        cameraAt(11.0, 15.0, -90.0, 1.0)};
  for (auto& v : views) projectInto(body, v);
  mirrorLabels(views[1]);  // the view from behind names the sides by the image's
  const Skeleton3D plain = gf::gesture::triangulate(views, TriangulationConfig{});
  const auto plain_frame = gf::gesture::bodyFrameOf(plain);
  // Without resolving, the shoulders triangulate between the two true ones: no usable body frame, or a wrong one.
  const bool plain_right = plain_frame && (plain_frame->R_world_body - Eigen::Matrix3d::Identity()).norm() < 0.05;
  EXPECT_FALSE(plain_right);
  TriangulationConfig resolve;
  resolve.resolve_sides = true;
  const Skeleton3D s = gf::gesture::triangulate(views, resolve);
  EXPECT_EQ(s.mirrored_views, 2U);  // view 1 only
  EXPECT_FALSE(s.mirrored_all);
  for (int k = 0; k < gf::gesture::kNumKeypoints; ++k) {
    const auto i = static_cast<std::size_t>(k);
    ASSERT_TRUE(s.valid[i]) << "keypoint " << k;
    EXPECT_LT((s.p_world[i] - body.p[i]).norm(), 1e-6) << "keypoint " << k;
  }
  EXPECT_EQ(gf::gesture::oneArmGesture3D(s), gf::gesture::kExtendArmSide);
  // Correctly named views stay as they are.
  for (auto& v : views) projectInto(body, v);
  EXPECT_EQ(gf::gesture::triangulate(views, resolve).mirrored_views, 0U);
}

TEST(ViewTriangulationTest, ResolveSidesMirrorsEveryLabelWhenAllViewsNamedThemFromBehind) {
  SkeletonSynthesizer synth(SynthConfig{}, 14);
  const gf::gesture::Body3D body = synth.pose(Motion::kRaiseArmUp, 1.0, 0.0, true);
  std::vector<CalibratedSkeleton> views{cameraAt(10.0, 20.0, 10.0, 1.0), cameraAt(9.0, 25.0, 70.0, 1.0),
                                        cameraAt(11.0, 15.0, -50.0, 1.0)};
  for (auto& v : views) {
    projectInto(body, v);
    mirrorLabels(v);  // all three agree, all wrong: the body would face backwards, its raised arm swap sides
  }
  const Skeleton3D plain = gf::gesture::triangulate(views, TriangulationConfig{});
  const auto plain_frame = gf::gesture::bodyFrameOf(plain);
  ASSERT_TRUE(plain_frame);
  EXPECT_LT(plain_frame->R_world_body(0, 0), -0.9);  // forward axis backwards
  TriangulationConfig resolve;
  resolve.resolve_sides = true;
  const Skeleton3D s = gf::gesture::triangulate(views, resolve);
  EXPECT_TRUE(s.mirrored_all);  // the nose lies in front of the body
  const auto frame = gf::gesture::bodyFrameOf(s);
  ASSERT_TRUE(frame);
  EXPECT_LT((frame->R_world_body - Eigen::Matrix3d::Identity()).norm(), 0.05);
  for (int k = 0; k < gf::gesture::kNumKeypoints; ++k) {
    const auto i = static_cast<std::size_t>(k);
    ASSERT_TRUE(s.valid[i]);
    EXPECT_LT((s.p_world[i] - body.p[i]).norm(), 1e-6) << "keypoint " << k;
  }
  TriangulationConfig bad = resolve;
  bad.nose_behind_m = -0.1;
  ASSERT_EQ(bad.validate().size(), 1u);
  EXPECT_NE(bad.validate()[0].find("nose_behind_m"), std::string::npos);
}

// A side kick or a lunge can hold an arm exactly where "extend" holds it (docs/gestures.md §6):
// the arm test alone says "extend"; the stance says no. Exact views, so the numbers are the body's.
TEST(ViewTriangulationTest, TheArmOfTheGestureWithoutAnUprightStanceIsNoGesture) {
  SkeletonSynthesizer synth(SynthConfig{}, 3);
  const gf::gesture::Body3D upright = synth.pose(Motion::kExtendArmSide, 1.0, 0.0, true);
  const auto seen = [](const gf::gesture::Body3D& body) {
    std::vector<CalibratedSkeleton> views{cameraAt(10.0, 20.0, 0.0, 1.0), cameraAt(9.0, 30.0, 60.0, 1.0),
                                          cameraAt(12.0, 15.0, -60.0, 1.0)};
    for (auto& v : views) projectInto(body, v);
    return gf::gesture::triangulate(views, TriangulationConfig{});
  };
  const auto i = [](int k) { return static_cast<std::size_t>(k); };
  const Eigen::Vector3d hip = 0.5 * (upright.p[i(gf::gesture::kLeftHip)] + upright.p[i(gf::gesture::kRightHip)]);
  const double torso = (0.5 * (upright.p[i(gf::gesture::kLeftShoulder)] + upright.p[i(gf::gesture::kRightShoulder)]) - hip).norm();
  // The right foot kicked out sideways (the arm is the left one): 1.0 torso lengths from the hips.
  gf::gesture::Body3D kick = upright;
  kick.p[i(gf::gesture::kRightAnkle)] = hip + Eigen::Vector3d(0.0, -1.0 * torso, 0.15);
  const Skeleton3D sk = seen(kick);
  EXPECT_LT(gf::gesture::armGeometry(sk, true).from_outward_deg, 25.5);  // the arm is the gesture's
  EXPECT_NEAR(gf::gesture::stanceOf(sk).foot_offset_torso, 1.0, 1e-6);
  EXPECT_EQ(gf::gesture::oneArmGesture3D(sk), gf::gesture::kNone);
  // The whole body leaning 30° sideways about the hips (arm and all: still "extended" in the body frame).
  gf::gesture::Body3D lean = upright;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(degToRad(30.0), Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (int k : {gf::gesture::kNose, gf::gesture::kLeftEye, gf::gesture::kRightEye, gf::gesture::kLeftEar,
                gf::gesture::kRightEar, gf::gesture::kLeftShoulder, gf::gesture::kRightShoulder, gf::gesture::kLeftElbow,
                gf::gesture::kRightElbow, gf::gesture::kLeftWrist, gf::gesture::kRightWrist}) {
    lean.p[i(k)] = hip + R * (upright.p[i(k)] - hip);
  }
  const Skeleton3D sl = seen(lean);
  EXPECT_LT(gf::gesture::armGeometry(sl, true).from_outward_deg, 25.5);
  EXPECT_NEAR(gf::gesture::stanceOf(sl).trunk_tilt_deg, gf::gesture::stanceOf(seen(upright)).trunk_tilt_deg + 30.0, 1.0);
  EXPECT_EQ(gf::gesture::oneArmGesture3D(sl), gf::gesture::kNone);
  // Just inside both limits it counts; feet unseen (no ankles): stance unknown, no gesture.
  gf::gesture::ArmGestureThresholds loose;
  loose.max_foot_offset_torso = 1.05;
  EXPECT_EQ(gf::gesture::oneArmGesture3D(sk, loose), gf::gesture::kExtendArmSide);
  loose.max_trunk_tilt_deg = 35.0;
  EXPECT_EQ(gf::gesture::oneArmGesture3D(sl, loose), gf::gesture::kExtendArmSide);
  Skeleton3D no_feet = seen(upright);
  no_feet.valid[i(gf::gesture::kLeftAnkle)] = false;
  EXPECT_FALSE(gf::gesture::stanceOf(no_feet).valid);
  EXPECT_EQ(gf::gesture::oneArmGesture3D(no_feet), gf::gesture::kNone);
}

TEST(ViewTriangulationTest, OneViewOrNearlyParallelRaysGiveNoPoint) {
  SkeletonSynthesizer synth(SynthConfig{}, 4);
  const gf::gesture::Body3D body = synth.pose(Motion::kRaiseArmUp, 1.0, 0.0, false);
  std::vector<CalibratedSkeleton> one{cameraAt(10.0, 20.0, 30.0, 1.0)};
  projectInto(body, one[0]);
  const Skeleton3D s1 = gf::gesture::triangulate(one, TriangulationConfig{});
  for (bool v : s1.valid) EXPECT_FALSE(v);
  EXPECT_FALSE(gf::gesture::bodyFrameOf(s1));
  EXPECT_EQ(gf::gesture::oneArmGesture3D(s1), gf::gesture::kNone);
  // Two cameras 3° apart (< min_ray_angle_deg 10°): no depth, nothing triangulated.
  std::vector<CalibratedSkeleton> close{cameraAt(10.0, 20.0, 30.0, 1.0), cameraAt(10.0, 20.0, 33.0, 1.0)};
  for (auto& v : close) projectInto(body, v);
  const Skeleton3D s2 = gf::gesture::triangulate(close, TriangulationConfig{});
  for (bool v : s2.valid) EXPECT_FALSE(v);
  // A keypoint one view misses (confidence 0) is triangulated from the other two.
  std::vector<CalibratedSkeleton> three{cameraAt(10.0, 20.0, 0.0, 1.0), cameraAt(9.0, 30.0, 60.0, 1.0),
                                        cameraAt(12.0, 15.0, -60.0, 1.0)};
  for (auto& v : three) projectInto(body, v);
  three[1].skeleton.c[gf::gesture::kRightWrist] = 0.0;
  three[2].skeleton.c[gf::gesture::kRightWrist] = 0.1;  // below min_confidence 0.3
  three[2].skeleton.c[gf::gesture::kNose] = 0.0;
  const Skeleton3D s3 = gf::gesture::triangulate(three, TriangulationConfig{});
  EXPECT_FALSE(s3.valid[gf::gesture::kRightWrist]);  // one view left
  EXPECT_TRUE(s3.valid[gf::gesture::kNose]);
  EXPECT_EQ(s3.views[gf::gesture::kNose], 2);
  // A view with a non-finite pose is skipped, not propagated.
  three[0].p_world_camera.x() = std::nan("");
  const Skeleton3D s4 = gf::gesture::triangulate(three, TriangulationConfig{});
  EXPECT_EQ(s4.views[gf::gesture::kLeftHip], 2);
  for (int k = 0; k < gf::gesture::kNumKeypoints; ++k) {
    if (s4.valid[static_cast<std::size_t>(k)]) {
      EXPECT_TRUE(s4.p_world[static_cast<std::size_t>(k)].allFinite());
    }
  }
}

TEST(ViewTriangulationTest, ConfigErrorsNameTheFieldAndValue) {
  TriangulationConfig c;
  EXPECT_TRUE(c.validate().empty());
  c.min_confidence = 1.5;
  c.min_ray_angle_deg = 0.0;
  const auto e = c.validate();
  ASSERT_EQ(e.size(), 2u);
  EXPECT_NE(e[0].find("min_confidence"), std::string::npos);
  EXPECT_NE(e[0].find("1.5"), std::string::npos);
  EXPECT_NE(e[1].find("min_ray_angle_deg"), std::string::npos);
  gf::gesture::ArmGestureThresholds t;
  EXPECT_TRUE(t.validate().empty());
  t.extend_max_deg = 95.0;
  t.min_reach_ratio = 0.0;
  const auto et = t.validate();
  ASSERT_EQ(et.size(), 2u);
  EXPECT_NE(et[0].find("extend_max_deg"), std::string::npos);
  EXPECT_NE(et[0].find("95"), std::string::npos);
  EXPECT_NE(et[1].find("min_reach_ratio"), std::string::npos);
  gf::gesture::ArmGestureThresholds st;
  st.max_trunk_tilt_deg = 90.0;
  st.max_foot_offset_torso = std::nan("");
  const auto es = st.validate();
  ASSERT_EQ(es.size(), 2u);
  EXPECT_NE(es[0].find("max_trunk_tilt_deg: expected (0, 90) deg, got 90"), std::string::npos) << es[0];
  EXPECT_NE(es[1].find("max_foot_offset_torso: expected (0, 5], got nan"), std::string::npos) << es[1];
}

namespace {

/// Per motion: the share of frames the 3-D test reads as `id` over `count` performances seen by
/// three cameras (leader at a random azimuth, followers ±60°, Table II-like: 6–18 m, 5–40° above;
/// the generator's noise, dropouts, box jitter and aim jitter). Gestures: their frames at the pose
/// (label ≠ 0); other motions: every frame between the motion's start and end.
struct Share {
  int hits = 0, frames = 0, unknown = 0;
  double rate() const { return frames > 0 ? static_cast<double>(hits) / frames : 0.0; }
};
Share share3D(Motion m, int id, int count, std::uint64_t seed) {
  SkeletonSynthesizer synth(SynthConfig{}, seed);
  std::mt19937_64 rng(seed + 1000);
  std::uniform_real_distribution<double> dist(6.0, 18.0), elev(5.0, 40.0), azim(-180.0, 180.0);
  Share out;
  for (int n = 0; n < count; ++n) {
    const double e = elev(rng), a = azim(rng);
    const std::vector<SkeletonSynthesizer::View> cams{{dist(rng), e, a}, {dist(rng), e, a + 60.0}, {dist(rng), e, a - 60.0}};
    const std::vector<SynthSequence> views = synth.generateViewsFrom(m, cams);
    for (std::size_t k = 0; k < views.front().frames.size(); ++k) {
      const double t = views.front().frames[k].t_s;
      const bool gesture = gf::gesture::gestureIdOf(m) != gf::gesture::kNone;
      if (gesture ? views.front().frames[k].label == gf::gesture::kNone
                  : (t < views.front().motion_start_s || t > views.front().motion_end_s)) {
        continue;
      }
      std::vector<CalibratedSkeleton> calibrated;
      for (const SynthSequence& v : views) {
        CalibratedSkeleton c = cameraAt(v.distance_m, v.elevation_deg, v.azimuth_deg, 0.55 * v.height_m);
        c.skeleton = v.frames[k].skeleton;
        calibrated.push_back(c);
      }
      const Skeleton3D s = gf::gesture::triangulate(calibrated, TriangulationConfig{});
      ++out.frames;
      if (!gf::gesture::bodyFrameOf(s)) ++out.unknown;
      if (gf::gesture::oneArmGesture3D(s) == id) ++out.hits;
    }
  }
  return out;
}

}  // namespace

// What one 2-D view cannot do (docs/gestures.md §6): the arm pointing forward-outward, which a
// single camera reads as "extend an arm" from ~30° beside it, is not an extended arm in 3-D.
// Per frame, three noisy views (40 performances per motion, fixed seeds) — measured 2026-12-02 with
// the default thresholds (27.5°): extend 0.89 and raise 0.90 of the frames at the pose (the rest:
// the generator's least extended arms, 24.9° from the outward axis, plus noise; 2 % without a body
// frame); pointing read as extend 0.0005; the balancing lunge, whose leading arm the generator puts
// between "extend" and "raise" (30–60° above the horizontal), 0.014 / 0.037; every other motion 0.
// The bounds leave room for other noise draws, not for a 2-D-like confusion.
// Since the v8 generator (2026-12-03) half of the balancing lunges are side kicks whose leading arm
// is −10…+50° about the horizontal: up to +27.5° that arm IS extended sideways in 3-D — the same arm
// pose as the gesture, not a near-miss of it — and by arm geometry alone the lunge read as "extend"
// in 0.19 of its frames (0.014 before the kicks). The upright-stance test (stanceOf, same day) takes
// that to 0 of 3770 frames (80 performances), the gestures from 0.916 / 0.920 of their frames to
// 0.909 / 0.910 (extend / raise).
TEST(ViewTriangulationTest, ThreeNoisyViewsTellExtendAndRaiseFromTheirNearMisses) {
  const int n = 40;
  EXPECT_GE(share3D(Motion::kExtendArmSide, gf::gesture::kExtendArmSide, n, 11).rate(), 0.85);
  EXPECT_GE(share3D(Motion::kRaiseArmUp, gf::gesture::kRaiseArmUp, n, 12).rate(), 0.85);
  EXPECT_LE(share3D(Motion::kArmPartwayOrPointing, gf::gesture::kExtendArmSide, n, 27).rate(), 0.01);
  // The side kicks and lunges: their arm may be the gesture's, their stance is not (above).
  EXPECT_LE(share3D(Motion::kBalanceLunge, gf::gesture::kExtendArmSide, n, 21).rate(), 0.005);
  EXPECT_LE(share3D(Motion::kBalanceLunge, gf::gesture::kRaiseArmUp, n, 22).rate(), 0.005);
  for (Motion m : {Motion::kArmPartwayOrPointing, Motion::kBalanceLunge, Motion::kReachUpBolt, Motion::kClimbingLadder,
                   Motion::kWalking, Motion::kHoldObjectAtChest, Motion::kArmsFoldedLow, Motion::kToolAtWaist,
                   Motion::kIdle, Motion::kCrossArms, Motion::kPalmsTogether}) {
    const auto seed = static_cast<std::uint64_t>(m);
    EXPECT_LE(share3D(m, gf::gesture::kExtendArmSide, n, 20 + seed).rate(), 0.05) << gf::gesture::toString(m);
    EXPECT_LE(share3D(m, gf::gesture::kRaiseArmUp, n, 40 + seed).rate(), 0.06) << gf::gesture::toString(m);
  }
}

// ---------------------------------------------------------------------------------------
// ViewFusion with confirm_3d (docs/gestures.md §6): one view reads a one-arm gesture, the other
// does not; the triangulated skeletons of the vote window decide whether it counts.
namespace {

/// Changes observation `o` of frame k before it is observed (e.g. a view's keypoints moved).
using ObservationEdit = std::function<void(int k, gf::gesture::ViewObservation& o)>;

/// 1.2 s of observations at 15 Hz from two cameras (leader at 0°, follower at +60°) of one body;
/// view 0 reads `id0`, view 1 `id1`; `edit`, if given, changes each observation first. Returns the
/// fused verdict at the end.
gf::gesture::FusedGesture fuseTwoViews(const gf::gesture::Body3D& body, int id0, int id1,
                                       const gf::gesture::ViewFusionConfig& config, bool with_skeletons = true,
                                       int frames = 18, const ObservationEdit& edit = {}) {
  gf::gesture::ViewFusion fusion(config, 3, 4);
  std::vector<CalibratedSkeleton> cams{cameraAt(10.0, 20.0, 0.0, 1.0), cameraAt(9.0, 25.0, 60.0, 1.0)};
  for (auto& c : cams) projectInto(body, c);
  double t = 0.0;
  for (int k = 0; k < frames; ++k) {
    t = 10.0 + k / 15.0;
    for (int v = 0; v < 2; ++v) {
      gf::gesture::ViewObservation o;
      o.view = v;
      o.t_s = t;
      o.gesture_id = v == 0 ? id0 : id1;
      o.distance_m = 10.0;
      o.elevation_deg = 20.0;
      if (with_skeletons) o.calibrated = cams[static_cast<std::size_t>(v)];
      if (edit) edit(k, o);
      EXPECT_TRUE(fusion.observe(o));
    }
  }
  return fusion.fuse(t);
}

gf::gesture::FusedGesture fuseTwoViews(const gf::gesture::Body3D& body, int id0, int id1, bool confirm_3d,
                                       bool with_skeletons = true, int frames = 18) {
  gf::gesture::ViewFusionConfig config;
  config.confirm_3d = confirm_3d;
  return fuseTwoViews(body, id0, id1, config, with_skeletons, frames);
}

}  // namespace

TEST(ViewFusion3DTest, AGestureOneViewMissesCountsWhenTheArmIsThereIn3D) {
  SkeletonSynthesizer synth(SynthConfig{}, 5);
  const auto extend = synth.pose(Motion::kExtendArmSide, 1.0, 0.0, false);
  EXPECT_EQ(fuseTwoViews(extend, 2, 0, false).gesture_id, 0);  // the 2-of-3 vote alone: one vote short
  const auto f = fuseTwoViews(extend, 2, 0, true);
  EXPECT_EQ(f.gesture_id, 2);
  EXPECT_TRUE(f.confirmed_3d);
  EXPECT_EQ(f.agreeing_views, 1);
  const auto raise = synth.pose(Motion::kRaiseArmUp, 1.0, 0.0, true);
  EXPECT_EQ(fuseTwoViews(raise, 0, 4, true).gesture_id, 4);
  // Two agreeing views need no confirmation (and get none).
  const auto two = fuseTwoViews(extend, 2, 2, true);
  EXPECT_EQ(two.gesture_id, 2);
  EXPECT_FALSE(two.confirmed_3d);
}

TEST(ViewFusion3DTest, APostureThatIsNotTheGestureIn3DDoesNotCount) {
  SkeletonSynthesizer synth(SynthConfig{}, 6);
  // The arm pointing forward-outward (the near-miss one view reads as "extend"), and a raised arm
  // read as "extend" by one view: the 3-D arm contradicts both.
  const auto pointing = synth.pose(Motion::kArmPartwayOrPointing, 1.0, 0.0, true);
  EXPECT_EQ(fuseTwoViews(pointing, 2, 0, true).gesture_id, 0);
  const auto raise = synth.pose(Motion::kRaiseArmUp, 1.0, 0.0, true);
  EXPECT_EQ(fuseTwoViews(raise, 2, 0, true).gesture_id, 0);
  // Two-arm gestures are not tested in 3-D: one view's "cross arms" stays one vote short.
  const auto cross = synth.pose(Motion::kCrossArms, 1.0, 0.0, true);
  EXPECT_EQ(fuseTwoViews(cross, 1, 0, true).gesture_id, 0);
  // Without skeletons, or with fewer 3-D frames than confirm_3d_min_frames (5), nothing is confirmed.
  const auto extend = synth.pose(Motion::kExtendArmSide, 1.0, 0.0, true);
  EXPECT_EQ(fuseTwoViews(extend, 2, 0, true, false).gesture_id, 0);
  EXPECT_EQ(fuseTwoViews(extend, 2, 0, true, true, 4).gesture_id, 0);
  EXPECT_EQ(fuseTwoViews(extend, 2, 0, true, true, 5).gesture_id, 2);
}

namespace {

/// As fuseTwoViews (one view reads `id0`, the other `id1`), but in two of every three frames the
/// second view puts both wrists `jitter_px` pixels off, alternately up and down: a triangulated arm
/// that jumps from frame to frame (as a network's keypoints of a held arm do), whose median over
/// five frames is the arm itself.
gf::gesture::FusedGesture fuseTwoJitteryViews(const gf::gesture::Body3D& body, int id0, int id1,
                                              const gf::gesture::ViewFusionConfig& config, double jitter_px) {
  return fuseTwoViews(body, id0, id1, config, true, 18, [jitter_px](int k, gf::gesture::ViewObservation& o) {
    if (o.view != 1 || k % 3 == 0) return;
    const double dy = k % 3 == 1 ? jitter_px : -jitter_px;
    for (const auto w : {gf::gesture::Keypoint::kLeftWrist, gf::gesture::Keypoint::kRightWrist}) {
      o.calibrated->skeleton.y[static_cast<std::size_t>(w)] += dy;
    }
  });
}

}  // namespace

TEST(ViewFusion3DTest, TheOneArmConfirmationReadsTheHeldArmOnMediansAsTheCheckDoes) {
  // A held "extend" whose triangulated wrist jumps in two of every three frames: frame by frame
  // (require_3d_median_frames 1) the arm is the gesture in a third of the frames only and one
  // view's "extend" is not confirmed; read on the median of five frames (the default, as require_3d
  // reads it) it is. The pointing near-miss with the same jitter stays unconfirmed either way.
  SkeletonSynthesizer synth(SynthConfig{}, 5);
  const auto extend = synth.pose(Motion::kExtendArmSide, 1.0, 0.0, false);
  const auto pointing = synth.pose(Motion::kArmPartwayOrPointing, 1.0, 0.0, false);
  gf::gesture::ViewFusionConfig framewise;
  framewise.confirm_3d = true;
  framewise.require_3d_median_frames = 1;
  gf::gesture::ViewFusionConfig medians;
  medians.confirm_3d = true;
  ASSERT_EQ(medians.require_3d_median_frames, 5);
  const double jitter_px = 60.0;
  EXPECT_EQ(fuseTwoJitteryViews(extend, 2, 0, framewise, jitter_px).gesture_id, 0);
  const auto f = fuseTwoJitteryViews(extend, 2, 0, medians, jitter_px);
  EXPECT_EQ(f.gesture_id, 2);
  EXPECT_TRUE(f.confirmed_3d);
  EXPECT_EQ(fuseTwoJitteryViews(pointing, 2, 0, framewise, jitter_px).gesture_id, 0);
  EXPECT_EQ(fuseTwoJitteryViews(pointing, 2, 0, medians, jitter_px).gesture_id, 0);
  // Without the jitter both read the extend (the test's premise: only the jitter separates them).
  EXPECT_EQ(fuseTwoJitteryViews(extend, 2, 0, framewise, 0.0).gesture_id, 2);
}

TEST(ViewFusion3DTest, ConfirmKeysAreValidatedAndRead) {
  gf::gesture::ViewFusionConfig c;
  c.confirm_3d_min_fraction = 0.0;
  c.confirm_3d_min_frames = 0;
  c.confirm_3d_max_dt_s = -1.0;
  const auto e = c.validate();
  ASSERT_EQ(e.size(), 3u);
  EXPECT_NE(e[0].find("view_fusion.confirm_3d_min_fraction"), std::string::npos);
  EXPECT_NE(e[1].find("view_fusion.confirm_3d_min_frames must be in [1, 1000], got 0"), std::string::npos);
  EXPECT_NE(e[2].find("view_fusion.confirm_3d_max_dt_s"), std::string::npos);
  using gf::common::ConfigReader;
  ConfigReader ok = ConfigReader::fromString("view_fusion: {confirm_3d: true, confirm_3d_min_fraction: 0.7, "
                                             "confirm_3d_min_frames: 8, confirm_3d_max_dt_s: 0.05}\n",
                                             "ok.yaml", ConfigReader::MissingKeys::kUseDefaults);
  const auto read = gf::gesture::readViewFusionConfig(ok);
  EXPECT_TRUE(ok.ok()) << ok.errorReport();
  EXPECT_TRUE(read.confirm_3d);
  EXPECT_DOUBLE_EQ(read.confirm_3d_min_fraction, 0.7);
  EXPECT_EQ(read.confirm_3d_min_frames, 8);
  EXPECT_DOUBLE_EQ(read.confirm_3d_max_dt_s, 0.05);
  ConfigReader bad = ConfigReader::fromString("view_fusion: {confirm_3d: maybe, confirm_3d_min_frames: 0}\n", "bad.yaml",
                                              ConfigReader::MissingKeys::kUseDefaults);
  (void)gf::gesture::readViewFusionConfig(bad);
  EXPECT_FALSE(bad.ok());
  for (const char* key : {"view_fusion.confirm_3d", "view_fusion.confirm_3d_min_frames"}) {
    EXPECT_NE(bad.errorReport().find(key), std::string::npos) << key << " missing in:\n" << bad.errorReport();
  }
}

// ---------------------------------------------------------------------------------------
// ViewFusion with require_3d (default on; docs/gestures.md §6): with two or more calibrated views,
// a gesture both views read passes only when design.md §2's geometry of it holds in 3-D
// (gesture/gesture_geometry.hpp) in require_3d_min_fraction of the window's triangulated frames.
namespace {

gf::gesture::ViewFusionConfig require3d(bool on) {
  gf::gesture::ViewFusionConfig c;
  c.require_3d = on;
  return c;
}

}  // namespace

TEST(ViewFusionRequire3DTest, EveryGestureWhoseGeometryHoldsPasses) {
  SkeletonSynthesizer synth(SynthConfig{}, 8);
  const std::pair<Motion, int> gestures[] = {{Motion::kCrossArms, 1}, {Motion::kExtendArmSide, 2},
                                             {Motion::kPalmsTogether, 3}, {Motion::kRaiseArmUp, 4}};
  for (const auto& [motion, id] : gestures) {
    SCOPED_TRACE(gf::gesture::toString(motion));
    const auto f = fuseTwoViews(synth.pose(motion, 1.0, 0.0, true), id, id, require3d(true));
    EXPECT_EQ(f.gesture_id, id);
    EXPECT_TRUE(f.checked_3d);
    EXPECT_FALSE(f.rejected_3d);
    EXPECT_EQ(f.frames_3d, 15);  // the 1 s vote window at 15 Hz
  }
}

TEST(ViewFusionRequire3DTest, WorkPosturesBothViewsMisreadAreRejected) {
  SkeletonSynthesizer synth(SynthConfig{}, 9);
  // What two frontal views may read alike (issue 33): a tool held at the waist as "palms together",
  // an arm pointing as "extend", a bent arm reaching a bolt as "raise", arms folded low as "cross".
  const std::pair<Motion, int> misreads[] = {{Motion::kToolAtWaist, 3}, {Motion::kArmPartwayOrPointing, 2},
                                             {Motion::kReachUpBolt, 4}, {Motion::kArmsFoldedLow, 1}};
  for (const auto& [motion, id] : misreads) {
    SCOPED_TRACE(gf::gesture::toString(motion));
    const auto body = synth.pose(motion, 1.0, 0.0, true);
    EXPECT_EQ(fuseTwoViews(body, id, id, require3d(false)).gesture_id, id);  // the vote alone passes it
    const auto f = fuseTwoViews(body, id, id, require3d(true));
    EXPECT_EQ(f.gesture_id, 0);
    EXPECT_TRUE(f.checked_3d);
    EXPECT_TRUE(f.rejected_3d);
  }
  // A gesture read as another one: raise read as "extend" by both views.
  const auto f = fuseTwoViews(synth.pose(Motion::kRaiseArmUp, 1.0, 0.0, false), 2, 2, require3d(true));
  EXPECT_EQ(f.gesture_id, 0);
  EXPECT_TRUE(f.rejected_3d);
}

TEST(ViewFusionRequire3DTest, WithoutTwoCalibratedViewsTheVoteDecidesAloneWithTwoTheGeometry) {
  SkeletonSynthesizer synth(SynthConfig{}, 10);
  const auto tool = synth.pose(Motion::kToolAtWaist, 1.0, 0.0, true);
  // No skeletons (one camera, or no camera poses): today's vote.
  const auto none = fuseTwoViews(tool, 3, 3, require3d(true), false);
  EXPECT_EQ(none.gesture_id, 3);
  EXPECT_FALSE(none.checked_3d);
  EXPECT_EQ(none.frames_3d, 0);
  // Two calibrated views but fewer triangulated frames than require_3d_min_frames (5): not enough 3-D
  // evidence, refused even for a real gesture; with 5, the geometry decides.
  const auto palms = synth.pose(Motion::kPalmsTogether, 1.0, 0.0, true);
  const auto few = fuseTwoViews(palms, 3, 3, require3d(true), true, 4);
  EXPECT_EQ(few.gesture_id, 0);
  EXPECT_TRUE(few.checked_3d);
  EXPECT_TRUE(few.rejected_3d);
  EXPECT_EQ(fuseTwoViews(palms, 3, 3, require3d(true), true, 5).gesture_id, 3);
  EXPECT_EQ(fuseTwoViews(tool, 3, 3, require3d(true), true, 5).gesture_id, 0);
}

// Two calibrated views whose calibrated observations never pair up in time (each view's skeleton
// arrives only in the frames the other's does not — a follower's pose lookup failing every other
// frame): no triangulated frame, which does not skip the 3-D check — refused like too few frames
// (before, the vote alone decided then).
TEST(ViewFusionRequire3DTest, TwoCalibratedViewsThatNeverPairAreRefused) {
  SkeletonSynthesizer synth(SynthConfig{}, 10);
  const auto palms = synth.pose(Motion::kPalmsTogether, 1.0, 0.0, true);
  const gf::gesture::ViewFusionConfig c = require3d(true);
  const auto shifted = fuseTwoViews(palms, 3, 3, c, true, 18, [&](int k, gf::gesture::ViewObservation& o) {
    if ((k + o.view) % 2 == 1) o.calibrated.reset();  // 1/15 s apart > confirm_3d_max_dt_s
  });
  EXPECT_EQ(shifted.frames_3d, 0);
  EXPECT_TRUE(shifted.checked_3d);
  EXPECT_TRUE(shifted.rejected_3d);
  EXPECT_EQ(shifted.gesture_id, 0);
  // The same views paired: the geometry holds.
  EXPECT_EQ(fuseTwoViews(palms, 3, 3, c, true, 18).gesture_id, 3);
}

TEST(ViewFusionRequire3DTest, AConfirmedOneArmGestureMustAlsoHoldItsGeometry) {
  SkeletonSynthesizer synth(SynthConfig{}, 11);
  gf::gesture::ViewFusionConfig c = require3d(true);
  c.confirm_3d = true;
  // The 3-D confirmation (arm within 27.5° of the outward axis) and the design's region agree on a
  // clearly extended arm (hand-built: straight out to the side, 5° forward).
  auto body = synth.pose(Motion::kRaiseArmUp, 0.0, 0.0, true);  // rest pose of this body
  const Eigen::Vector3d sh = body.p[gf::gesture::kLeftShoulder];
  const Eigen::Vector3d d = Eigen::Vector3d(std::sin(degToRad(5.0)), std::cos(degToRad(5.0)), 0.0);
  body.p[gf::gesture::kLeftElbow] = sh + 0.32 * d;
  body.p[gf::gesture::kLeftWrist] = sh + 0.57 * d;
  const auto f = fuseTwoViews(body, 2, 0, c);
  EXPECT_EQ(f.gesture_id, 2);
  EXPECT_TRUE(f.confirmed_3d);
  EXPECT_TRUE(f.checked_3d);
  // 65° of abduction (the design's band, 55–70°): 25° from the outward axis, within the confirmation's 27.5°.
  const Eigen::Vector3d b = Eigen::Vector3d(0.0, std::sin(degToRad(65.0)), -std::cos(degToRad(65.0)));
  body.p[gf::gesture::kLeftElbow] = sh + 0.32 * b;
  body.p[gf::gesture::kLeftWrist] = sh + 0.57 * b;
  const auto band = fuseTwoViews(body, 2, 0, c);
  EXPECT_EQ(band.gesture_id, 0);
  EXPECT_TRUE(band.rejected_3d);
  EXPECT_FALSE(band.confirmed_3d);
}

TEST(ViewFusion3DTest, WithScopeAllATwoArmGestureOneViewReadsIsConfirmedOnItsRegion) {
  SkeletonSynthesizer synth(SynthConfig{}, 12);
  gf::gesture::ViewFusionConfig c;
  c.confirm_3d = true;
  c.confirm_3d_scope = gf::gesture::ViewFusionConfig::ConfirmScope::kAll;
  // One view reads "cross arms" / "palms together", the other none: the 3-D skeleton shows the gesture.
  for (const auto& [motion, id] : {std::pair{Motion::kCrossArms, 1}, std::pair{Motion::kPalmsTogether, 3}}) {
    SCOPED_TRACE(gf::gesture::toString(motion));
    const auto body = synth.pose(motion, 1.0, 0.0, true);
    c.confirm_3d_scope = gf::gesture::ViewFusionConfig::ConfirmScope::kOneArm;
    EXPECT_EQ(fuseTwoViews(body, id, 0, c).gesture_id, 0);  // one_arm: two-arm gestures are never confirmed
    c.confirm_3d_scope = gf::gesture::ViewFusionConfig::ConfirmScope::kAll;
    const auto f = fuseTwoViews(body, id, 0, c);
    EXPECT_EQ(f.gesture_id, id);
    EXPECT_TRUE(f.confirmed_3d);
    EXPECT_TRUE(f.checked_3d);
    EXPECT_EQ(f.agreeing_views, 1);
  }
  // The near-misses one view misreads stay none: the 3-D skeleton is not in the gesture's region.
  for (const auto& [motion, id] : {std::pair{Motion::kToolAtWaist, 3}, std::pair{Motion::kArmsFoldedLow, 1},
                                   std::pair{Motion::kHoldObjectAtChest, 3}, std::pair{Motion::kReachUpBolt, 4}}) {
    SCOPED_TRACE(gf::gesture::toString(motion));
    const auto f = fuseTwoViews(synth.pose(motion, 1.0, 0.0, true), id, 0, c);
    EXPECT_EQ(f.gesture_id, 0);
    EXPECT_FALSE(f.confirmed_3d);
  }
  // One-arm gestures are confirmed as with one_arm, upright stance included: a balancing lunge whose
  // arm is where "extend" puts it, read as extend by one view, stays none (rendered held-out set 9102:
  // the regions alone let 22 fused lunge frames through).
  {
    gf::gesture::Body3D kick = synth.pose(Motion::kExtendArmSide, 1.0, 0.0, true);
    const auto i = [](int k) { return static_cast<std::size_t>(k); };
    const Eigen::Vector3d hip = 0.5 * (kick.p[i(gf::gesture::kLeftHip)] + kick.p[i(gf::gesture::kRightHip)]);
    const double torso = (0.5 * (kick.p[i(gf::gesture::kLeftShoulder)] + kick.p[i(gf::gesture::kRightShoulder)]) - hip).norm();
    kick.p[i(gf::gesture::kRightAnkle)] = hip + Eigen::Vector3d(0.0, -1.0 * torso, 0.15);  // a side kick
    kick.p[i(gf::gesture::kLeftAnkle)] = hip + Eigen::Vector3d(0.0, 1.0 * torso, 0.15);
    const auto f = fuseTwoViews(kick, 2, 0, c);
    EXPECT_EQ(f.gesture_id, 0);
    EXPECT_FALSE(f.confirmed_3d);
    c.confirm_3d_scope = gf::gesture::ViewFusionConfig::ConfirmScope::kOneArm;
    EXPECT_EQ(fuseTwoViews(kick, 2, 0, c).gesture_id, 0);
    c.confirm_3d_scope = gf::gesture::ViewFusionConfig::ConfirmScope::kAll;
    // Upright, the same arm is confirmed.
    EXPECT_EQ(fuseTwoViews(synth.pose(Motion::kExtendArmSide, 1.0, 0.0, true), 2, 0, c).gesture_id, 2);
  }
  // Read and validated: one_arm | all, anything else refused naming the key and the value.
  using gf::common::ConfigReader;
  ConfigReader ok = ConfigReader::fromString("view_fusion: {confirm_3d_scope: all}\n", "ok.yaml",
                                             ConfigReader::MissingKeys::kUseDefaults);
  EXPECT_EQ(gf::gesture::readViewFusionConfig(ok).confirm_3d_scope, gf::gesture::ViewFusionConfig::ConfirmScope::kAll);
  EXPECT_TRUE(ok.ok()) << ok.errorReport();
  ConfigReader bad = ConfigReader::fromString("view_fusion: {confirm_3d_scope: both}\n", "bad.yaml",
                                              ConfigReader::MissingKeys::kUseDefaults);
  (void)gf::gesture::readViewFusionConfig(bad);
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.errorReport().find("view_fusion.confirm_3d_scope"), std::string::npos) << bad.errorReport();
  EXPECT_NE(bad.errorReport().find("both"), std::string::npos) << bad.errorReport();
}

TEST(ViewFusionRequire3DTest, RequireKeysAreValidatedAndRead) {
  gf::gesture::ViewFusionConfig c;
  EXPECT_TRUE(c.require_3d);  // default on
  c.require_3d_min_fraction = 1.5;
  c.require_3d_min_frames = 0;
  c.require_3d_median_frames = 4;
  const auto e = c.validate();
  ASSERT_EQ(e.size(), 3u);
  EXPECT_NE(e[0].find("view_fusion.require_3d_min_fraction"), std::string::npos) << e[0];
  EXPECT_NE(e[1].find("view_fusion.require_3d_min_frames must be in [1, 1000], got 0"), std::string::npos) << e[1];
  EXPECT_NE(e[2].find("view_fusion.require_3d_median_frames"), std::string::npos) << e[2];
  EXPECT_NE(e[2].find("odd"), std::string::npos) << e[2];
  using gf::common::ConfigReader;
  ConfigReader ok = ConfigReader::fromString("view_fusion: {require_3d: false, require_3d_min_fraction: 0.7, "
                                             "require_3d_min_frames: 8, require_3d_median_frames: 3}\n",
                                             "ok.yaml", ConfigReader::MissingKeys::kUseDefaults);
  const auto read = gf::gesture::readViewFusionConfig(ok);
  EXPECT_TRUE(ok.ok()) << ok.errorReport();
  EXPECT_FALSE(read.require_3d);
  EXPECT_DOUBLE_EQ(read.require_3d_min_fraction, 0.7);
  EXPECT_EQ(read.require_3d_min_frames, 8);
  EXPECT_EQ(read.require_3d_median_frames, 3);
  ConfigReader bad = ConfigReader::fromString("view_fusion: {require_3d: perhaps, require_3d_min_fraction: 0}\n",
                                              "bad.yaml", ConfigReader::MissingKeys::kUseDefaults);
  (void)gf::gesture::readViewFusionConfig(bad);
  EXPECT_FALSE(bad.ok());
  for (const char* key : {"view_fusion.require_3d", "view_fusion.require_3d_min_fraction"}) {
    EXPECT_NE(bad.errorReport().find(key), std::string::npos) << key << " missing in:\n" << bad.errorReport();
  }
  // The shipped configuration turns it on.
  ConfigReader shipped = ConfigReader::fromFile(std::string(GF_SOURCE_DIR) + "/config/gestures.yaml",
                                                ConfigReader::MissingKeys::kUseDefaults);
  EXPECT_TRUE(gf::gesture::readViewFusionConfig(shipped).require_3d);
  EXPECT_TRUE(shipped.ok()) << shipped.errorReport();
}

TEST(ViewFusionRequire3DTest, TheNetworkTolerantRulesAreWhatTheCheckTests) {
  // The generator's palms together with the wrists pulled 0.10 H apart (how MoveNet reports them,
  // docs/gestures.md §9): refused by the design's region, passed by geometry_3d network_tolerant.
  SkeletonSynthesizer synth(SynthConfig{}, 12);
  auto body = synth.pose(Motion::kPalmsTogether, 1.0, 0.0, true);
  const Eigen::Vector3d ls = body.p[gf::gesture::kLeftShoulder], rs = body.p[gf::gesture::kRightShoulder];
  const Eigen::Vector3d hips = 0.5 * (body.p[gf::gesture::kLeftHip] + body.p[gf::gesture::kRightHip]);
  const double H = (0.5 * (ls + rs) - hips).norm() / 0.30;
  const Eigen::Vector3d y = (ls - rs).normalized();
  const Eigen::Vector3d mid = 0.5 * (body.p[gf::gesture::kLeftWrist] + body.p[gf::gesture::kRightWrist]);
  body.p[gf::gesture::kLeftWrist] = mid + 0.05 * H * y;
  body.p[gf::gesture::kRightWrist] = mid - 0.05 * H * y;
  gf::gesture::ViewFusionConfig c = require3d(true);
  const auto design = fuseTwoViews(body, 3, 3, c);
  EXPECT_EQ(design.gesture_id, 0);
  EXPECT_TRUE(design.rejected_3d);
  c.geometry.rules = gf::gesture::GeometryRules::kNetworkTolerant;
  const auto tolerant = fuseTwoViews(body, 3, 3, c);
  EXPECT_EQ(tolerant.gesture_id, 3);
  EXPECT_TRUE(tolerant.checked_3d);
  EXPECT_FALSE(tolerant.rejected_3d);
  // A tool at the waist both views misread as palms stays refused under the tolerant rules.
  const auto tool = fuseTwoViews(synth.pose(Motion::kToolAtWaist, 1.0, 0.0, true), 3, 3, c);
  EXPECT_EQ(tool.gesture_id, 0);
  EXPECT_TRUE(tool.rejected_3d);
}

TEST(ViewFusionRequire3DTest, GeometryKeysAreValidatedAndRead) {
  gf::gesture::ViewFusionConfig c;
  EXPECT_EQ(c.geometry.rules, gf::gesture::GeometryRules::kDesign);
  c.geometry.tolerant.palms_max_separation_H = 0.0;
  c.geometry.tolerant.folded_max_height_H = 0.85;  // above cross_min_height_H 0.80: no band
  c.geometry.tolerant.cross_max_height_H = 0.78;   // below cross_min_height_H: no region
  const auto e = c.validate();
  ASSERT_EQ(e.size(), 3u);
  EXPECT_NE(e[0].find("view_fusion.tolerant_3d.palms_max_separation_H"), std::string::npos) << e[0];
  EXPECT_NE(e[1].find("view_fusion.tolerant_3d.cross_max_height_H"), std::string::npos) << e[1];
  EXPECT_NE(e[2].find("view_fusion.tolerant_3d.folded_max_height_H"), std::string::npos) << e[2];
  EXPECT_NE(e[2].find("cross_min_height_H"), std::string::npos) << e[2];
  using gf::common::ConfigReader;
  ConfigReader ok = ConfigReader::fromString("view_fusion: {geometry_3d: network_tolerant, tolerant_3d: "
                                             "{palms_max_separation_H: 0.12, raise_min_shoulder_wrist_deg: 150}}\n",
                                             "ok.yaml", ConfigReader::MissingKeys::kUseDefaults);
  const auto read = gf::gesture::readViewFusionConfig(ok);
  EXPECT_TRUE(ok.ok()) << ok.errorReport();
  EXPECT_EQ(read.geometry.rules, gf::gesture::GeometryRules::kNetworkTolerant);
  EXPECT_DOUBLE_EQ(read.geometry.tolerant.palms_max_separation_H, 0.12);
  EXPECT_DOUBLE_EQ(read.geometry.tolerant.raise_min_shoulder_wrist_deg, 150.0);
  ConfigReader bad = ConfigReader::fromString("view_fusion: {geometry_3d: lenient, tolerant_3d: {cross_min_height_H: 2}}\n",
                                              "bad.yaml", ConfigReader::MissingKeys::kUseDefaults);
  (void)gf::gesture::readViewFusionConfig(bad);
  EXPECT_FALSE(bad.ok());
  for (const char* key : {"view_fusion.geometry_3d", "lenient", "view_fusion.tolerant_3d.cross_min_height_H"}) {
    EXPECT_NE(bad.errorReport().find(key), std::string::npos) << key << " missing in:\n" << bad.errorReport();
  }
}

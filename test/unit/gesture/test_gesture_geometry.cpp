// gesture/gesture_geometry.hpp: design.md §2's gestures and near-misses as 3-D regions with
// ambiguity bands, on hand-built skeletons (no generator, no network): each gesture inside its
// region, each near-miss outside, points in the band none.
#include <gtest/gtest.h>

#include <cmath>

#include <Eigen/Geometry>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/gesture/gesture_geometry.hpp"
#include "gesture_formation/gesture/skeleton_synth.hpp"

namespace gf = gesture_formation;
using gf::common::degToRad;
using gf::gesture::classifyPose3D;
using gf::gesture::PoseRegion;
using gf::gesture::PoseVerdict;
using gf::gesture::Skeleton3D;
using Eigen::Vector3d;

namespace {

/// A standing worker of height H in the body frame (x forward, y left, z up, feet at 0), shoulders at
/// 0.82 H and hips at 0.52 H (design.md §2), arms hanging; the arms are then set by the tests.
struct Worker {
  double H = 1.75;
  Skeleton3D s;

  explicit Worker(double height_m = 1.75) : H(height_m) {
    set(gf::gesture::kNose, {0.05 * H, 0, 0.915 * H});
    set(gf::gesture::kLeftEye, {0.04 * H, 0.02 * H, 0.93 * H});
    set(gf::gesture::kRightEye, {0.04 * H, -0.02 * H, 0.93 * H});
    set(gf::gesture::kLeftEar, {0, 0.045 * H, 0.925 * H});
    set(gf::gesture::kRightEar, {0, -0.045 * H, 0.925 * H});
    set(gf::gesture::kLeftShoulder, {0, 0.129 * H, 0.82 * H});
    set(gf::gesture::kRightShoulder, {0, -0.129 * H, 0.82 * H});
    set(gf::gesture::kLeftHip, {0, 0.085 * H, 0.52 * H});
    set(gf::gesture::kRightHip, {0, -0.085 * H, 0.52 * H});
    set(gf::gesture::kLeftKnee, {0.01 * H, 0.085 * H, 0.285 * H});
    set(gf::gesture::kRightKnee, {0.01 * H, -0.085 * H, 0.285 * H});
    set(gf::gesture::kLeftAnkle, {0, 0.085 * H, 0.039 * H});
    set(gf::gesture::kRightAnkle, {0, -0.085 * H, 0.039 * H});
    armDir(true, {0.05, 0.1, -1}, {0.05, 0.1, -1});
    armDir(false, {0.05, -0.1, -1}, {0.05, -0.1, -1});
  }
  void set(int k, const Vector3d& p) {
    s.p_world[static_cast<std::size_t>(k)] = p;
    s.valid[static_cast<std::size_t>(k)] = true;
  }
  Vector3d at(int k) const { return s.p_world[static_cast<std::size_t>(k)]; }
  /// An arm from its upper-arm and forearm directions (body frame), segment lengths 0.186 H, 0.146 H.
  void armDir(bool left, const Vector3d& upper, const Vector3d& fore) {
    const Vector3d sh = at(left ? gf::gesture::kLeftShoulder : gf::gesture::kRightShoulder);
    const Vector3d el = sh + 0.186 * H * upper.normalized();
    set(left ? gf::gesture::kLeftElbow : gf::gesture::kRightElbow, el);
    set(left ? gf::gesture::kLeftWrist : gf::gesture::kRightWrist, el + 0.146 * H * fore.normalized());
  }
  /// Both arms from elbow and wrist positions given in fractions of H (x, y, z) for the left arm, the
  /// right arm its mirror image.
  void hands(const Vector3d& elbow_H, const Vector3d& wrist_H) {
    set(gf::gesture::kLeftElbow, H * elbow_H);
    set(gf::gesture::kRightElbow, H * Vector3d(elbow_H.x(), -elbow_H.y(), elbow_H.z()));
    set(gf::gesture::kLeftWrist, H * wrist_H);
    set(gf::gesture::kRightWrist, H * Vector3d(wrist_H.x(), -wrist_H.y(), wrist_H.z()));
  }
  /// A straight arm along a direction given by its elevation from hanging and the azimuth of its
  /// plane (0: the arm's own side, 90: forward).
  void straightArm(bool left, double elevation_deg, double plane_deg) {
    const double e = degToRad(elevation_deg), a = degToRad(plane_deg);
    const Vector3d d(std::sin(e) * std::sin(a), (left ? 1.0 : -1.0) * std::sin(e) * std::cos(a), -std::cos(e));
    armDir(left, d, d);
  }
};

void expectGesture(const Worker& w, int gesture) {
  const PoseVerdict v = classifyPose3D(w.s);
  EXPECT_EQ(v.gesture_id, gesture) << "region " << gf::gesture::toString(v.region);
  EXPECT_EQ(v.region, PoseRegion::kGesture);
}

void expectNone(const Worker& w, PoseRegion region, int nearest) {
  const PoseVerdict v = classifyPose3D(w.s);
  EXPECT_EQ(v.gesture_id, gf::gesture::kNone);
  EXPECT_EQ(v.region, region) << "got " << gf::gesture::toString(v.region) << ", expected " << gf::gesture::toString(region);
  EXPECT_EQ(v.nearest_gesture, nearest);
}

}  // namespace

TEST(GestureGeometryTest, TheDefaultsAreDesignSection2sNumbers) {
  const gf::gesture::GestureGeometryNumbers n;
  EXPECT_EQ(n.shoulder_height_H, 0.82);
  EXPECT_EQ(n.hip_height_H, 0.52);
  EXPECT_EQ(n.palms_max_separation_H, 0.06);
  EXPECT_EQ(n.palms_min_height_H, 0.67);
  EXPECT_EQ(n.palms_max_height_H, 0.80);
  EXPECT_EQ(n.palms_forearm_max_from_horizontal_deg, 30.0);
  EXPECT_EQ(n.tool_max_height_H, 0.61);
  EXPECT_EQ(n.cross_min_height_H, 0.80);
  EXPECT_EQ(n.folded_max_height_H, 0.70);
  EXPECT_EQ(n.extend_min_abduction_deg, 70.0);
  EXPECT_EQ(n.extend_max_abduction_deg, 110.0);
  EXPECT_EQ(n.extend_min_elbow_deg, 150.0);
  EXPECT_EQ(n.pointing_max_abduction_deg, 55.0);
  EXPECT_EQ(n.raise_min_elevation_deg, 150.0);
  EXPECT_EQ(n.raise_min_elbow_deg, 150.0);
  EXPECT_EQ(n.reach_max_elevation_deg, 130.0);
  EXPECT_EQ(n.reach_max_elbow_deg, 120.0);
}

TEST(GestureGeometryTest, MeasuresTheStandingBody) {
  Worker w(1.80);
  const auto m = gf::gesture::measurePose(w.s);
  ASSERT_TRUE(m.valid);
  EXPECT_NEAR(m.height_m, 1.80, 1e-9);
  EXPECT_LT((m.frame.R_world_body - Eigen::Matrix3d::Identity()).norm(), 1e-9);
  ASSERT_TRUE(m.left.valid && m.right.valid);
  EXPECT_LT(m.left.elevation_deg, 10.0);
  EXPECT_GT(m.left.elbow_deg, 179.0);
  EXPECT_NEAR(m.left.wrist_height_H, 0.82 - (0.186 + 0.146) * 0.99, 0.01);
  w.straightArm(true, 100.0, 10.0);  // to the side, 10° above the horizontal and 10° forward
  const auto side = gf::gesture::measurePose(w.s).left;
  EXPECT_NEAR(side.elevation_deg, 100.0, 1e-6);
  EXPECT_NEAR(side.horizontal_abduction_deg, 80.0, 1e-6);
  w.straightArm(false, 90.0, 90.0);  // pointing forward: horizontal abduction 0, elevation 90
  const auto fwd = gf::gesture::measurePose(w.s).right;
  EXPECT_NEAR(fwd.horizontal_abduction_deg, 0.0, 1e-6);
  EXPECT_NEAR(fwd.elevation_deg, 90.0, 1e-6);
  w.straightArm(false, 90.0, -60.0);  // pointing back and outward: 30° from straight back
  EXPECT_NEAR(gf::gesture::measurePose(w.s).right.horizontal_abduction_deg, 30.0, 1e-6);
}

TEST(GestureGeometryTest, RestingArmsAreNoGestureAndNoNearMiss) {
  expectNone(Worker(), PoseRegion::kOther, gf::gesture::kNone);
}

// ---- palms together (3) and its near-miss, the tool held in both hands ----

TEST(GestureGeometryTest, PalmsTogetherAtMidChestWithLevelForearmsIsGesture3) {
  Worker w;
  w.hands({0.06, 0.15, 0.71}, {0.22, 0.01, 0.73});  // forearms ~5° from horizontal, wrists 0.02 H apart
  expectGesture(w, gf::gesture::kPalmsTogether);
}

TEST(GestureGeometryTest, AToolHeldAtTheWaistIsNotPalmsTogether) {
  Worker w;
  w.hands({0.02, 0.14, 0.64}, {0.18, 0.02, 0.55});  // wrists together, low, below the elbows
  expectNone(w, PoseRegion::kToolAtWaist, gf::gesture::kPalmsTogether);
  // The same hands a little higher, still below 0.61 H, and held level: still the tool.
  w.hands({0.02, 0.14, 0.60}, {0.18, 0.02, 0.60});
  expectNone(w, PoseRegion::kToolAtWaist, gf::gesture::kPalmsTogether);
}

TEST(GestureGeometryTest, HandsTogetherBetweenTheWaistAndMidChestAreTheBand) {
  Worker w;
  for (double h : {0.62, 0.64, 0.66}) {
    SCOPED_TRACE(h);
    w.hands({0.05, 0.15, h}, {0.21, 0.01, h});
    expectNone(w, PoseRegion::kBand, gf::gesture::kPalmsTogether);
  }
}

TEST(GestureGeometryTest, PalmsAtMidChestNeedLevelForearmsCloseWristsAndHandsInFront) {
  Worker w;
  w.hands({0.10, 0.15, 0.56}, {0.20, 0.01, 0.72});  // forearms ~45° up: a tool lifted, not the gesture
  EXPECT_EQ(classifyPose3D(w.s).gesture_id, gf::gesture::kNone);
  w.hands({0.06, 0.15, 0.71}, {0.22, 0.05, 0.73});  // wrists 0.10 H apart: an object held, not palms
  EXPECT_EQ(classifyPose3D(w.s).gesture_id, gf::gesture::kNone);
  w.hands({-0.10, 0.15, 0.71}, {-0.04, 0.01, 0.73});  // behind the back
  EXPECT_EQ(classifyPose3D(w.s).gesture_id, gf::gesture::kNone);
  w.hands({0.06, 0.15, 0.80}, {0.22, 0.01, 0.84});  // at the shoulders: above mid-chest
  EXPECT_EQ(classifyPose3D(w.s).gesture_id, gf::gesture::kNone);
}

// ---- cross arms (1) and its near-miss, arms folded low ----

TEST(GestureGeometryTest, WristsCrossedAtShoulderHeightAreGesture1) {
  Worker w;
  w.hands({0.10, 0.16, 0.70}, {0.17, -0.04, 0.84});
  expectGesture(w, gf::gesture::kCrossArms);
}

TEST(GestureGeometryTest, ArmsFoldedLowAreNotCrossArms) {
  Worker w;
  w.hands({0.06, 0.15, 0.58}, {0.12, -0.08, 0.62});
  expectNone(w, PoseRegion::kArmsFoldedLow, gf::gesture::kCrossArms);
}

TEST(GestureGeometryTest, WristsCrossedBetweenChestAndShouldersAreTheBand) {
  Worker w;
  for (double h : {0.72, 0.76, 0.79}) {
    SCOPED_TRACE(h);
    w.hands({0.08, 0.16, 0.64}, {0.15, -0.05, h});
    expectNone(w, PoseRegion::kBand, gf::gesture::kCrossArms);
  }
}

TEST(GestureGeometryTest, WristsHighButNotCrossedAreNotCrossArms) {
  Worker w;
  w.hands({0.10, 0.16, 0.70}, {0.17, 0.04, 0.86});  // hands up in front of the face, not crossed
  EXPECT_NE(classifyPose3D(w.s).gesture_id, gf::gesture::kCrossArms);
}

// ---- extend an arm to the side (2) and its near-miss, part-way or pointing ----

TEST(GestureGeometryTest, AnArmAbductedBetween70And110DegreesIsGesture2WithEitherArm) {
  for (bool left : {true, false}) {
    for (double abd : {71.0, 80.0, 90.0, 100.0, 109.0}) {
      SCOPED_TRACE(std::to_string(abd) + (left ? " left" : " right"));
      Worker w;
      w.straightArm(left, abd, 0.0);
      expectGesture(w, gf::gesture::kExtendArmSide);
    }
  }
}

TEST(GestureGeometryTest, PointingForwardIsNotExtendToTheSide) {
  // Forward (plane 90°) and forward-outward (0–35° outward: plane 55–90°), level: abduction ≤ 55°.
  for (double plane : {90.0, 75.0, 60.0, 55.0}) {
    SCOPED_TRACE(plane);
    Worker w;
    w.straightArm(true, 90.0, plane);
    expectNone(w, PoseRegion::kArmPartwayOrPointing, gf::gesture::kExtendArmSide);
  }
  // Pointing 10° below the horizontal, 30° outward.
  Worker w;
  w.straightArm(true, 80.0, 60.0);
  expectNone(w, PoseRegion::kArmPartwayOrPointing, gf::gesture::kExtendArmSide);
}

TEST(GestureGeometryTest, AnArmRaisedPartWayToTheSideIsNotExtend) {
  for (double abd : {25.0, 40.0, 55.0}) {
    SCOPED_TRACE(abd);
    Worker w;
    w.straightArm(false, abd, 0.0);
    expectNone(w, PoseRegion::kArmPartwayOrPointing, gf::gesture::kExtendArmSide);
  }
}

TEST(GestureGeometryTest, AbductionBetween55And70DegreesIsTheBand) {
  for (double abd : {57.0, 62.0, 68.0}) {
    SCOPED_TRACE(abd);
    Worker w;
    w.straightArm(true, abd, 0.0);
    expectNone(w, PoseRegion::kBand, gf::gesture::kExtendArmSide);
  }
  // The same band seen as a pointing arm swung outward: 62° out of the sagittal plane, level.
  Worker w;
  w.straightArm(true, 90.0, 28.0);
  expectNone(w, PoseRegion::kBand, gf::gesture::kExtendArmSide);
}

TEST(GestureGeometryTest, ABentArmAtTheSideIsNotExtend) {
  Worker w;
  w.armDir(true, {0, 1, 0}, {1, 0, 0});  // upper arm sideways, forearm forward: elbow 90°
  EXPECT_EQ(classifyPose3D(w.s).gesture_id, gf::gesture::kNone);
}

TEST(GestureGeometryTest, BothArmsExtendedIsNotTheOneArmGesture) {
  Worker w;
  w.straightArm(true, 90.0, 0.0);
  w.straightArm(false, 90.0, 0.0);
  expectNone(w, PoseRegion::kAmbiguous, gf::gesture::kNone);
}

// ---- raise an arm up (4) and its near-miss, reaching ----

TEST(GestureGeometryTest, AnArmStraightUpIsGesture4InAnyPlane) {
  for (double plane : {0.0, 45.0, 90.0}) {
    for (double el : {151.0, 165.0, 180.0}) {
      SCOPED_TRACE(std::to_string(el) + " in plane " + std::to_string(plane));
      Worker w;
      w.straightArm(false, el, plane);
      expectGesture(w, gf::gesture::kRaiseArmUp);
    }
  }
}

TEST(GestureGeometryTest, ReachingUpWithABentArmOrPartWayIsNotRaise) {
  Worker w;
  w.straightArm(true, 120.0, 90.0);  // part-way up in front (≤ 130°)
  expectNone(w, PoseRegion::kReachingUp, gf::gesture::kRaiseArmUp);
  // Upper arm high (155°) but the elbow bent to 90° (a bolt above the head).
  const double e = degToRad(155.0);
  const Vector3d upper(std::sin(e), 0.0, -std::cos(e));
  w.armDir(true, upper, Vector3d(1.0, 0.0, -0.3));
  const auto m = gf::gesture::measurePose(w.s);
  ASSERT_LT(m.left.elbow_deg, 120.0);
  expectNone(w, PoseRegion::kReachingUp, gf::gesture::kRaiseArmUp);
}

TEST(GestureGeometryTest, ElevationBetween130And150DegreesOrElbowBetween120And150IsTheBand) {
  for (double el : {133.0, 140.0, 148.0}) {
    SCOPED_TRACE(el);
    Worker w;
    w.straightArm(true, el, 90.0);
    expectNone(w, PoseRegion::kBand, gf::gesture::kRaiseArmUp);
  }
  // Upper arm at 160°, elbow at 135°.
  Worker w;
  const double e = degToRad(160.0), f = degToRad(160.0 - 45.0);
  w.armDir(true, Vector3d(std::sin(e), 0.0, -std::cos(e)), Vector3d(std::sin(f), 0.0, -std::cos(f)));
  ASSERT_NEAR(gf::gesture::measurePose(w.s).left.elbow_deg, 135.0, 1e-6);
  expectNone(w, PoseRegion::kBand, gf::gesture::kRaiseArmUp);
}

// ---- properties ----

TEST(GestureGeometryTest, VerdictsDoNotDependOnTheWorldFrameTheHeightOrALean) {
  // One pose of each region, rebuilt for short and tall workers and moved into a rotated, shifted
  // world frame with the body leaning 15° forward: every verdict stays.
  const auto poses = [](Worker& w, int which) {
    switch (which) {
      case 0: w.hands({0.06, 0.15, 0.71}, {0.22, 0.01, 0.73}); break;
      case 1: w.hands({0.02, 0.14, 0.64}, {0.18, 0.02, 0.55}); break;
      case 2: w.hands({0.10, 0.16, 0.70}, {0.17, -0.04, 0.84}); break;
      case 3: w.hands({0.06, 0.15, 0.58}, {0.12, -0.08, 0.62}); break;
      case 4: w.straightArm(true, 90.0, 0.0); break;
      case 5: w.straightArm(true, 85.0, 70.0); break;
      case 6: w.straightArm(false, 170.0, 20.0); break;
      default: w.straightArm(false, 140.0, 90.0); break;
    }
  };
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(2.1, Vector3d::UnitZ()) * Eigen::AngleAxisd(0.2, Vector3d::UnitX())).toRotationMatrix();
  const Eigen::Matrix3d lean = Eigen::AngleAxisd(degToRad(15.0), Vector3d::UnitY()).toRotationMatrix();
  const Vector3d shift(31.0, -12.0, 4.5);
  for (int which = 0; which < 8; ++which) {
    Worker ref;
    poses(ref, which);
    const PoseVerdict expected = classifyPose3D(ref.s);
    for (double H : {1.45, 2.10}) {
      Worker w(H);
      poses(w, which);
      for (auto& p : w.s.p_world) p = shift + R * (lean * (p - Vector3d(0, 0, 0.52 * H)));
      const PoseVerdict v = classifyPose3D(w.s);
      EXPECT_EQ(v.gesture_id, expected.gesture_id) << "pose " << which << ", H " << H;
      EXPECT_EQ(v.region, expected.region) << "pose " << which << ", H " << H;
    }
  }
}

TEST(GestureGeometryTest, MissingJointsGiveNoVerdict) {
  Worker w;
  w.straightArm(true, 90.0, 0.0);
  w.s.valid[gf::gesture::kLeftHip] = false;
  expectNone(w, PoseRegion::kUnknown, gf::gesture::kNone);
  Worker v;
  v.straightArm(true, 90.0, 0.0);
  v.s.valid[gf::gesture::kLeftElbow] = false;  // the extended arm cannot be measured
  EXPECT_EQ(classifyPose3D(v.s).gesture_id, gf::gesture::kNone);
}

TEST(GestureGeometryTest, TheGeneratorsCanonicalGesturesLieInsideTheirRegions) {
  // The training generator's poses (gesture/skeleton_synth.hpp) at full progress, 40 bodies each:
  // the gestures inside their regions, the near-misses never inside a gesture's.
  int inside = 0, total = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    gf::gesture::SkeletonSynthesizer synth(gf::gesture::SynthConfig{}, seed);
    (void)synth.next();  // draws a body and a pose variation
    for (auto motion : {gf::gesture::Motion::kCrossArms, gf::gesture::Motion::kExtendArmSide,
                        gf::gesture::Motion::kPalmsTogether, gf::gesture::Motion::kRaiseArmUp,
                        gf::gesture::Motion::kToolAtWaist, gf::gesture::Motion::kArmsFoldedLow,
                        gf::gesture::Motion::kArmPartwayOrPointing, gf::gesture::Motion::kReachUpBolt}) {
      const gf::gesture::Body3D body = synth.pose(motion, 1.0, 0.0, seed % 2 == 0);
      Skeleton3D s;
      for (std::size_t k = 0; k < body.p.size(); ++k) {
        s.p_world[k] = body.p[k];
        s.valid[k] = true;
      }
      const int expected = gf::gesture::gestureIdOf(motion);
      const int got = classifyPose3D(s).gesture_id;
      if (expected == gf::gesture::kNone) {
        EXPECT_EQ(got, gf::gesture::kNone) << gf::gesture::toString(motion) << " seed " << seed;
      } else {
        ++total;
        inside += got == expected ? 1 : 0;
        EXPECT_TRUE(got == expected || got == gf::gesture::kNone)
            << gf::gesture::toString(motion) << " read as " << got << ", seed " << seed;
      }
    }
  }
  // The generator draws extend with ±15° forward and palms with varying forearms: a few of its
  // corners fall in a band (none), never in another gesture's region.
  EXPECT_GE(inside, total * 9 / 10) << inside << " of " << total;
}

TEST(GestureGeometryTest, TheMedianSkeletonRemovesSingleFrameNoiseAndKeepsMissingKeypointsMissing) {
  Worker w;
  w.straightArm(true, 90.0, 0.0);
  std::vector<Skeleton3D> frames(5, w.s);
  frames[1].p_world[gf::gesture::kLeftElbow] += Vector3d(0.0, 0.0, 0.30);  // one wild elbow
  frames[3].valid[gf::gesture::kLeftWrist] = false;                       // one missing wrist
  for (auto& f : frames) f.valid[gf::gesture::kNose] = false;             // never seen
  const Skeleton3D m = gf::gesture::medianSkeleton(frames, 0, 4);
  EXPECT_LT((m.p_world[gf::gesture::kLeftElbow] - w.at(gf::gesture::kLeftElbow)).norm(), 1e-12);
  EXPECT_TRUE(m.valid[gf::gesture::kLeftWrist]);
  EXPECT_LT((m.p_world[gf::gesture::kLeftWrist] - w.at(gf::gesture::kLeftWrist)).norm(), 1e-12);
  EXPECT_FALSE(m.valid[gf::gesture::kNose]);
  // The wild frame alone reads no gesture (elbow bent), the median reads the extended arm.
  EXPECT_EQ(classifyPose3D(frames[1]).gesture_id, gf::gesture::kNone);
  EXPECT_EQ(classifyPose3D(m).gesture_id, gf::gesture::kExtendArmSide);
  // Clamped ranges; an even count takes the mean of the middle two.
  EXPECT_TRUE(gf::gesture::medianSkeleton(frames, 3, 99).valid[gf::gesture::kLeftElbow]);
  EXPECT_FALSE(gf::gesture::medianSkeleton(frames, 7, 9).valid[gf::gesture::kLeftElbow]);
  std::vector<Skeleton3D> two(2, w.s);
  two[1].p_world[gf::gesture::kLeftHip] += Vector3d(0.0, 0.0, 0.10);
  EXPECT_NEAR(gf::gesture::medianSkeleton(two, 0, 1).p_world[gf::gesture::kLeftHip].z(),
              w.at(gf::gesture::kLeftHip).z() + 0.05, 1e-12);
}

// ---------------------------------------------------------------------------------------
// GeometryRules::kNetworkTolerant (docs/gestures.md §6): palms, cross and raise as the skeleton
// network reports them (hands a hand-width apart, wrists named by their image side, a straight arm's
// elbow bent), and the near-misses of each still outside.
namespace {

gf::gesture::GestureGeometryNumbers tolerant() {
  gf::gesture::GestureGeometryNumbers n;
  n.rules = gf::gesture::GeometryRules::kNetworkTolerant;
  return n;
}

PoseVerdict tolerantVerdict(const Worker& w) { return classifyPose3D(w.s, tolerant()); }

/// The two wrists (and elbows) placed independently, in fractions of H (x forward, y left, z up).
void twoHands(Worker& w, const Vector3d& l_elbow, const Vector3d& l_wrist, const Vector3d& r_elbow, const Vector3d& r_wrist) {
  w.set(gf::gesture::kLeftElbow, w.H * l_elbow);
  w.set(gf::gesture::kLeftWrist, w.H * l_wrist);
  w.set(gf::gesture::kRightElbow, w.H * r_elbow);
  w.set(gf::gesture::kRightWrist, w.H * r_wrist);
}

}  // namespace

TEST(GestureGeometryTolerantTest, TheDefaultsAreTheDesignsAndTheTolerantNumbersAreTheTrainingSetsChoice) {
  EXPECT_EQ(gf::gesture::GestureGeometryNumbers{}.rules, gf::gesture::GeometryRules::kDesign);
  // Chosen on the rendered training sets 3801-3804 (tools/gesture/fit_3d_regions.py, session 32)
  const gf::gesture::TolerantGeometryNumbers t;
  EXPECT_EQ(t.palms_max_separation_H, 0.13);
  EXPECT_EQ(t.palms_min_height_H, 0.65);
  EXPECT_EQ(t.palms_max_height_H, 0.78);
  EXPECT_EQ(t.tool_max_height_H, 0.61);
  EXPECT_EQ(t.max_midline_offset_H, 0.15);
  EXPECT_EQ(t.palms_max_centre_offset_H, 0.08);
  EXPECT_EQ(t.palms_forearm_max_deg, 20.0);
  EXPECT_EQ(t.cross_max_midline_offset_H, 0.20);
  EXPECT_EQ(t.cross_min_height_H, 0.80);
  EXPECT_EQ(t.cross_max_height_H, 0.90);
  EXPECT_EQ(t.folded_max_height_H, 0.70);
  EXPECT_EQ(t.extend_min_shoulder_wrist_deg, 62.0);
  EXPECT_EQ(t.extend_max_shoulder_wrist_deg, 115.0);
  EXPECT_EQ(t.extend_min_horizontal_deg, 65.0);
  EXPECT_EQ(t.extend_min_elbow_deg, 130.0);
  EXPECT_EQ(t.pointing_max_shoulder_wrist_deg, 55.0);
  EXPECT_EQ(t.raise_min_shoulder_wrist_deg, 140.0);
  EXPECT_EQ(t.raise_min_elbow_deg, 120.0);
  EXPECT_EQ(t.reach_max_shoulder_wrist_deg, 130.0);
  EXPECT_EQ(t.reach_max_elbow_deg, 120.0);
  EXPECT_EQ(t.one_arm_max_trunk_tilt_deg, 20.0);
  EXPECT_EQ(t.one_arm_max_foot_offset_torso, 0.8);
}

TEST(GestureGeometryTolerantTest, PalmsAHandWidthApartAtMidChestArePalmsTogether) {
  Worker w;
  w.hands({0.06, 0.15, 0.71}, {0.22, 0.05, 0.73});  // wrists 0.10 H apart, as MoveNet reports palms
  EXPECT_EQ(classifyPose3D(w.s).gesture_id, gf::gesture::kNone);  // the design's region: ≤ 0.06 H
  const PoseVerdict v = tolerantVerdict(w);
  EXPECT_EQ(v.gesture_id, gf::gesture::kPalmsTogether) << gf::gesture::toString(v.region);
  w.hands({0.06, 0.15, 0.71}, {0.22, 0.01, 0.73});  // the design's palms stay palms
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kPalmsTogether);
}

TEST(GestureGeometryTolerantTest, ObjectsToolsAndTiltedForearmsAreNotPalmsTogether) {
  Worker w;
  w.hands({0.06, 0.15, 0.71}, {0.22, 0.08, 0.73});  // wrists 0.16 H apart: an object held at the chest
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kNone);
  // hands 0.10 H apart at the chest but off to one side (the object held beside the body)
  twoHands(w, {0.06, 0.20, 0.71}, {0.22, 0.20, 0.73}, {0.06, -0.02, 0.71}, {0.22, 0.10, 0.73});
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kNone);
  w.hands({0.10, 0.15, 0.56}, {0.20, 0.05, 0.72});  // forearms ~45° up
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kNone);
  w.hands({-0.10, 0.15, 0.71}, {-0.04, 0.05, 0.73});  // behind the back
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kNone);
  w.hands({0.02, 0.14, 0.60}, {0.18, 0.05, 0.58});  // a tool held at the waist, hands 0.10 H apart
  const PoseVerdict tool = tolerantVerdict(w);
  EXPECT_EQ(tool.gesture_id, gf::gesture::kNone);
  EXPECT_EQ(tool.region, PoseRegion::kToolAtWaist);
  w.hands({0.02, 0.14, 0.62}, {0.18, 0.05, 0.63});  // between the waist and mid-chest: the band
  const PoseVerdict band = tolerantVerdict(w);
  EXPECT_EQ(band.gesture_id, gf::gesture::kNone);
  EXPECT_EQ(band.region, PoseRegion::kBand);
  EXPECT_EQ(band.nearest_gesture, gf::gesture::kPalmsTogether);
}

TEST(GestureGeometryTolerantTest, HighWristsNearTheMidlineAreCrossArmsWhicheverWristIsNamedLeft) {
  Worker w;
  w.hands({0.10, 0.16, 0.70}, {0.17, 0.04, 0.84});  // not crossed as named (the network's sides)
  EXPECT_EQ(classifyPose3D(w.s).gesture_id, gf::gesture::kNone);
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kCrossArms);
  w.hands({0.10, 0.16, 0.70}, {0.17, -0.04, 0.84});  // crossed: the design's cross stays cross
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kCrossArms);
}

TEST(GestureGeometryTolerantTest, LadderRungsFoldedArmsAndTheBandAreNotCrossArms) {
  Worker w;
  w.hands({0.15, 0.17, 0.80}, {0.20, 0.14, 0.94});  // hands on a ladder's rungs: 0.14 H off the midline
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kNone);
  w.hands({0.06, 0.15, 0.58}, {0.12, 0.08, 0.62});  // arms folded low, wrists uncrossed as named
  const PoseVerdict folded = tolerantVerdict(w);
  EXPECT_EQ(folded.gesture_id, gf::gesture::kNone);
  EXPECT_EQ(folded.region, PoseRegion::kArmsFoldedLow);
  w.hands({0.08, 0.16, 0.64}, {0.15, 0.05, 0.73});  // near the midline at 0.73 H, forearms tilted: the band
  const PoseVerdict band = tolerantVerdict(w);
  EXPECT_EQ(band.gesture_id, gf::gesture::kNone);
  EXPECT_EQ(band.region, PoseRegion::kBand);
  EXPECT_EQ(band.nearest_gesture, gf::gesture::kCrossArms);
}

// The label-free cross between the shoulders and the face (rendered_tuning_2: without the ceiling it
// held in 29 % of the ladder-climbing frames and, from 0.76 H, in 26 % of an object held at the chest).
TEST(GestureGeometryTolerantTest, LabelFreeCrossLiesBetweenTheShouldersAndTheFace) {
  Worker w;
  w.hands({0.10, 0.16, 0.74}, {0.17, 0.11, 0.85});  // 0.11 H off the midline at 0.85 H
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kCrossArms);
  w.hands({0.12, 0.14, 0.80}, {0.20, 0.06, 0.91});  // near the midline above the face: rungs, not a cross
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kNone);
  w.hands({0.10, 0.16, 0.70}, {0.20, 0.07, 0.79});  // a box held at the chest (wrists 0.14 H apart): below 0.80 H
  const PoseVerdict chest = tolerantVerdict(w);
  EXPECT_EQ(chest.gesture_id, gf::gesture::kNone);
  w.hands({0.10, 0.16, 0.74}, {0.17, 0.19, 0.85});  // 0.19 H off the midline: still in (the network's uncrossed wrists)
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kCrossArms);
  w.hands({0.10, 0.22, 0.74}, {0.17, 0.22, 0.85});  // 0.22 H off the midline: out
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kNone);
}

TEST(GestureGeometryTolerantTest, ARaisedArmWithABentReadElbowIsRaiseAReachIsNot) {
  Worker w;
  // upper arm 140° from hanging, forearm 170° (beside the head): the elbow reads 150°, the line
  // shoulder → wrist ~154° — MoveNet's raised arm (§9: upper arm 140°, elbow 152°)
  const auto dir = [](double deg) { return Vector3d(0.0, std::sin(degToRad(deg)), -std::cos(degToRad(deg))); };
  w.armDir(true, dir(140.0), dir(170.0));
  const auto m = gf::gesture::measurePose(w.s);
  ASSERT_TRUE(m.left.valid);
  EXPECT_GT(m.left.shoulder_wrist_elevation_deg, 150.0);
  EXPECT_LT(m.left.shoulder_wrist_elevation_deg, 156.0);
  EXPECT_EQ(classifyPose3D(w.s).gesture_id, gf::gesture::kNone);  // the design's upper arm ≥ 150°
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kRaiseArmUp);
  // reaching up to a bolt: upper arm 100°, elbow ~117° (§9) -> the line ~125°
  w.armDir(true, dir(100.0), dir(163.0));
  const PoseVerdict reach = tolerantVerdict(w);
  EXPECT_EQ(reach.gesture_id, gf::gesture::kNone);
  EXPECT_EQ(reach.region, PoseRegion::kReachingUp);
  // the line at ~138°, elbow ~160°: the band
  w.armDir(true, dir(130.0), dir(150.0));
  const PoseVerdict band = tolerantVerdict(w);
  EXPECT_EQ(band.gesture_id, gf::gesture::kNone);
  EXPECT_EQ(band.region, PoseRegion::kBand);
  EXPECT_EQ(band.nearest_gesture, gf::gesture::kRaiseArmUp);
}

TEST(GestureGeometryTolerantTest, ExtendIsReadOnTheLineShoulderToWristAndItsNearMissesStayOut) {
  Worker w;
  // the other arm hanging a little outward (its wrist 0.24 H from the midline: outside the label-free
  // cross's 0.20 H, whose band would otherwise name the region of a high and a low wrist)
  w.armDir(false, {0.0, -0.5, -1.0}, {0.0, -0.2, -1.0});
  w.straightArm(true, 90.0, 0.0);
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kExtendArmSide);
  // the network's sideways arm: upper arm 60° from hanging, forearm 85° — the design's region refuses
  // it (upper arm < 70°), the line shoulder → wrist (~71°) is extend's
  const auto side = [](double deg) { return Vector3d(0.0, std::sin(degToRad(deg)), -std::cos(degToRad(deg))); };
  w.armDir(true, side(60.0), side(85.0));
  EXPECT_EQ(classifyPose3D(w.s).gesture_id, gf::gesture::kNone);
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kExtendArmSide);
  w.straightArm(true, 90.0, 90.0);  // pointing forward
  EXPECT_EQ(tolerantVerdict(w).region, PoseRegion::kArmPartwayOrPointing);
  w.straightArm(true, 90.0, 30.0);  // 60° from forward: the band
  EXPECT_EQ(tolerantVerdict(w).region, PoseRegion::kBand);
  w.straightArm(true, 40.0, 0.0);  // part-way
  EXPECT_EQ(tolerantVerdict(w).region, PoseRegion::kArmPartwayOrPointing);
  w.straightArm(true, 58.0, 0.0);  // between part-way and extend: the band
  EXPECT_EQ(tolerantVerdict(w).region, PoseRegion::kBand);
  w.armDir(true, side(90.0), Vector3d(0.0, 0.2, 1.0));  // upper arm sideways, forearm up: elbow ~100°
  EXPECT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kNone);
}

// A lunge's or a side kick's arm is where extend's (or raise's) is; signals are given standing.
TEST(GestureGeometryTolerantTest, OneArmGesturesOnlyStandingUpright) {
  Worker w;
  w.straightArm(true, 90.0, 0.0);
  ASSERT_EQ(tolerantVerdict(w).gesture_id, gf::gesture::kExtendArmSide);
  Worker wide = w;  // an ankle 1.0 torso lengths (0.30 H) from under the hips: a lunge
  wide.set(gf::gesture::kRightAnkle, {0.0, -0.30 * w.H, 0.04 * w.H});
  EXPECT_EQ(tolerantVerdict(wide).gesture_id, gf::gesture::kNone);
  EXPECT_EQ(tolerantVerdict(wide).region, PoseRegion::kBand);
  Worker unseen = w;  // ankles not seen: unknown stance
  unseen.s.valid[gf::gesture::kLeftAnkle] = false;
  EXPECT_EQ(tolerantVerdict(unseen).gesture_id, gf::gesture::kNone);
  // trunk leaning 30° forward: the whole body turned about the hips' axis (the arm with it)
  Worker lean = w;
  const Eigen::AngleAxisd tilt(degToRad(30.0), Vector3d::UnitY());
  const Vector3d hips(0.0, 0.0, 0.52 * w.H);
  for (std::size_t k = 0; k < lean.s.p_world.size(); ++k) {
    if (k == gf::gesture::kLeftAnkle || k == gf::gesture::kRightAnkle || k == gf::gesture::kLeftKnee ||
        k == gf::gesture::kRightKnee) {
      continue;
    }
    lean.s.p_world[k] = hips + tilt * (lean.s.p_world[k] - hips);
  }
  EXPECT_EQ(tolerantVerdict(lean).gesture_id, gf::gesture::kNone);
  EXPECT_EQ(classifyPose3D(lean.s).gesture_id, gf::gesture::kExtendArmSide);  // the design's regions have no stance
  Worker up;  // raise likewise
  up.straightArm(true, 175.0, 0.0);
  ASSERT_EQ(tolerantVerdict(up).gesture_id, gf::gesture::kRaiseArmUp);
  up.set(gf::gesture::kLeftAnkle, {0.0, 0.40 * up.H, 0.04 * up.H});
  EXPECT_EQ(tolerantVerdict(up).gesture_id, gf::gesture::kNone);
}

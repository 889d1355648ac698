#include "gesture_formation/gesture/skeleton_synth.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include <Eigen/Geometry>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/common/csv.hpp"

namespace gesture_formation::gesture {

namespace {

using common::degToRad;
using Eigen::Vector3d;

double smoothstep(double s) {
  s = std::clamp(s, 0.0, 1.0);
  return s * s * (3.0 - 2.0 * s);
}

/// Two-link IK: elbow and wrist for a shoulder, a wrist target, segment lengths and a
/// pole direction (where the elbow points). Unreachable targets are pulled in.
void solveArm(const Vector3d& shoulder, const Vector3d& target, double a, double b, const Vector3d& pole,
              Vector3d& elbow, Vector3d& wrist) {
  Vector3d axis = target - shoulder;
  double dist = axis.norm();
  if (dist < 1e-9) {
    axis = Vector3d(0, 0, -1);
    dist = 1e-9;
  }
  const Vector3d e = axis / dist;
  dist = std::clamp(dist, std::abs(a - b) + 1e-4, a + b - 1e-4);
  const double x = (a * a - b * b + dist * dist) / (2.0 * dist);
  const double r = std::sqrt(std::max(0.0, a * a - x * x));
  Vector3d n = pole - pole.dot(e) * e;
  if (n.norm() < 1e-9) n = (std::abs(e.z()) < 0.9 ? Vector3d(0, 0, -1) : Vector3d(-1, 0, 0)) - e.z() * e;
  n.normalize();
  elbow = shoulder + x * e + r * n;
  wrist = shoulder + dist * e;
}

/// Mirrors a body-frame vector to the other side (y → −y).
Vector3d mirror(const Vector3d& v) { return Vector3d(v.x(), -v.y(), v.z()); }

}  // namespace

const char* toString(Motion m) {
  switch (m) {
    case Motion::kCrossArms: return "cross_arms";
    case Motion::kExtendArmSide: return "extend_arm_side";
    case Motion::kPalmsTogether: return "palms_together";
    case Motion::kRaiseArmUp: return "raise_arm_up";
    case Motion::kReachUpBolt: return "reach_up_bolt";
    case Motion::kArmsFoldedLow: return "arms_folded_low";
    case Motion::kToolAtWaist: return "tool_at_waist";
    case Motion::kArmPartwayOrPointing: return "arm_partway_or_pointing";
    case Motion::kWalking: return "walking";
    case Motion::kClimbingLadder: return "climbing_ladder";
    case Motion::kIdle: return "idle";
    case Motion::kHoldObjectAtChest: return "hold_object_at_chest";
    case Motion::kBalanceLunge: return "balance_lunge";
    case Motion::kCount: break;
  }
  return "?";
}

int gestureIdOf(Motion m) {
  switch (m) {
    case Motion::kCrossArms: return kCrossArms;
    case Motion::kExtendArmSide: return kExtendArmSide;
    case Motion::kPalmsTogether: return kPalmsTogether;
    case Motion::kRaiseArmUp: return kRaiseArmUp;
    default: return kNone;
  }
}

const common::FieldTable<SynthConfig>& synthConfigFields() {
  using C = SynthConfig;
  using common::Range;
  static const common::FieldTable<SynthConfig> t{{
      {"fps", Range::openClosed(0.0, 120.0), [](C& c) { return &c.fps; }},
      {"height_min_m", Range::closed(1.0, 2.3), [](C& c) { return &c.height_min_m; }},
      {"height_max_m", Range::closed(1.0, 2.3), [](C& c) { return &c.height_max_m; }},
      {"proportion_jitter", Range::closed(0.0, 0.3), [](C& c) { return &c.proportion_jitter; }},
      {"distance_min_m", Range::closed(1.5, 100.0), [](C& c) { return &c.distance_min_m; }},
      {"distance_max_m", Range::closed(1.5, 100.0), [](C& c) { return &c.distance_max_m; }},
      {"elevation_min_deg", Range::closed(-30.0, 80.0), [](C& c) { return &c.elevation_min_deg; }},
      {"elevation_max_deg", Range::closed(-30.0, 80.0), [](C& c) { return &c.elevation_max_deg; }},
      {"azimuth_min_deg", Range::closed(-360.0, 360.0), [](C& c) { return &c.azimuth_min_deg; }},
      {"azimuth_max_deg", Range::closed(-360.0, 360.0), [](C& c) { return &c.azimuth_max_deg; }},
      {"tempo_min", Range::closed(0.1, 5.0), [](C& c) { return &c.tempo_min; }},
      {"tempo_max", Range::closed(0.1, 5.0), [](C& c) { return &c.tempo_max; }},
      {"hold_min_s", Range::closed(0.0, 30.0), [](C& c) { return &c.hold_min_s; }},
      {"hold_max_s", Range::closed(0.0, 30.0), [](C& c) { return &c.hold_max_s; }},
      {"lead_min_s", Range::closed(0.0, 30.0), [](C& c) { return &c.lead_min_s; }},
      {"lead_max_s", Range::closed(0.0, 30.0), [](C& c) { return &c.lead_max_s; }},
      {"keypoint_noise_min", Range::closed(0.0, 0.2), [](C& c) { return &c.keypoint_noise_min; }},
      {"keypoint_noise_max", Range::closed(0.0, 0.2), [](C& c) { return &c.keypoint_noise_max; }},
      {"dropout_max", Range::closed(0.0, 0.9), [](C& c) { return &c.dropout_max; }},
      {"box_jitter", Range::closed(0.0, 0.3), [](C& c) { return &c.box_jitter; }},
      {"gesture_fraction", Range::closed(0.0, 1.0), [](C& c) { return &c.gesture_fraction; }},
  }};
  return t;
}

std::vector<common::ConfigError> synthConfigProblems(const SynthConfig& c) {
  std::vector<common::ConfigError> e = synthConfigFields().rangeProblems(c);
  const auto interval = [&e](double lo, double hi, const std::string& name, const std::string& unit) {
    common::checkRule(e, lo <= hi, name + "_max" + unit, hi, "must be >= " + name + "_min" + unit);
  };
  interval(c.height_min_m, c.height_max_m, "height", "_m");
  interval(c.distance_min_m, c.distance_max_m, "distance", "_m");
  interval(c.elevation_min_deg, c.elevation_max_deg, "elevation", "_deg");
  interval(c.azimuth_min_deg, c.azimuth_max_deg, "azimuth", "_deg");
  interval(c.tempo_min, c.tempo_max, "tempo", "");
  interval(c.hold_min_s, c.hold_max_s, "hold", "_s");
  interval(c.lead_min_s, c.lead_max_s, "lead", "_s");
  interval(c.keypoint_noise_min, c.keypoint_noise_max, "keypoint_noise", "");
  synthConfigFields().sortByTableOrder(e);
  return e;
}

std::vector<std::string> SynthConfig::validate() const {
  std::vector<std::string> e = common::problemLines(synthConfigProblems(*this));
  for (const auto& c : camera.validate()) e.push_back(c);
  return e;
}

SkeletonSynthesizer::SkeletonSynthesizer(const SynthConfig& config, std::uint64_t seed)
    : config_(config), camera_(config.camera), rng_(seed), seed_(seed) {
  drawShape();
}

void SkeletonSynthesizer::drawShape() {
  std::uniform_real_distribution<double> uh(config_.height_min_m, config_.height_max_m);
  std::uniform_real_distribution<double> uj(1.0 - config_.proportion_jitter, 1.0 + config_.proportion_jitter);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const double H = uh(rng_);
  shape_.height = H;
  // Segment lengths as fractions of the height (Drillis & Contini), each jittered.
  shape_.shoulder_half = 0.129 * H * uj(rng_);
  shape_.hip_half = 0.085 * H * uj(rng_);
  shape_.upper_arm = 0.186 * H * uj(rng_);
  shape_.forearm = 0.146 * H * uj(rng_);
  shape_.ankle_z = 0.039 * H;
  shape_.knee_z = 0.285 * H * uj(rng_);
  shape_.hip_z = 0.530 * H * (1.0 + 0.5 * (uj(rng_) - 1.0));
  shape_.shoulder_z = 0.818 * H * (1.0 + 0.3 * (uj(rng_) - 1.0));
  shape_.nose_z = 0.915 * H;
  var_ = Variation{u01(rng_), u01(rng_), u01(rng_), u01(rng_)};
}

/// The arms' IK targets and elbow poles being posed (pose()); one-arm motions are written in the
/// left arm's frame and mirrored for the right arm.
struct SkeletonSynthesizer::ArmTargets {
  Vector3d sL, sR;  ///< shoulders
  double reach;     ///< upper arm + forearm
  bool left_arm;
  Vector3d pose_L, pose_R, ppole_L, ppole_R;

  void oneArm(const Vector3d& target_left_frame, const Vector3d& pole_left_frame) {
    if (left_arm) {
      pose_L = target_left_frame;
      ppole_L = pole_left_frame;
    } else {
      pose_R = mirror(target_left_frame);
      ppole_R = mirror(pole_left_frame);
    }
  }
  // Explicit return type: an Eigen expression returned by `auto` would dangle (conventions).
  Vector3d straight(const Vector3d& dir_left_frame) const { return sL + 0.999 * reach * dir_left_frame.normalized(); }
};

Body3D SkeletonSynthesizer::pose(Motion motion, double s, double phase, bool left_arm) const {
  const BodyShape& b = shape_;
  const double H = b.height;
  Body3D body;
  auto& p = body.p;
  const Vector3d sL(0, b.shoulder_half, b.shoulder_z), sR(0, -b.shoulder_half, b.shoulder_z);
  p[kLeftShoulder] = sL;
  p[kRightShoulder] = sR;
  p[kLeftHip] = Vector3d(0, b.hip_half, b.hip_z);
  p[kRightHip] = Vector3d(0, -b.hip_half, b.hip_z);
  p[kLeftKnee] = Vector3d(0.01 * H, b.hip_half, b.knee_z);
  p[kRightKnee] = Vector3d(0.01 * H, -b.hip_half, b.knee_z);
  p[kLeftAnkle] = Vector3d(0, b.hip_half, b.ankle_z);
  p[kRightAnkle] = Vector3d(0, -b.hip_half, b.ankle_z);
  p[kNose] = Vector3d(0.05 * H, 0, b.nose_z);
  p[kLeftEye] = Vector3d(0.042 * H, 0.018 * H, b.nose_z + 0.02 * H);
  p[kRightEye] = Vector3d(0.042 * H, -0.018 * H, b.nose_z + 0.02 * H);
  p[kLeftEar] = Vector3d(-0.005 * H, 0.045 * H, b.nose_z + 0.012 * H);
  p[kRightEar] = Vector3d(-0.005 * H, -0.045 * H, b.nose_z + 0.012 * H);
  body.head_top = Vector3d(0, 0, H);

  const double reach = b.upper_arm + b.forearm;
  // Rest: arms hanging, slightly out and forward, elbows pointing back.
  const Vector3d rest_dir_L = Vector3d(0.05, 0.12, -1.0).normalized();
  Vector3d target_L = sL + 0.97 * reach * rest_dir_L;
  Vector3d target_R = sR + 0.97 * reach * mirror(rest_dir_L);
  Vector3d pole_L(-1, 0.2, 0), pole_R(-1, -0.2, 0);
  ArmTargets a{sL, sR, reach, left_arm, target_L, target_R, pole_L, pole_R};
  if (!staticArms(motion, a)) movingArms(motion, s, phase, a, body);
  const Vector3d &pose_L = a.pose_L, &pose_R = a.pose_R, &ppole_L = a.ppole_L, &ppole_R = a.ppole_R;
  const bool cyclic = motion == Motion::kWalking || motion == Motion::kClimbingLadder;
  const double w = cyclic ? 1.0 : s;
  target_L = target_L + w * (pose_L - target_L);
  target_R = target_R + w * (pose_R - target_R);
  pole_L = (pole_L.normalized() + w * (ppole_L.normalized() - pole_L.normalized()));
  pole_R = (pole_R.normalized() + w * (ppole_R.normalized() - pole_R.normalized()));
  solveArm(sL, target_L, b.upper_arm, b.forearm, pole_L, p[kLeftElbow], p[kLeftWrist]);
  solveArm(sR, target_R, b.upper_arm, b.forearm, pole_R, p[kRightElbow], p[kRightWrist]);
  lungeStance(motion, s, left_arm, body);
  return body;
}

bool SkeletonSynthesizer::staticArms(Motion motion, ArmTargets& a) const {
  const BodyShape& b = shape_;
  const double H = b.height;
  const double va = var_.a, vb = var_.b, vc = var_.c, vd = var_.d;
  switch (motion) {
    case Motion::kCrossArms: {  // forearms crossed in front of the upper chest/face, wrists ≥ shoulders
      const Vector3d wl((0.15 + 0.05 * va) * H, -(0.03 + 0.03 * vb) * H, b.shoulder_z + 0.08 * vc * H);
      a.pose_L = wl;
      a.pose_R = mirror(wl);
      a.ppole_L = Vector3d(0, 1, -1);
      a.ppole_R = Vector3d(0, -1, -1);
      break;
    }
    case Motion::kExtendArmSide: {  // abducted 70–110°, straight, ±15° forward
      const double abd = degToRad(70 + 40 * va), fwd = degToRad(-15 + 30 * vb);
      a.oneArm(a.straight(Vector3d(std::sin(abd) * std::sin(fwd), std::sin(abd) * std::cos(fwd), -std::cos(abd))),
             Vector3d(-1, 0, -0.3));
      break;
    }
    case Motion::kPalmsTogether: {  // wrists meet in front of the mid-chest, forearms ~horizontal
      const double x = (0.20 + 0.05 * va) * H, z = (0.70 + 0.04 * vb) * H, half_gap = (0.004 + 0.01 * vc) * H;
      a.pose_L = Vector3d(x, half_gap, z);
      a.pose_R = Vector3d(x, -half_gap, z);
      a.ppole_L = Vector3d(0, 1, -0.3);
      a.ppole_R = Vector3d(0, -1, -0.3);
      break;
    }
    case Motion::kRaiseArmUp: {  // straight up, within 25° of vertical (flexion/abduction > 155°)
      const double tilt = degToRad(25 * va), az = degToRad(90 * vb);
      a.oneArm(a.straight(Vector3d(std::sin(tilt) * std::cos(az), std::sin(tilt) * std::sin(az), std::cos(tilt))),
             Vector3d(0, 1, 0));
      break;
    }
    case Motion::kReachUpBolt: {  // bent arm in front of the body, hand above the head
      Vector3d t((0.25 + 0.10 * va) * H, (0.05 * vb - 0.02) * H, (0.98 + 0.08 * vc) * H);
      if ((t - a.sL).norm() > 0.85 * a.reach) t = a.sL + 0.85 * a.reach * (t - a.sL).normalized();
      a.oneArm(t, Vector3d(0, 0.5, -1));
      break;
    }
    case Motion::kArmsFoldedLow: {  // wrists at the opposite elbows, below the chest
      const Vector3d wl(0.12 * H, -(0.06 + 0.03 * va) * H, (0.60 + 0.04 * vb) * H);
      a.pose_L = wl;
      a.pose_R = mirror(wl) + Vector3d(0, 0, -0.01 * H);
      a.ppole_L = Vector3d(-0.3, 1, -0.5);
      a.ppole_R = Vector3d(-0.3, -1, -0.5);
      break;
    }
    case Motion::kToolAtWaist: {  // both hands low at the waist, wrists below the elbows
      const double x = (0.18 + 0.04 * va) * H, z = (0.52 + 0.05 * vb) * H;
      a.pose_L = Vector3d(x, 0.02 * H, z);
      a.pose_R = Vector3d(x, -0.02 * H, z);
      a.ppole_L = Vector3d(-1, 0.5, 0);
      a.ppole_R = Vector3d(-1, -0.5, 0);
      break;
    }
    case Motion::kArmPartwayOrPointing: {
      if (vd < 0.5) {  // raised part-way to the side: abduction 25–55°
        const double abd = degToRad(25 + 30 * va);
        a.oneArm(a.straight(Vector3d(0.1, std::sin(abd), -std::cos(abd))), Vector3d(-1, 0, 0));
      } else {  // pointing forward, −10…+20° elevation, 0–35° outward
        const double el = degToRad(-10 + 30 * vb), az = degToRad(35 * vc);
        a.oneArm(a.straight(Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el))),
               Vector3d(0, 0, -1));
      }
      break;
    }
    default:
      return false;
  }
  return true;
}

void SkeletonSynthesizer::movingArms(Motion motion, double s, double phase, ArmTargets& a, Body3D& body) const {
  const BodyShape& b = shape_;
  const double H = b.height;
  const double va = var_.a, vb = var_.b, vc = var_.c, vd = var_.d;
  auto& p = body.p;
  switch (motion) {
    case Motion::kWalking: {
      const double arm_amp = degToRad(20 + 15 * va), leg_amp = degToRad(18 + 12 * vb);
      const double th = s * arm_amp * std::sin(phase);
      a.pose_L = a.sL + 0.97 * a.reach * Vector3d(std::sin(th), 0.1, -std::cos(th)).normalized();
      a.pose_R = a.sR + 0.97 * a.reach * mirror(Vector3d(std::sin(-th), 0.1, -std::cos(-th)).normalized());
      const double legL = -s * leg_amp * std::sin(phase), legR = -legL;
      const double leg_len = b.hip_z - b.ankle_z;
      p[kLeftAnkle] = Vector3d(leg_len * std::sin(legL), b.hip_half, b.hip_z - leg_len * std::cos(legL));
      p[kRightAnkle] = Vector3d(leg_len * std::sin(legR), -b.hip_half, b.hip_z - leg_len * std::cos(legR));
      p[kLeftKnee] = 0.5 * (p[kLeftHip] + p[kLeftAnkle]) + Vector3d(0.03 * H, 0, 0);
      p[kRightKnee] = 0.5 * (p[kRightHip] + p[kRightAnkle]) + Vector3d(0.03 * H, 0, 0);
      break;
    }
    case Motion::kClimbingLadder: {  // hands alternate on the rails, knees lift alternately
      const double upL = 0.5 + 0.5 * std::sin(phase), upR = 0.5 + 0.5 * std::sin(phase + common::kPi);
      a.pose_L = Vector3d(0.25 * H, (0.10 + 0.04 * va) * H, (0.88 + 0.14 * upL) * H);
      a.pose_R = Vector3d(0.25 * H, -(0.10 + 0.04 * va) * H, (0.88 + 0.14 * upR) * H);
      a.ppole_L = Vector3d(0, 1, -1);
      a.ppole_R = Vector3d(0, -1, -1);
      const double liftL = s * std::max(0.0, std::sin(phase)), liftR = s * std::max(0.0, -std::sin(phase));
      p[kLeftKnee] += Vector3d(0.15 * H * liftL, 0, 0.13 * H * liftL);
      p[kLeftAnkle] += Vector3d(0.06 * H * liftL, 0, 0.12 * H * liftL);
      p[kRightKnee] += Vector3d(0.15 * H * liftR, 0, 0.13 * H * liftR);
      p[kRightAnkle] += Vector3d(0.06 * H * liftR, 0, 0.12 * H * liftR);
      break;
    }
    case Motion::kHoldObjectAtChest: {
      // An object (box, ball, tool bag) held or caught in front of the chest, the wrists apart
      // by its width (≥ 17 cm for a 1.75 m worker, wider than "palms together"), possibly
      // off to one side so that at most one wrist crosses the midline (never the X of gesture 1).
      const double x = (0.16 + 0.10 * va) * H, z = (0.66 + 0.16 * vb) * H;
      const double half = (0.05 + 0.06 * vc) * H, shift = (vd - 0.5) * 0.20 * H;
      a.pose_L = Vector3d(x, shift + half, z);
      a.pose_R = Vector3d(x, shift - half, z);
      a.ppole_L = Vector3d(-0.3, 1, -1);
      a.ppole_R = Vector3d(-0.3, -1, -1);
      break;
    }
    case Motion::kBalanceLunge: {
      // Stepping across a gap or kicking something loose: the leading arm out and up 30–60°
      // above the horizontal (between "extend" and "raise"), the other out, low and back; the
      // torso leans and the stance is wide (applied after the arms, below). The side kick
      // (half of them since v8): the leading arm −10…+50° about the horizontal.
      const bool kick = var_.variant < 0.5;
      const double up = kick ? degToRad(-10 + 60 * va) : degToRad(30 + 30 * va), fwd = degToRad(-30 + 60 * vb);
      const Vector3d lead_dir(std::cos(up) * std::sin(fwd), std::cos(up) * std::cos(fwd), std::sin(up));
      const Vector3d trail_dir = Vector3d(-0.3, 0.7, -0.6).normalized();
      if (a.left_arm) {
        a.pose_L = a.straight(lead_dir);
        a.pose_R = a.sR + 0.97 * a.reach * mirror(trail_dir);
      } else {
        a.pose_R = mirror(a.straight(lead_dir));
        a.pose_L = a.sL + 0.97 * a.reach * trail_dir;
      }
      a.ppole_L = Vector3d(-1, 0, -0.3);
      a.ppole_R = Vector3d(-1, 0, -0.3);
      break;
    }
    case Motion::kIdle:
    case Motion::kCount: {
      if (va > 0.6) {  // hands on the hips
        a.pose_L = Vector3d(0.03 * H, b.hip_half + 0.05 * H, b.hip_z + 0.05 * H);
        a.pose_R = mirror(a.pose_L);
        a.ppole_L = Vector3d(-0.5, 1, 0);
        a.ppole_R = Vector3d(-0.5, -1, 0);
      }
      break;
    }
    default:
      break;
  }
}

void SkeletonSynthesizer::lungeStance(Motion motion, double s, bool left_arm, Body3D& body) const {
  const double H = shape_.height;
  const double va = var_.a, vb = var_.b, vc = var_.c, vd = var_.d;
  auto& p = body.p;
  const auto idx = [](int k) { return static_cast<std::size_t>(k); };
  // The balancing lunge's upper body (head, shoulders, arms) rotated by R about the hip centre and
  // lowered by drop with the hips.
  const auto leanUpperBody = [&](const Eigen::Matrix3d& R, double drop) {
    const Vector3d hip_c = 0.5 * (p[kLeftHip] + p[kRightHip]);
    for (const int k : {kNose, kLeftEye, kRightEye, kLeftEar, kRightEar, kLeftShoulder, kRightShoulder, kLeftElbow,
                        kRightElbow, kLeftWrist, kRightWrist}) {
      auto& q = p[idx(k)];
      q = hip_c + R * (q - hip_c) - Vector3d(0, 0, drop);
    }
    body.head_top = hip_c + R * (body.head_top - hip_c) - Vector3d(0, 0, drop);
    p[kLeftHip].z() -= drop;
    p[kRightHip].z() -= drop;
  };
  if (motion == Motion::kBalanceLunge && var_.variant < 0.5) {
    // Side kick: the leg on the other side than the leading arm swings out sideways 0.20–0.45 H
    // and up to 0.18 H high, the standing knee bends, the upper body leans 10–40° over the
    // leading side and 0–20° forward about the hip centre.
    const double sign = left_arm ? 1.0 : -1.0;  // +y: the leading side
    const std::size_t kick_ankle = idx(left_arm ? kRightAnkle : kLeftAnkle), kick_knee = idx(left_arm ? kRightKnee : kLeftKnee);
    const std::size_t kick_hip = idx(left_arm ? kRightHip : kLeftHip), stand_knee = idx(left_arm ? kLeftKnee : kRightKnee);
    const double out = s * (0.20 + 0.25 * vb) * H, lift = s * 0.18 * vc * H, drop = s * 0.03 * H;
    p[kick_ankle] += Vector3d(0, -sign * out, lift);
    p[kick_knee] = 0.5 * (p[kick_hip] + p[kick_ankle]) + Vector3d(0.02 * H * s, 0, 0);
    p[stand_knee] += Vector3d(0.05 * H * s, 0, -0.5 * drop);
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(-sign * s * degToRad(10 + 30 * vd), Vector3d::UnitX()) *
                               Eigen::AngleAxisd(s * degToRad(20 * vc), Vector3d::UnitY()))
                                  .toRotationMatrix();
    leanUpperBody(R, drop);
  } else if (motion == Motion::kBalanceLunge) {
    // Wide stance: the leading side's foot forward, the other back; hips lowered; the upper
    // body leans forward 15–40° and sideways ±15° about the hip centre.
    const double step = s * (0.22 + 0.12 * va) * H, drop = s * 0.06 * H;
    const double sign = left_arm ? 1.0 : -1.0;
    const std::size_t front_ankle = idx(left_arm ? kLeftAnkle : kRightAnkle), back_ankle = idx(left_arm ? kRightAnkle : kLeftAnkle);
    const std::size_t front_knee = idx(left_arm ? kLeftKnee : kRightKnee), back_knee = idx(left_arm ? kRightKnee : kLeftKnee);
    p[front_ankle] += Vector3d(step, 0, 0);
    p[front_knee] += Vector3d(0.9 * step, 0, -0.3 * drop);
    p[back_ankle] += Vector3d(-0.8 * step, 0, 0);
    p[back_knee] += Vector3d(-0.4 * step, 0, -0.3 * drop);
    const Eigen::Matrix3d R =
        (Eigen::AngleAxisd(sign * s * degToRad(-15 + 30 * vd), Vector3d::UnitX()) *
         Eigen::AngleAxisd(s * degToRad(15 + 25 * vc), Vector3d::UnitY()))
            .toRotationMatrix();
    leanUpperBody(R, drop);
  }
}

SynthSequence SkeletonSynthesizer::next() {
  return nextViews({}).front();  // the same draws, one view
}

SynthSequence SkeletonSynthesizer::generate(Motion motion) {
  std::uniform_real_distribution<double> ud(config_.distance_min_m, config_.distance_max_m);
  std::uniform_real_distribution<double> ue(config_.elevation_min_deg, config_.elevation_max_deg);
  std::uniform_real_distribution<double> ua(config_.azimuth_min_deg, config_.azimuth_max_deg);
  const double d = ud(rng_), e = ue(rng_), a = ua(rng_);
  return renderViews(motion, {View{d, e, a}}).front();
}

SynthSequence SkeletonSynthesizer::generateFrom(Motion motion, double distance_m, double elevation_deg,
                                                double azimuth_deg) {
  return renderViews(motion, {View{distance_m, elevation_deg, azimuth_deg}}).front();
}

std::vector<SynthSequence> SkeletonSynthesizer::generateViewsFrom(Motion motion, const std::vector<View>& views) {
  if (views.empty()) return {};
  return renderViews(motion, views);
}

std::vector<SynthSequence> SkeletonSynthesizer::nextViews(const std::vector<double>& azimuth_offsets_deg) {
  // Motion, then distance, elevation, azimuth from the main stream (generate() draws the last three
  // the same way): a sequence with further views has the primary view of the one without.
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  Motion m;
  if (u01(rng_) < config_.gesture_fraction) {
    m = static_cast<Motion>(std::uniform_int_distribution<int>(0, 3)(rng_));
  } else {
    m = static_cast<Motion>(std::uniform_int_distribution<int>(4, static_cast<int>(Motion::kCount) - 1)(rng_));
  }
  std::uniform_real_distribution<double> ud(config_.distance_min_m, config_.distance_max_m);
  std::uniform_real_distribution<double> ue(config_.elevation_min_deg, config_.elevation_max_deg);
  std::uniform_real_distribution<double> ua(config_.azimuth_min_deg, config_.azimuth_max_deg);
  const double d = ud(rng_), e = ue(rng_), a = ua(rng_);
  std::vector<View> views{View{d, e, a}};
  // Further distances from a stream of their own (the main stream must not move).
  std::seed_seq ss{seed_, static_cast<std::uint64_t>(next_id_), std::uint64_t{0x5eedu}};
  std::mt19937_64 extra(ss);
  for (const double off : azimuth_offsets_deg) {
    double az = a + off;
    az = std::remainder(az, 360.0);
    views.push_back(View{std::uniform_real_distribution<double>(config_.distance_min_m, config_.distance_max_m)(extra), e, az});
  }
  return renderViews(m, views);
}

SkeletonSynthesizer::Script SkeletonSynthesizer::drawScript(Motion motion) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * u01(rng_); };
  Script sc;
  sc.motion = motion;
  sc.left_arm = u01(rng_) < 0.5;
  const double tempo = uniform(config_.tempo_min, config_.tempo_max);
  sc.lead = uniform(config_.lead_min_s, config_.lead_max_s);
  sc.rise = uniform(0.4, 0.9) / tempo;
  sc.hold = uniform(config_.hold_min_s, config_.hold_max_s);
  sc.fall = uniform(0.4, 0.9) / tempo;
  const double tail = uniform(config_.lead_min_s, config_.lead_max_s);
  sc.duration = sc.lead + sc.rise + sc.hold + sc.fall + tail;
  sc.cycle_hz = (motion == Motion::kWalking ? 0.9 : 0.45) * tempo;
  sc.phase0 = uniform(0.0, 2.0 * common::kPi);
  sc.noise_frac = uniform(config_.keypoint_noise_min, config_.keypoint_noise_max);
  sc.dropout = uniform(0.0, config_.dropout_max);
  return sc;
}

std::vector<SynthSequence> SkeletonSynthesizer::renderViews(Motion motion, const std::vector<View>& views) {
  drawShape();
  const Script script = drawScript(motion);
  const int id = next_id_++;
  {
    std::seed_seq ss{seed_, static_cast<std::uint64_t>(id), std::uint64_t{0x7a41a7u}};
    std::mt19937_64 variant_rng(ss);
    var_.variant = std::uniform_real_distribution<double>(0.0, 1.0)(variant_rng);
  }
  std::vector<SynthSequence> out;
  out.reserve(views.size());
  out.push_back(project(script, id, views.front(), rng_));
  for (std::size_t i = 1; i < views.size(); ++i) {
    std::seed_seq ss{seed_, static_cast<std::uint64_t>(id), static_cast<std::uint64_t>(i)};
    std::mt19937_64 rng(ss);
    // Each camera's detector has its own noise level and dropouts.
    Script own = script;
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    own.noise_frac = config_.keypoint_noise_min + (config_.keypoint_noise_max - config_.keypoint_noise_min) * u01(rng);
    own.dropout = config_.dropout_max * u01(rng);
    out.push_back(project(own, id, views[i], rng));
  }
  return out;
}

SynthSequence SkeletonSynthesizer::project(const Script& script, int id, const View& view, std::mt19937_64& rng) const {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * u01(rng); };
  std::normal_distribution<double> n01(0.0, 1.0);
  const Motion motion = script.motion;
  const double lead = script.lead, rise = script.rise, hold = script.hold, fall = script.fall;
  const double duration = script.duration, cycle_hz = script.cycle_hz, phase0 = script.phase0;
  const double noise_frac = script.noise_frac, dropout = script.dropout;

  SynthSequence seq;
  seq.id = id;
  seq.motion = motion;
  seq.left_arm = script.left_arm;
  seq.height_m = shape_.height;
  seq.distance_m = view.distance_m;
  seq.elevation_deg = view.elevation_deg;
  seq.azimuth_deg = view.azimuth_deg;
  seq.motion_start_s = lead;
  seq.motion_end_s = lead + rise + hold + fall;
  const double H = shape_.height;

  // Camera in the body frame, looking at the body centre (aim jitter ±3 % of the height).
  const double el = degToRad(view.elevation_deg), az = degToRad(view.azimuth_deg);
  const Vector3d centre(0, 0, 0.55 * H);
  const Vector3d cam = centre + view.distance_m * Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  const Vector3d aim = centre + 0.03 * H * Vector3d(n01(rng), n01(rng), n01(rng));
  const Vector3d zc = (aim - cam).normalized();
  const Vector3d xc = zc.cross(Vector3d::UnitZ()).normalized();
  const Vector3d yc = zc.cross(xc);
  Eigen::Matrix3d R_body_cam;
  R_body_cam << xc, yc, zc;
  // Which side faces the camera: face keypoints are hidden from behind, an ear from the other side.
  const double facing = std::cos(az), side = std::sin(az);

  const int frames = std::max(1, static_cast<int>(std::floor(duration * config_.fps)));
  for (int f = 0; f < frames; ++f) {
    const double t = f / config_.fps;
    double s = 0.0;
    if (t >= lead && t < lead + rise) s = smoothstep((t - lead) / rise);
    else if (t >= lead + rise && t < lead + rise + hold) s = 1.0;
    else if (t >= lead + rise + hold && t < lead + rise + hold + fall) s = 1.0 - smoothstep((t - lead - rise - hold) / fall);
    const double phase = phase0 + 2.0 * common::kPi * cycle_hz * t;
    Body3D body = pose(motion, s, phase, seq.left_arm);

    SynthFrame frame;
    frame.t_s = t;
    frame.label = (gestureIdOf(motion) != kNone && s >= 0.85) ? gestureIdOf(motion) : kNone;
    Skeleton2D& sk = frame.skeleton;
    double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
    std::array<bool, kNumKeypoints> projected{};
    for (int k = 0; k < kNumKeypoints; ++k) {
      const auto i = static_cast<std::size_t>(k);
      const auto px = camera_.project(R_body_cam.transpose() * (body.p[i] - cam));
      if (!px) continue;
      projected[i] = true;
      sk.x[i] = px->x();
      sk.y[i] = px->y();
      u0 = std::min(u0, px->x());
      u1 = std::max(u1, px->x());
      v0 = std::min(v0, px->y());
      v1 = std::max(v1, px->y());
    }
    const auto top = camera_.project(R_body_cam.transpose() * (body.head_top - cam));
    if (top) v0 = std::min(v0, top->y());
    // The person's box: keypoint extent, plus feet below the ankles and a margin, jittered.
    const double hpx = std::max(1.0, v1 - v0);
    const double wpx = std::max(0.25 * hpx, u1 - u0);
    const double cx = 0.5 * (u0 + u1);
    double bu0 = cx - 0.5 * wpx - 0.08 * wpx, bu1 = cx + 0.5 * wpx + 0.08 * wpx;
    double bv0 = v0 - 0.02 * hpx, bv1 = v1 + 0.04 * hpx;
    bu0 += config_.box_jitter * wpx * n01(rng);
    bu1 += config_.box_jitter * wpx * n01(rng);
    bv0 += config_.box_jitter * hpx * n01(rng);
    bv1 += config_.box_jitter * hpx * n01(rng);
    sk.u = bu0;
    sk.v = bv0;
    sk.w = std::max(2.0, bu1 - bu0);
    sk.h = std::max(2.0, bv1 - bv0);
    const double sigma_px = noise_frac * sk.h;
    for (int k = 0; k < kNumKeypoints; ++k) {
      const auto i = static_cast<std::size_t>(k);
      double conf = uniform(0.55, 1.0);
      double extra = 1.0;
      const bool face = k == kNose || k == kLeftEye || k == kRightEye;
      if (face && facing < -0.1) {
        conf = uniform(0.05, 0.35);
        extra = 2.5;
      }
      if ((k == kLeftEar && side < -0.5) || (k == kRightEar && side > 0.5)) {
        conf = uniform(0.05, 0.35);
        extra = 2.0;
      }
      sk.x[i] += extra * sigma_px * n01(rng);
      sk.y[i] += extra * sigma_px * n01(rng);
      const bool in_image = projected[i] && camera_.inImage(Eigen::Vector2d(sk.x[i], sk.y[i]));
      if (!in_image || u01(rng) < dropout) {
        sk.x[i] = 0.0;
        sk.y[i] = 0.0;
        conf = 0.0;
      }
      sk.c[i] = conf;
    }
    seq.frames.push_back(frame);
    seq.bodies.push_back(body);
  }
  return seq;
}

bool writeSkeletonCsv(const std::string& path, const std::vector<SynthSequence>& sequences, std::string* error) {
  std::ofstream out(path);
  if (!out) {
    if (error) *error = path + ": cannot open for writing";
    return false;
  }
  out << "t,u,v,w,h";
  for (int k = 0; k < kNumKeypoints; ++k) out << ",x" << k << ",y" << k << ",c" << k;
  out << ",label,sequence\n";
  for (const auto& seq : sequences) {
    for (const auto& f : seq.frames) {
      const auto& s = f.skeleton;
      out << common::formatDouble(f.t_s) << ',' << common::formatDouble(s.u) << ',' << common::formatDouble(s.v) << ','
          << common::formatDouble(s.w) << ',' << common::formatDouble(s.h);
      for (std::size_t k = 0; k < kNumKeypoints; ++k) {
        out << ',' << common::formatDouble(s.x[k]) << ',' << common::formatDouble(s.y[k]) << ','
            << common::formatDouble(s.c[k]);
      }
      out << ',' << f.label << ',' << seq.id << '\n';
    }
  }
  out.flush();
  if (!out) {
    if (error) *error = path + ": write failed";
    return false;
  }
  return true;
}

}  // namespace gesture_formation::gesture

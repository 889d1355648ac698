#include "gesture_formation/gesture/gesture_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "gesture_formation/common/angles.hpp"

namespace gesture_formation::gesture {

namespace {

double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return common::radToDeg(std::acos(std::clamp(a.normalized().dot(b.normalized()), -1.0, 1.0)));
}

/// One arm in the body frame (origin the shoulders' midpoint); `height_H` maps a world point to h(p).
template <class HeightOf>
ArmMeasures measureArm(const Skeleton3D& s, const BodyFrame& f, bool left, const HeightOf& height_H) {
  ArmMeasures a;
  const auto sh = static_cast<std::size_t>(left ? kLeftShoulder : kRightShoulder);
  const auto el = static_cast<std::size_t>(left ? kLeftElbow : kRightElbow);
  const auto wr = static_cast<std::size_t>(left ? kLeftWrist : kRightWrist);
  if (!s.valid[sh] || !s.valid[el] || !s.valid[wr]) return a;
  const Eigen::Matrix3d R_body_world = f.R_world_body.transpose();
  const Eigen::Vector3d upper = R_body_world * (s.p_world[el] - s.p_world[sh]);
  const Eigen::Vector3d fore = R_body_world * (s.p_world[wr] - s.p_world[el]);
  if (upper.norm() < 1e-3 || fore.norm() < 1e-3) return a;
  a.valid = true;
  a.elevation_deg = angleDeg(upper, -Eigen::Vector3d::UnitZ());
  const double outward = upper.y() * (left ? 1.0 : -1.0);
  a.horizontal_abduction_deg = common::radToDeg(std::atan2(outward, std::abs(upper.x())));
  a.elbow_deg = angleDeg(s.p_world[sh] - s.p_world[el], s.p_world[wr] - s.p_world[el]);
  a.shoulder_wrist_elevation_deg = angleDeg(upper + fore, -Eigen::Vector3d::UnitZ());
  const Eigen::Vector3d line = upper + fore;
  a.shoulder_wrist_horizontal_deg = common::radToDeg(std::atan2(line.y() * (left ? 1.0 : -1.0), std::abs(line.x())));
  a.forearm_from_horizontal_deg = std::abs(common::radToDeg(std::asin(std::clamp(fore.normalized().z(), -1.0, 1.0))));
  a.wrist_height_H = height_H(s.p_world[wr]);
  a.wrist_body = R_body_world * (s.p_world[wr] - f.p_world_origin);
  return a;
}

/// design.md §2 per gesture: inside its region, in the band to its nearest near-miss, in that
/// near-miss, or none of them.
enum class Test { kOut, kInside, kBand, kNearMiss };

Test palmsTogether(const PoseMeasures& m, const GestureGeometryNumbers& n) {
  if (!m.left.valid || !m.right.valid || m.wrist_separation_H > n.palms_max_separation_H) return Test::kOut;
  const double lo = std::min(m.left.wrist_height_H, m.right.wrist_height_H);
  const double hi = std::max(m.left.wrist_height_H, m.right.wrist_height_H);
  const double mean = 0.5 * (lo + hi);
  if (mean <= n.tool_max_height_H) return Test::kNearMiss;  // a tool held in both hands, low
  if (mean < n.palms_min_height_H) return Test::kBand;
  const bool in_front = m.left.wrist_body.x() > 0.0 && m.right.wrist_body.x() > 0.0;
  const bool level = m.left.forearm_from_horizontal_deg <= n.palms_forearm_max_from_horizontal_deg &&
                     m.right.forearm_from_horizontal_deg <= n.palms_forearm_max_from_horizontal_deg;
  return lo >= n.palms_min_height_H && hi <= n.palms_max_height_H && in_front && level ? Test::kInside : Test::kOut;
}

Test crossArms(const PoseMeasures& m, const GestureGeometryNumbers& n) {
  if (!m.left.valid || !m.right.valid || !m.wrists_crossed) return Test::kOut;
  const double lo = std::min(m.left.wrist_height_H, m.right.wrist_height_H);
  const double hi = std::max(m.left.wrist_height_H, m.right.wrist_height_H);
  if (lo >= n.cross_min_height_H) return Test::kInside;
  if (hi <= n.folded_max_height_H) return Test::kNearMiss;  // arms folded low
  return Test::kBand;
}

/// Both wrists within max_offset_H of the body's midline (either naming of the wrists).
bool wristsNearMidline(const PoseMeasures& m, double max_offset_H) {
  const double max_m = max_offset_H * m.height_m;
  return std::abs(m.left.wrist_body.y()) <= max_m && std::abs(m.right.wrist_body.y()) <= max_m;
}

/// Palms together as the networks see it (GeometryRules::kNetworkTolerant): hands a hand-width apart.
Test palmsTolerant(const PoseMeasures& m, const GestureGeometryNumbers& n) {
  const TolerantGeometryNumbers& t = n.tolerant;
  if (!m.left.valid || !m.right.valid || m.wrist_separation_H > t.palms_max_separation_H ||
      !wristsNearMidline(m, t.max_midline_offset_H) ||
      std::abs(0.5 * (m.left.wrist_body.y() + m.right.wrist_body.y())) > t.palms_max_centre_offset_H * m.height_m) {
    return Test::kOut;
  }
  const double mean = 0.5 * (m.left.wrist_height_H + m.right.wrist_height_H);
  if (mean <= t.tool_max_height_H) return Test::kNearMiss;  // a tool held in both hands, low
  if (mean < t.palms_min_height_H) return Test::kBand;
  const bool in_front = m.left.wrist_body.x() > 0.0 && m.right.wrist_body.x() > 0.0;
  const bool level = m.left.forearm_from_horizontal_deg <= t.palms_forearm_max_deg &&
                     m.right.forearm_from_horizontal_deg <= t.palms_forearm_max_deg;
  return mean <= t.palms_max_height_H && in_front && level ? Test::kInside : Test::kOut;
}

/// Cross arms without trusting which wrist the network names: both wrists near the midline between
/// the shoulders and the face (not above it: a ladder's rungs), or the design's crossed wrists.
Test crossTolerant(const PoseMeasures& m, const GestureGeometryNumbers& n) {
  if (crossArms(m, n) == Test::kInside) return Test::kInside;
  const TolerantGeometryNumbers& t = n.tolerant;
  if (!m.left.valid || !m.right.valid || !wristsNearMidline(m, t.cross_max_midline_offset_H)) return Test::kOut;
  const double lo = std::min(m.left.wrist_height_H, m.right.wrist_height_H);
  const double hi = std::max(m.left.wrist_height_H, m.right.wrist_height_H);
  if (hi > t.cross_max_height_H) return Test::kOut;
  if (lo >= t.cross_min_height_H) return Test::kInside;
  if (hi <= t.folded_max_height_H) return Test::kNearMiss;  // arms folded low
  return Test::kBand;
}

Test extendArm(const ArmMeasures& a, const GestureGeometryNumbers& n) {
  if (!a.valid || a.elevation_deg <= n.hanging_max_elevation_deg) return Test::kOut;
  const double el = a.elevation_deg, side = a.horizontal_abduction_deg;
  // The band mirrored above the shoulder: 110..125 for 55..70.
  const double mirror_max = 180.0 - n.pointing_max_abduction_deg;
  if (el >= mirror_max) return Test::kOut;  // an arm up: raise's business
  if (el <= n.pointing_max_abduction_deg || side <= n.pointing_max_abduction_deg) return Test::kNearMiss;
  if (el >= n.extend_min_abduction_deg && el <= n.extend_max_abduction_deg && side >= n.extend_min_abduction_deg) {
    return a.elbow_deg >= n.extend_min_elbow_deg ? Test::kInside : Test::kOut;
  }
  return Test::kBand;
}

Test raiseArm(const ArmMeasures& a, const GestureGeometryNumbers& n) {
  if (!a.valid) return Test::kOut;
  if (a.elevation_deg >= n.raise_min_elevation_deg && a.elbow_deg >= n.raise_min_elbow_deg) return Test::kInside;
  if (a.elevation_deg > n.reach_max_elevation_deg && a.elbow_deg >= n.reach_max_elbow_deg) return Test::kBand;
  if (a.elevation_deg > 90.0) return Test::kNearMiss;  // above the shoulder, but part-way or bent: reaching
  return Test::kOut;
}

/// Raise an arm read on the line shoulder → wrist (the elbow of a straight arm reads bent).
Test raiseTolerant(const ArmMeasures& a, const TolerantGeometryNumbers& t) {
  if (!a.valid) return Test::kOut;
  const double line = a.shoulder_wrist_elevation_deg;
  if (line >= t.raise_min_shoulder_wrist_deg && a.elbow_deg >= t.raise_min_elbow_deg) return Test::kInside;
  if (line > t.reach_max_shoulder_wrist_deg && a.elbow_deg >= t.reach_max_elbow_deg) return Test::kBand;
  if (a.elevation_deg > 90.0 || line > 90.0) return Test::kNearMiss;  // above the shoulder, but part-way or bent
  return Test::kOut;
}

/// Extend an arm read on the line shoulder → wrist (a sideways upper arm reads low, its elbow bent).
Test extendTolerant(const ArmMeasures& a, const TolerantGeometryNumbers& t, double hanging_max_deg) {
  if (!a.valid || a.shoulder_wrist_elevation_deg <= hanging_max_deg) return Test::kOut;
  const double line = a.shoulder_wrist_elevation_deg, side = a.shoulder_wrist_horizontal_deg;
  if (line >= 180.0 - t.pointing_max_shoulder_wrist_deg) return Test::kOut;  // an arm up: raise's business
  if (line <= t.pointing_max_shoulder_wrist_deg || side <= t.pointing_max_shoulder_wrist_deg) return Test::kNearMiss;
  if (line >= t.extend_min_shoulder_wrist_deg && line <= t.extend_max_shoulder_wrist_deg && side >= t.extend_min_horizontal_deg) {
    return a.elbow_deg >= t.extend_min_elbow_deg ? Test::kInside : Test::kOut;
  }
  return Test::kBand;
}

/// Standing upright enough for a one-arm gesture (TolerantGeometryNumbers: unknown stance is not).
bool upright(const PoseMeasures& m, const TolerantGeometryNumbers& t) {
  return m.stance.valid && m.stance.trunk_tilt_deg <= t.one_arm_max_trunk_tilt_deg &&
         m.stance.foot_offset_torso <= t.one_arm_max_foot_offset_torso;
}

}  // namespace

const char* toString(GeometryRules r) {
  switch (r) {
    case GeometryRules::kDesign: return "design";
    case GeometryRules::kNetworkTolerant: return "network_tolerant";
  }
  return "?";
}

const char* toString(PoseRegion r) {
  switch (r) {
    case PoseRegion::kOther: return "other";
    case PoseRegion::kGesture: return "gesture";
    case PoseRegion::kBand: return "band";
    case PoseRegion::kToolAtWaist: return "tool_at_waist";
    case PoseRegion::kArmsFoldedLow: return "arms_folded_low";
    case PoseRegion::kArmPartwayOrPointing: return "arm_partway_or_pointing";
    case PoseRegion::kReachingUp: return "reaching_up";
    case PoseRegion::kAmbiguous: return "ambiguous";
    case PoseRegion::kUnknown: return "unknown";
  }
  return "?";
}

PoseMeasures measurePose(const Skeleton3D& s, const GestureGeometryNumbers& n) {
  PoseMeasures m;
  const auto frame = bodyFrameOf(s);
  if (!frame) return m;
  const Eigen::Vector3d up = frame->R_world_body.col(2);
  const Eigen::Vector3d hips = 0.5 * (s.p_world[kLeftHip] + s.p_world[kRightHip]);
  const double torso_m = (frame->p_world_origin - hips).dot(up);
  if (!(torso_m >= 0.1)) return m;
  const double span_H = n.shoulder_height_H - n.hip_height_H;
  const auto height_H = [&](const Eigen::Vector3d& p) { return n.hip_height_H + span_H * (p - hips).dot(up) / torso_m; };
  m.valid = true;
  m.frame = *frame;
  m.height_m = torso_m / span_H;
  m.left = measureArm(s, *frame, true, height_H);
  m.right = measureArm(s, *frame, false, height_H);
  m.stance = stanceOf(s);
  if (m.left.valid && m.right.valid) {
    m.wrist_separation_H = (m.left.wrist_body - m.right.wrist_body).norm() / m.height_m;
    m.wrists_crossed = m.left.wrist_body.y() < 0.0 && m.right.wrist_body.y() > 0.0;
  }
  return m;
}

PoseVerdict classifyPose(const PoseMeasures& m, const GestureGeometryNumbers& n) {
  PoseVerdict v;
  if (!m.valid) return v;
  const bool tolerant = n.rules == GeometryRules::kNetworkTolerant;
  const Test palms = tolerant ? palmsTolerant(m, n) : palmsTogether(m, n);
  const Test cross = tolerant ? crossTolerant(m, n) : crossArms(m, n);
  Test extend[2] = {tolerant ? extendTolerant(m.left, n.tolerant, n.hanging_max_elevation_deg) : extendArm(m.left, n),
                    tolerant ? extendTolerant(m.right, n.tolerant, n.hanging_max_elevation_deg) : extendArm(m.right, n)};
  Test raise[2] = {tolerant ? raiseTolerant(m.left, n.tolerant) : raiseArm(m.left, n),
                   tolerant ? raiseTolerant(m.right, n.tolerant) : raiseArm(m.right, n)};
  if (tolerant && !upright(m, n.tolerant)) {  // a lunge's or a kick's arm: at most the band
    for (Test* t : {&extend[0], &extend[1], &raise[0], &raise[1]}) {
      if (*t == Test::kInside) *t = Test::kBand;
    }
  }
  // Gesture regions: each (gesture, arm) inside counts once; a one-arm gesture needs exactly one arm.
  std::multiset<int> inside;
  if (palms == Test::kInside) inside.insert(kPalmsTogether);
  if (cross == Test::kInside) inside.insert(kCrossArms);
  for (int a = 0; a < 2; ++a) {
    if (extend[a] == Test::kInside) inside.insert(kExtendArmSide);
    if (raise[a] == Test::kInside) inside.insert(kRaiseArmUp);
  }
  if (inside.size() == 1) {
    v.gesture_id = *inside.begin();
    v.region = PoseRegion::kGesture;
    return v;
  }
  if (inside.size() > 1) {
    v.region = PoseRegion::kAmbiguous;
    return v;
  }
  // No gesture: the band first (it is where a gesture and a near-miss meet), then the near-misses.
  const auto any = [](const Test t[2], Test want) { return t[0] == want || t[1] == want; };
  const std::pair<Test, int> bands[] = {{palms, kPalmsTogether}, {cross, kCrossArms}};
  for (const auto& [t, g] : bands) {
    if (t == Test::kBand) return PoseVerdict{kNone, PoseRegion::kBand, g};
  }
  if (any(extend, Test::kBand)) return PoseVerdict{kNone, PoseRegion::kBand, kExtendArmSide};
  if (any(raise, Test::kBand)) return PoseVerdict{kNone, PoseRegion::kBand, kRaiseArmUp};
  if (palms == Test::kNearMiss) return PoseVerdict{kNone, PoseRegion::kToolAtWaist, kPalmsTogether};
  if (cross == Test::kNearMiss) return PoseVerdict{kNone, PoseRegion::kArmsFoldedLow, kCrossArms};
  if (any(raise, Test::kNearMiss)) return PoseVerdict{kNone, PoseRegion::kReachingUp, kRaiseArmUp};
  if (any(extend, Test::kNearMiss)) return PoseVerdict{kNone, PoseRegion::kArmPartwayOrPointing, kExtendArmSide};
  v.region = PoseRegion::kOther;
  return v;
}

Skeleton3D medianSkeleton(const std::vector<Skeleton3D>& frames, std::size_t first, std::size_t last) {
  Skeleton3D out;
  if (frames.empty() || first >= frames.size()) return out;
  last = std::min(last, frames.size() - 1);
  if (last < first) return out;
  const Skeleton3D& mid = frames[first + (last - first) / 2];
  out.views = mid.views;
  out.reprojection_px = mid.reprojection_px;
  std::vector<double> c[3];
  for (std::size_t k = 0; k < out.p_world.size(); ++k) {
    for (auto& v : c) v.clear();
    for (std::size_t i = first; i <= last; ++i) {
      if (!frames[i].valid[k]) continue;
      for (int d = 0; d < 3; ++d) c[d].push_back(frames[i].p_world[k][d]);
    }
    if (c[0].empty()) continue;
    for (int d = 0; d < 3; ++d) {
      auto& v = c[d];
      const auto half = static_cast<std::ptrdiff_t>(v.size() / 2);
      std::nth_element(v.begin(), v.begin() + half, v.end());
      double m = v[static_cast<std::size_t>(half)];
      if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + half));  // even count: mean of the middle two
      out.p_world[k][d] = m;
    }
    out.valid[k] = true;
  }
  return out;
}

PoseVerdict classifyPose3D(const Skeleton3D& s, const GestureGeometryNumbers& numbers) {
  return classifyPose(measurePose(s, numbers), numbers);
}

}  // namespace gesture_formation::gesture

#pragma once
/// \file
/// \brief design.md §2's gestures and near-misses as regions of 3-D body geometry, with the
/// ambiguity band between each gesture and its nearest near-miss counted as "none"
/// (docs/gestures.md §6, "Gesture geometry in 3-D"; issue 33 item 2).
///
/// Input: a COCO-17 skeleton in 3-D (any right-handed world frame, e.g. triangulated by
/// gesture/view_triangulation.hpp). The body frame is the one of bodyFrameOf(): y along the right →
/// left shoulder axis, z from the hips' midpoint towards the shoulders' (orthogonalised), x = y × z
/// forward, origin the shoulders' midpoint. Every number below is design.md §2's ("In numbers", H =
/// standing height, shoulder joints ≈ 0.82 H, hip joints ≈ 0.52 H, upper-arm angles from hanging
/// down); none was tuned on data:
///  - heights are fractions of H along the body's up axis, placed by the skeleton's own hips
///    (0.52 H) and shoulders (0.82 H): h(p) = 0.52 + 0.30 · (p − hips)·z / (shoulders − hips)·z,
///    and lengths are in units of H = torso height / 0.30 — no ankles and no known height needed;
///  - palms together (3): wrists ≤ 0.06 H apart, both at 0.67–0.80 H, in front of the body, each
///    forearm within 30° of horizontal; near-miss "tool held in both hands": wrists together (≤ 0.06 H)
///    at ≤ 0.61 H; band: wrists together at 0.61–0.67 H;
///  - cross arms (1): each wrist crossed over the body's midline (the left wrist right of it, the
///    right wrist left of it), both at ≥ 0.80 H; near-miss "arms folded low": wrists crossed at
///    ≤ 0.70 H; band: crossed at 0.70–0.80 H;
///  - extend an arm to the side (2): upper arm abducted 70–110°, elbow ≥ 150°; near-miss "raised
///    part-way or pointing": abduction ≤ 55°; band 55–70° (and 110–125°, its mirror above the
///    shoulder). The abduction of a sideways arm is read in two planes, both of which must show it:
///    in the frontal plane, the upper arm's elevation from hanging down (70–110°; part-way ≤ 55°), and
///    in the horizontal plane, its horizontal abduction — the angle of its horizontal direction from
///    straight forward (or back) towards its own side: 90° straight sideways, 0° pointing forward
///    (≥ 70°; pointing ≤ 55°). So an arm pointing forward, or forward-outward up to 55° from forward,
///    is the near-miss at any elevation up to 125°, never "extend to the side";
///  - raise an arm up (4): upper arm ≥ 150° from hanging (elevation, any plane), elbow ≥ 150°;
///    near-miss "reaching": elevation ≤ 130° or elbow < 120°; band: elevation 130–150° or elbow 120–150°.
/// A one-arm gesture needs exactly one arm in its region; two arms in gesture regions of different
/// gestures (or a one-arm and a two-arm gesture at once) are ambiguous: none.
///
/// GeometryRules::kNetworkTolerant (docs/gestures.md §6, "3-D rules as the networks see them") replaces
/// every region by one that allows for the skeleton network's measured systematic errors (§9: MoveNet
/// names the hands by their image side, so crossed wrists triangulate uncrossed; palms' wrists a
/// hand-width apart; a raised arm's elbow reads bent, a sideways upper arm low), with the numbers of
/// TolerantGeometryNumbers, chosen on the rendered TRAINING sets (its comment):
///  - palms together: wrists ≤ 0.13 H apart, their midpoint ≤ 0.08 H and each ≤ 0.15 H from the
///    midline, their mean height 0.65–0.78 H, both in front of the body, forearms within 20° of
///    horizontal; near-miss "tool held in both hands": the same hands together at a mean ≤ 0.61 H;
///    band 0.61–0.65 H;
///  - cross arms, not depending on which wrist the network names: both wrists ≤ 0.20 H from the
///    midline, both ≥ 0.80 H and neither above 0.90 H (or the design's region: crossed, both ≥ 0.80 H);
///    near-miss "arms folded low": near the midline with the higher wrist ≤ 0.70 H; band between;
///  - extend an arm to the side: read on the line shoulder → wrist, 62–115° from hanging and ≥ 65°
///    from forward, elbow ≥ 130°; near-miss part-way or pointing: that line ≤ 55° from hanging or
///    ≤ 55° from forward; band between;
///  - raise an arm up: read on the line shoulder → wrist, ≥ 140° from hanging with the elbow ≥ 120°;
///    near-miss "reaching": that line ≤ 130° or the elbow < 120°; band between;
///  - extend and raise only standing upright (trunk ≤ 20° from vertical, ankles ≤ 0.8 torso lengths
///    from under the hips; unknown stance: none).
/// Thread safety: free functions without state.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/gesture/skeleton.hpp"
#include "gesture_formation/gesture/view_triangulation.hpp"

namespace gesture_formation::gesture {

/// \brief Which regions classifyPose() tests (file comment).
enum class GeometryRules : int {
  kDesign = 0,         ///< design.md §2's regions as written
  kNetworkTolerant,    ///< every region allowing for the skeleton network's systematic errors (one-arm: upright)
};
const char* toString(GeometryRules r);

/// \brief The numbers of GeometryRules::kNetworkTolerant (fractions of H, degrees): not design.md's. Chosen on
/// the rendered TRAINING sets (seeds 3801-3804) by the chain with the classifier replaced by the frames' labels
/// (the gestures it must pass) and by an adversary reading every work motion as each gesture in turn (the
/// near-misses it must refuse): tools/gesture/fit_3d_regions.py; docs/gestures.md §6.
struct TolerantGeometryNumbers {
  double palms_max_separation_H = 0.13;   ///< MoveNet's palms: median 0.10 H, p90 0.15 H apart
  double palms_min_height_H = 0.65, palms_max_height_H = 0.78;  ///< the wrists' mean height
  double tool_max_height_H = 0.61;        ///< band: tool_max .. palms_min
  double max_midline_offset_H = 0.15;     ///< palms: each wrist this near the midline
  double palms_max_centre_offset_H = 0.08;  ///< palms: the wrists' midpoint this near the midline
  double palms_forearm_max_deg = 20.0;    ///< palms: each forearm within this of the body's horizontal plane
  double cross_max_midline_offset_H = 0.20;  ///< label-free cross: each wrist this near the midline
  double cross_min_height_H = 0.80;       ///< label-free cross: both wrists at least this high (design.md's 0.80)
  double cross_max_height_H = 0.90;       ///< label-free cross: neither wrist above this (the face; a ladder's rungs are higher)
  double folded_max_height_H = 0.70;      ///< band: folded_max .. cross_min
  /// Extend read on the line shoulder → wrist (the upper arm of a sideways arm reads low): the line's
  /// elevation from hanging and its horizontal abduction, the elbow at least this straight.
  double extend_min_shoulder_wrist_deg = 62.0, extend_max_shoulder_wrist_deg = 115.0;
  double extend_min_horizontal_deg = 65.0, extend_min_elbow_deg = 130.0;
  double pointing_max_shoulder_wrist_deg = 55.0;  ///< near-miss part-way or pointing (line or horizontal); band between
  double raise_min_shoulder_wrist_deg = 140.0, raise_min_elbow_deg = 120.0;
  double reach_max_shoulder_wrist_deg = 130.0, reach_max_elbow_deg = 120.0;  ///< band between
  /// One-arm gestures only standing upright (stanceOf: a lunge's or a side kick's arm is where extend's
  /// is): trunk within this of vertical, each ankle within this many torso lengths of the hips; unknown
  /// stance (ankles not seen): no one-arm gesture.
  double one_arm_max_trunk_tilt_deg = 20.0, one_arm_max_foot_offset_torso = 0.8;
};

/// \brief design.md §2's numbers (fractions of the standing height H, angles in degrees). The
/// defaults ARE the design; they are not tuning parameters (tests pin them).
struct GestureGeometryNumbers {
  double shoulder_height_H = 0.82, hip_height_H = 0.52;  ///< the body's scale: joints' heights
  double palms_max_separation_H = 0.06;                  ///< wrists "within a hand's width"
  double palms_min_height_H = 0.67, palms_max_height_H = 0.80;
  double palms_forearm_max_from_horizontal_deg = 30.0;
  double tool_max_height_H = 0.61;                       ///< band: tool_max .. palms_min
  double cross_min_height_H = 0.80;
  double folded_max_height_H = 0.70;                     ///< band: folded_max .. cross_min
  double extend_min_abduction_deg = 70.0, extend_max_abduction_deg = 110.0;  ///< elevation; horizontal: ≥ the min
  double extend_min_elbow_deg = 150.0;
  double pointing_max_abduction_deg = 55.0;              ///< band: 55..70 (and its mirror 110..125), both planes
  double raise_min_elevation_deg = 150.0, raise_min_elbow_deg = 150.0;
  double reach_max_elevation_deg = 130.0, reach_max_elbow_deg = 120.0;  ///< band: 130..150, elbow 120..150
  /// Reporting aid, not in design.md (it changes no gesture decision): an arm whose upper arm is
  /// within this of hanging down is "at rest", not the near-miss "part-way or pointing".
  double hanging_max_elevation_deg = 20.0;
  /// Which regions to test; kNetworkTolerant reads `tolerant` for palms, cross and raise.
  GeometryRules rules = GeometryRules::kDesign;
  TolerantGeometryNumbers tolerant;
};

/// \brief One arm measured in the body frame (angles [deg], heights in H, positions [m]).
struct ArmMeasures {
  bool valid = false;                 ///< shoulder, elbow and wrist known
  double elevation_deg = 0.0;         ///< upper arm (shoulder → elbow) from hanging down: 0 down, 90 horizontal, 180 up
  double horizontal_abduction_deg = 0.0;  ///< upper arm's horizontal direction from forward/back towards its own side:
                                         ///< 90 sideways, 0 forward or back, < 0 across the body (file comment)
  double elbow_deg = 180.0;           ///< inner elbow angle (180: straight)
  double shoulder_wrist_elevation_deg = 0.0;  ///< the line shoulder → wrist from hanging down (as elevation_deg)
  double shoulder_wrist_horizontal_deg = 0.0;  ///< that line's horizontal abduction (as horizontal_abduction_deg)
  double forearm_from_horizontal_deg = 90.0;  ///< |angle| of elbow → wrist to the body's horizontal plane
  double wrist_height_H = 0.0;        ///< h(wrist)
  Eigen::Vector3d wrist_body = Eigen::Vector3d::Zero();  ///< wrist in the body frame [m] (x fwd, y left, z up)
};

/// \brief The measures of design.md §2 on one 3-D skeleton.
struct PoseMeasures {
  bool valid = false;         ///< body frame (shoulders and hips) known, torso upright enough to scale
  BodyFrame frame;
  double height_m = 0.0;      ///< H implied by the torso: (shoulders − hips)·z / 0.30
  ArmMeasures left, right;
  double wrist_separation_H = 0.0;  ///< |left wrist − right wrist| / H (both arms valid)
  bool wrists_crossed = false;      ///< the left wrist right of the midline (y < 0) and the right wrist left of it
  Stance stance;                    ///< how the worker stands (stanceOf)
};

/// \brief Measures a 3-D skeleton (world frame). Invalid (valid = false) without both shoulders and
/// hips (bodyFrameOf) or with a torso shorter than 0.1 m along its own up axis; an arm is invalid
/// without its shoulder, elbow or wrist.
PoseMeasures measurePose(const Skeleton3D& s, const GestureGeometryNumbers& n = {});

/// \brief The region a pose falls in: a gesture, one of design.md §2's near-misses, the ambiguity
/// band between them, or anything else.
enum class PoseRegion : int {
  kOther = 0,           ///< none of the regions below (none)
  kGesture,             ///< `gesture_id` holds
  kBand,                ///< between a gesture and its nearest near-miss: none, no command
  kToolAtWaist,         ///< near-miss of palms together
  kArmsFoldedLow,       ///< near-miss of cross arms
  kArmPartwayOrPointing,  ///< near-miss of extend
  kReachingUp,          ///< near-miss of raise (arm up but bent, or part-way)
  kAmbiguous,           ///< two different gestures' regions at once: none
  kUnknown,             ///< not measurable (missing joints): none
};
const char* toString(PoseRegion r);

/// \brief The verdict on one pose: gesture_id ≠ 0 only with region kGesture.
struct PoseVerdict {
  int gesture_id = kNone;
  PoseRegion region = PoseRegion::kUnknown;
  /// For kBand and the near-misses: the gesture whose band / near-miss it is (kNone otherwise).
  int nearest_gesture = kNone;
};

/// \brief Classifies measured geometry by the regions of `numbers.rules` (file comment). `numbers` must be
/// consistent (each band's lower edge ≤ its upper edge); the defaults are.
PoseVerdict classifyPose(const PoseMeasures& m, const GestureGeometryNumbers& numbers = {});
/// \brief measurePose() then classifyPose().
PoseVerdict classifyPose3D(const Skeleton3D& s, const GestureGeometryNumbers& numbers = {});

/// \brief The per-keypoint median (of each world coordinate) of frames[first..last] (inclusive,
/// clamped to the vector), over the frames in which that keypoint is valid; a keypoint valid in none
/// of them stays invalid. For a held posture it averages out the triangulation noise of single
/// frames (ViewFusion's require_3d reads each frame with its neighbours). Views and reprojection
/// errors: those of the middle frame.
Skeleton3D medianSkeleton(const std::vector<Skeleton3D>& frames, std::size_t first, std::size_t last);

}  // namespace gesture_formation::gesture

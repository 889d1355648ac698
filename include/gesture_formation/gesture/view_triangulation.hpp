#pragma once
/// \file
/// \brief The worker's skeleton in 3-D from the formation's calibrated 2-D views, and the arm
/// geometry of design.md §2's one-arm gestures measured in it (docs/gestures.md §6, "3-D fusion":
/// the step after the 2-of-3 vote: gesture::ViewFusion with view_fusion.confirm_3d).
///
/// One camera cannot tell an arm extended to the side from an arm pointing forward-outward seen
/// from ~30° beside it: both project alike. Two cameras whose poses are known (the UAVs'
/// odometry; the optical frame of estimation/camera_model.hpp) see the arm in 3-D: each
/// keypoint seen with enough confidence by two or more views is the point closest, in the
/// least-squares sense weighted by confidence, to their viewing rays. The body frame is then
/// made from the triangulated shoulders and hips — y along the right → left shoulder axis, z
/// from the hips' midpoint towards the shoulders' (orthogonalised), x = y × z forward — so no
/// heading estimate is needed, and an arm's direction (shoulder → wrist) is measured in it.
/// Thread safety: free functions without state.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/estimation/camera_model.hpp"
#include "gesture_formation/gesture/skeleton.hpp"

namespace gesture_formation::gesture {

/// \brief One camera's skeleton with the camera's pose: R_world_camera rotates optical-frame
/// vectors into the world, p_world_camera is the optical centre [m].
struct CalibratedSkeleton {
  Skeleton2D skeleton;
  Eigen::Matrix3d R_world_camera = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_world_camera = Eigen::Vector3d::Zero();
  estimation::CameraIntrinsics intrinsics;
};

/// \brief Every problem of a calibrated skeleton received from outside (another UAV, a ROS
/// topic), each naming the field and the value; empty when valid: intrinsics valid
/// (CameraIntrinsics::validate), R_world_camera a rotation (orthonormal within 1e-6, det +1),
/// p_world_camera finite and within 10 km, keypoints finite, confidences in [0, 1]. The box is
/// not checked (the triangulation does not use it).
std::vector<std::string> validate(const CalibratedSkeleton& c);

/// \brief A camera distance_m from the point (0, 0, aim_height_m) of a body frame (x forward, y left,
/// z up, feet at 0), elevation_deg above the horizontal and azimuth_deg around z from x, looking at
/// that point with its image rows horizontal — the viewpoints of gesture/skeleton_synth.hpp without
/// their aim jitter (±3 % of the height). The pose is in the body frame; the skeleton is empty.
CalibratedSkeleton cameraAround(double distance_m, double elevation_deg, double azimuth_deg, double aim_height_m,
                                const estimation::CameraIntrinsics& intrinsics = {});

/// \brief Parameters of the triangulation.
struct TriangulationConfig {
  double min_confidence = 0.3;      ///< a keypoint below this confidence is not used, in [0, 1)
  double min_ray_angle_deg = 10.0;  ///< the widest angle between a keypoint's rays must reach this, in (0, 90)
  /// Skeleton networks name a person's sides by the side of the image they appear on (seen from
  /// behind, or with crossed arms, "left" is the image's left). With resolve_sides, each view's
  /// skeleton is taken as named or mirrored (every left/right pair exchanged), whichever combination
  /// of views makes the body's keypoints (eyes, ears, shoulders, hips, knees, ankles) triangulate
  /// with the least confidence-weighted squared reprojection error (ties: fewer mirrored views;
  /// at most 6 views are resolved, more are taken as named); then, if the nose triangulates more
  /// than nose_behind_m behind the shoulders (the body frame's forward axis), every label is
  /// mirrored — the views agreed with each other, and all named the sides from behind.
  bool resolve_sides = false;
  double nose_behind_m = 0.05;      ///< ≥ 0 [m]

  /// \brief Every problem, each naming the field and the value; empty when valid.
  std::vector<std::string> validate() const;
};

/// \brief Triangulated keypoints (COCO-17 order). A keypoint is valid when at least two views saw
/// it with min_confidence and their rays span min_ray_angle_deg.
struct Skeleton3D {
  std::array<Eigen::Vector3d, kNumKeypoints> p_world{};
  std::array<bool, kNumKeypoints> valid{};
  std::array<int, kNumKeypoints> views{};                   ///< views that contributed
  std::array<double, kNumKeypoints> reprojection_px{};      ///< the largest reprojection error over those views [px]
  unsigned mirrored_views = 0;  ///< resolve_sides: bit v set when view v was taken mirrored
  bool mirrored_all = false;    ///< resolve_sides: every label exchanged after the nose test
};

/// \brief Triangulates every keypoint from `views` (any number; views with a non-finite pose or a
/// non-finite keypoint are skipped for that keypoint). `config` must be valid.
Skeleton3D triangulate(const std::vector<CalibratedSkeleton>& views, const TriangulationConfig& config);

/// \brief The body frame of a triangulated skeleton: columns x forward, y left, z up (world
/// coordinates), origin the shoulders' midpoint. Nullopt unless both shoulders and both hips are
/// valid and the shoulder width and torso length are plausible (0.15–0.7 m, 0.2–1.0 m).
struct BodyFrame {
  Eigen::Matrix3d R_world_body = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p_world_origin = Eigen::Vector3d::Zero();
};
std::optional<BodyFrame> bodyFrameOf(const Skeleton3D& s);

/// \brief One arm measured in the body frame.
struct ArmGeometry {
  bool valid = false;               ///< shoulder and wrist triangulated, body frame available
  Eigen::Vector3d direction_body = Eigen::Vector3d::Zero();  ///< unit shoulder → wrist (x fwd, y left, z up)
  double from_outward_deg = 180.0;  ///< angle to the arm's own side (left arm: +y, right arm: −y)
  double from_up_deg = 180.0;       ///< angle to +z
  double from_forward_deg = 180.0;  ///< angle to +x
  double reach_ratio = 0.0;         ///< |shoulder → wrist| / |shoulder → elbow| + |elbow → wrist| (1 = straight); 0 without the elbow
};
ArmGeometry armGeometry(const Skeleton3D& s, bool left_arm);

/// \brief How the worker stands: the trunk (hips' midpoint → shoulders' midpoint) against the world
/// vertical (+z) and how far the feet are from under the hips. Signals are given standing; a side
/// kick or a lunge puts an arm where "extend" puts it, but not with the trunk upright and the feet
/// under the hips (docs/gestures.md §6).
struct Stance {
  bool valid = false;               ///< shoulders, hips and both ankles triangulated, torso ≥ 0.2 m
  double trunk_tilt_deg = 180.0;    ///< angle of the trunk to +z
  double foot_offset_torso = 0.0;   ///< the larger horizontal distance of an ankle from the hips' midpoint, in torso lengths
};
Stance stanceOf(const Skeleton3D& s);

/// \brief design.md §2 one-arm gestures, 3-D tests on a triangulated skeleton: "extend an arm to
/// the side" (2) when an arm is within extend_max_deg of its outward axis and nearly straight;
/// "raise an arm up" (4) within raise_max_deg of vertical; otherwise 0 — and 0 unless the worker
/// stands upright (stanceOf: trunk within max_trunk_tilt_deg of vertical, each ankle within
/// max_foot_offset_torso torso lengths of the hips horizontally; unknown stance: 0). Two-arm
/// gestures are not tested here (0). The arm thresholds come from the pose definitions of the
/// generator (gesture/skeleton_synth.hpp: extend = abduction 70–110°, ±15° forward, i.e. ≤ 25° from
/// the outward axis; raise ≤ 25° from vertical) plus a margin for triangulation error; the stance
/// thresholds from the generator's gestures seen by three noisy views (trunk p99 13°, feet p99 0.55)
/// against its side kicks and lunges (feet p1 0.81, trunk p50 27° in the frames whose arm reads as
/// a gesture) — measured 2026-12-03, docs/gestures.md §6.
struct ArmGestureThresholds {
  double extend_max_deg = 27.5;    ///< [deg], in (0, 90)
  double raise_max_deg = 27.5;     ///< [deg], in (0, 90)
  double min_reach_ratio = 0.85;   ///< straight arm (elbow angle ≳ 120°), in (0, 1]
  double max_trunk_tilt_deg = 20.0;  ///< [deg], in (0, 90)
  double max_foot_offset_torso = 0.8;  ///< [torso lengths], in (0, 5]

  /// \brief Every problem, each naming the field and the value; empty when valid.
  std::vector<std::string> validate() const;
};
/// `thresholds` must be valid.
int oneArmGesture3D(const Skeleton3D& s, const ArmGestureThresholds& thresholds = {});

}  // namespace gesture_formation::gesture

#pragma once
/// \file
/// \brief Multi-view vote over the gesture classifications of the formation's cameras
/// (docs/gestures.md §6; beyond the paper, whose future work it is).
///
/// One camera sees the worker in 2-D, and some work postures project exactly like a gesture
/// from some viewpoints: an arm pointing forward and outward, seen from ~30° beside the
/// pointing direction, projects like an arm extended to the side. The formation watches the
/// worker from several azimuths at once (the followers sit ±60° from the leader, Table II);
/// a posture that looks like a gesture from one of them does not from the others. Each UAV
/// classifies its own view (the same LSTM), the leader keeps the recent classifications of
/// every view and, per leader frame, fuses them into the one id that goes to the
/// GestureFilter (whose parameters stay the paper's):
///  - a view votes only when its newest classification is fresh (t_now − t ≤ max_age_s) and, with
///    gate_envelope, its camera is inside the classifier's validated envelope (distance and
///    elevation of the camera from the worker within the training ranges) — a view outside
///    it, or of unknown geometry, does not vote;
///  - with vote_window_s > 0 a view votes for the gesture it read most often among its
///    classifications (inside the envelope) of the last vote_window_s, when that gesture has
///    at least vote_min_fraction (0.5: half) of them, else for none: a view whose newest frame
///    flickers (a poorer viewpoint, e.g. along the extended arm) still counts when it reads the
///    gesture in half its frames, and one stray frame does not (vote_window_s = 0: the newest
///    classification votes). 0.3 also let a work posture through that two views read in 46 %
///    and 93 % of their frames (docs/gestures.md §4.1);
///  - the fused id is the gesture id (≠ 0) with the most votes when that count is unique and
///    ≥ min_agreeing_views; otherwise 0 (none). "none" votes never outvote a gesture, so
///    a gesture seen by two of three views passes; a posture seen as a gesture by one view
///    does not.
///  - with confirm_3d, a one-arm gesture (extend, raise) exactly one vote short still passes when
///    the views' skeletons of the vote window, triangulated (gesture/view_triangulation.hpp), show
///    the arm in that pose in at least confirm_3d_min_fraction of the 3-D frames: the geometry
///    that no 2-D view can tell apart from a pointing arm (docs/gestures.md §6). With
///    confirm_3d_scope all, every gesture one vote short is confirmed the same way, on its
///    geometry_3d region (gesture/gesture_geometry.hpp, each frame read on the median of
///    require_3d_median_frames): a two-arm gesture that only the frontal view reads in 2-D (the
///    side and rear views' networks name the hands by image side) passes when the formation's
///    3-D skeleton shows it.
///  - with require_3d (default on), every gesture the vote (or the confirmation) passes is checked in
///    3-D whenever two or more calibrated views see the worker in the vote window (an instant at
///    which two or more views' skeletons, at most confirm_3d_max_dt_s apart, triangulate): it goes
///    to the filter only when there are at least require_3d_min_frames such frames and the geometry
///    of that gesture (gesture/gesture_geometry.hpp, the regions of config.geometry.rules: design.md
///    §2's, or the network-tolerant ones; for the design's: palms together at mid-chest with
///    forearms near horizontal, wrists crossed at or above the shoulders, an arm abducted to the
///    side near horizontal, an arm straight up) holds in at least require_3d_min_fraction of them,
///    each read on the median of require_3d_median_frames frames around it; otherwise none
///    (FusedGesture::rejected_3d). With fewer calibrated views
///    (one camera, no camera poses) the vote decides alone, as without require_3d.
/// min_agreeing_views = 1 with one view is the paper's single-camera pipeline.
///
/// Link delay (fusion_lag_s, docs/gestures.md §4.1): the followers' classifications reach the
/// leader over the radio, 0.1–0.4 s late under load — older than max_age_s by the time they
/// arrive, so fused at the newest frame they would never vote. A caller that fuses at
/// t_now − fusion_lag_s compares the views at one past moment that every view's report has
/// reached: "a view's newest classification" is then its newest at or before that moment
/// (+ max_age_s, the clock tolerance), and observations may arrive up to fusion_lag_s out of
/// order (they are inserted in time order). fusion_lag_s = 0: fused at the newest frame.
/// Thread safety: none; one instance per thread.

#include <cstddef>
#include <deque>
#include <optional>
#include <string>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/gesture/gesture_geometry.hpp"
#include "gesture_formation/gesture/view_triangulation.hpp"

namespace gesture_formation::gesture {

/// \brief Parameters (YAML `view_fusion.*` of config/gestures.yaml).
struct ViewFusionConfig {
  int min_agreeing_views = 2;     ///< votes the winning gesture needs, ≥ 1 (1: single camera)
  double max_age_s = 0.25;        ///< a classification votes while t_now − t ≤ this [s], > 0
  bool gate_envelope = true;      ///< views outside the validated envelope do not vote
  double distance_min_m = 5.0;    ///< envelope (the LSTM's training ranges, docs/gestures.md §2)
  double distance_max_m = 20.0;
  double elevation_min_deg = 0.0;
  double elevation_max_deg = 45.0;
  double vote_window_s = 1.0;     ///< ≥ 0 [s]: a view votes its dominant gesture of this window (0: its newest)
  double vote_min_fraction = 0.5; ///< (0, 1]: the dominant gesture's share of the window's classifications
  /// 3-D confirmation (docs/gestures.md §6): a one-arm gesture (extend 2, raise 4) one vote short of
  /// min_agreeing_views counts when the views' triangulated skeletons of the vote window show it
  /// (gesture/view_triangulation.hpp) in at least confirm_3d_min_fraction of at least
  /// confirm_3d_min_frames frames. Needs observations that carry calibrated skeletons.
  bool confirm_3d = false;
  /// Which gestures confirm_3d may confirm (YAML `view_fusion.confirm_3d_scope`): one_arm (extend,
  /// raise; oneArmGesture3D) or all (every gesture, on its geometry_3d region as require_3d reads it).
  enum class ConfirmScope { kOneArm, kAll };
  ConfirmScope confirm_3d_scope = ConfirmScope::kOneArm;
  double confirm_3d_min_fraction = 0.5;  ///< (0, 1]
  int confirm_3d_min_frames = 5;         ///< ≥ 1
  double confirm_3d_max_dt_s = 0.034;    ///< views' frames at most this apart form one 3-D frame [s], > 0 (also require_3d's)
  /// 3-D check of every gesture (docs/gestures.md §6): with two or more calibrated views, a gesture
  /// passes only when the vote window has at least require_3d_min_frames triangulated frames and its
  /// design.md §2 geometry holds in at least require_3d_min_fraction of them.
  bool require_3d = true;
  double require_3d_min_fraction = 0.3;  ///< (0, 1]; 0.3 chosen on the tuning sets (docs/gestures.md §6)
  int require_3d_min_frames = 5;         ///< ≥ 1
  /// Odd, 1..31: each triangulated frame is read on the per-keypoint median of it and its neighbours
  /// (this many frames centred on it; gesture::medianSkeleton): a held gesture's single frames are
  /// noisy (the elbow of a triangulated arm moves by centimetres), its median is not. 1: frame by frame.
  int require_3d_median_frames = 5;
  /// The 3-D tests' triangulation takes each view's skeleton as named or mirrored, whichever agrees
  /// with the other views, and mirrors all when the nose lies behind (TriangulationConfig::resolve_sides:
  /// skeleton networks name the sides by the image's, docs/gestures.md §6).
  bool resolve_sides = false;
  /// The regions require_3d tests (YAML `view_fusion.geometry_3d`: design | network_tolerant) and, for
  /// network_tolerant, their numbers (`view_fusion.tolerant_3d.*`, gesture_geometry.hpp); the other
  /// numbers are design.md's and not configurable.
  GestureGeometryNumbers geometry;
  /// [0, 2] s: callers fuse at t_now − fusion_lag_s (the links' delay budget); observations may
  /// arrive this much out of order and the history is kept this much longer. 0: no lag.
  /// Default 0.4 s (since 2026-12-03): the fault matrix's delay budget (0.1 s + up to 0.3 s).
  double fusion_lag_s = 0.4;

  /// \brief Every problem, each naming the key; empty when valid.
  std::vector<std::string> validate() const;
  /// \brief Whether the views' observations should carry their calibrated skeletons (the 3-D tests
  /// use them: confirm_3d or require_3d).
  bool usesCalibratedViews() const { return confirm_3d || require_3d; }
  /// \brief Whether a camera at this distance and elevation from the worker may vote (always with
  /// gate_envelope off; never with an unknown geometry).
  bool inEnvelope(double distance_m, double elevation_deg) const;
};

/// \brief Reads `view_fusion.{min_agreeing_views, max_age_s, gate_envelope, distance_min_m,
/// distance_max_m, elevation_min_deg, elevation_max_deg, vote_window_s, vote_min_fraction, confirm_3d,
/// confirm_3d_scope, confirm_3d_min_fraction, confirm_3d_min_frames, confirm_3d_max_dt_s, require_3d, require_3d_min_fraction,
/// require_3d_min_frames, require_3d_median_frames, resolve_sides, geometry_3d, tolerant_3d.*, fusion_lag_s}` (missing keys: the defaults above
/// unless the reader requires every key).
ViewFusionConfig readViewFusionConfig(common::ConfigReader& reader);

/// \brief One camera's classification of one frame.
struct ViewObservation {
  int view = 0;                 ///< 0 = the leader, 1.. = followers
  double t_s = 0.0;             ///< frame time [s]
  int gesture_id = 0;           ///< the classifier's argmax, 0..max_gesture_id
  double distance_m = -1.0;     ///< camera → worker [m]; < 0 or NaN: unknown
  double elevation_deg = 0.0;   ///< camera above the worker [deg] (NaN: unknown)
  /// The frame's skeleton with the camera's pose (for confirm_3d and require_3d; empty: the view takes
  /// no part in the 3-D tests).
  std::optional<CalibratedSkeleton> calibrated;
};

/// \brief The fused verdict of one frame.
struct FusedGesture {
  int gesture_id = 0;      ///< what goes to the GestureFilter
  int voting_views = 0;    ///< fresh views inside the envelope
  int agreeing_views = 0;  ///< votes for gesture_id (for 0: votes of the best gesture, which fell short)
  int none_views = 0;      ///< fresh views inside the envelope that vote none
  bool confirmed_3d = false;  ///< gesture_id passed with the 3-D confirmation as its last vote
  bool checked_3d = false;    ///< require_3d: the vote's gesture was checked in 3-D (two or more calibrated views)
  bool rejected_3d = false;   ///< require_3d: the vote's gesture failed its 3-D geometry (gesture_id is then 0)
  int frames_3d = 0;          ///< triangulated frames of the vote window the 3-D tests used
};

/// \brief Keeps the newest observation per view and fuses them.
class ViewFusion {
 public:
  /// `views` cameras (ids 0..views−1), gesture ids 0..max_gesture_id. Call validate() on the
  /// config first; an invalid config is clamped to something safe (min_agreeing_views ≥ 1,
  /// fusion_lag_s into [0, 2], not finite: 0).
  ViewFusion(const ViewFusionConfig& config, int views, int max_gesture_id);

  /// Stores `o` in its view's history (in time order). Rejected (false, `reason` set, nothing
  /// changed): unknown view id, t not finite or older than that view's newest stored observation
  /// by more than fusion_lag_s, gesture id outside 0..max_gesture_id.
  bool observe(const ViewObservation& o, std::string* reason = nullptr);
  /// The fused id at t_now from the stored observations: each view's newest observation at or
  /// before t_now + max_age_s must be fresh (t_now − t ≤ max_age_s). With a lag, call it with
  /// t_now − fusion_lag_s.
  FusedGesture fuse(double t_now) const;
  /// Whether a view's geometry lies inside the validated envelope.
  bool inEnvelope(double distance_m, double elevation_deg) const;

  int views() const { return static_cast<int>(history_.size()); }
  const ViewFusionConfig& config() const { return config_; }

 private:
  ViewFusionConfig config_;
  int max_gesture_id_;
  /// Per view: its observations of the last vote_window_s + max_age_s + fusion_lag_s up to its
  /// newest (back()), in time order.
  std::vector<std::deque<ViewObservation>> history_;
  /// View i's newest observation at or before t_now + max_age_s (nullptr: none).
  const ViewObservation* newestAt(std::size_t i, double t_now) const;
  /// The vote of view i at t_now (0: none), `newest` (its newestAt) being fresh and inside the envelope.
  int viewVote(std::size_t i, const ViewObservation& newest, double t_now) const;
  /// The vote window's triangulated frames: one per observation of the view with the most usable
  /// calibrated observations, with every other view's nearest (≤ confirm_3d_max_dt_s); only frames
  /// two or more views took part in.
  std::vector<Skeleton3D> framesIn3D(double t_now) const;
  /// An observation the 3-D tests may use at t_now: calibrated, inside the vote window and the envelope.
  bool usableFor3D(const ViewObservation& o, double t_now) const;
  /// Views with at least one observation usableFor3D at t_now.
  int calibratedViews(double t_now) const;
  /// Whether design.md §2's geometry of gesture g holds in require_3d_min_fraction of the frames, each
  /// read on the median of require_3d_median_frames around it (require_3d).
  bool holdsIn3D(int g, const std::vector<Skeleton3D>& frames) const;
  /// Whether the triangulated frames show gesture g (confirm_3d): a one-arm gesture in
  /// confirm_3d_min_fraction of the frames with a body frame, each read on the median of
  /// require_3d_median_frames around it (oneArmGesture3D, with its upright stance); with scope all a
  /// two-arm gesture on its geometry_3d region read as holdsIn3D reads it (medians), same fraction.
  bool confirmedIn3D(int g, const std::vector<Skeleton3D>& frames) const;
  /// How many of the frames, each read on the median of require_3d_median_frames around it, fall in
  /// gesture g's geometry_3d region.
  std::size_t framesInRegion(int g, const std::vector<Skeleton3D>& frames) const;
};

}  // namespace gesture_formation::gesture

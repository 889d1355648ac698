#pragma once
/// \file
/// \brief Perception measured against the truth in the rendered closed loop (docs/simulation.md
/// §8): one PerceptionRecord per camera frame and UAV (what the real pipeline found beside what
/// the renderer knows: the worker's visible box and projected joints), and their summary — the
/// metrics.json `perception` section: detection rate and keypoint error binned by distance and
/// by camera elevation, identity switches, time per frame.
/// Thread safety: free functions, reentrant.

#include <array>
#include <string>
#include <vector>

namespace gesture_formation::sim {

/// \brief One camera frame of one UAV.
struct PerceptionRecord {
  double t_s = 0.0;
  int uav = 0;                 ///< 0 leader, i follower i
  double distance_m = 0.0;     ///< true camera centre → worker mid-body
  double elevation_deg = 0.0;  ///< of the camera above the worker's mid-body (formation::viewGeometry)
  int truth_box_height_px = 0; ///< height of the worker's visible box (0: not seen at all)
  int visible_pixels = 0;      ///< worker pixels in the image
  bool in_view = false;        ///< truth: the visible box is at least kMinTruthBoxHeightPx tall
  bool detected = false;       ///< the pipeline gave the worker's box this frame
  bool detector_ran = false;
  double iou = 0.0;            ///< detected box vs. the visible box (0 when either is missing)
  int keypoints_compared = 0;  ///< truth-visible keypoints the skeleton reported (c > 0)
  double keypoint_error_px = 0.0;        ///< median over those [px] (NaN when none)
  double keypoint_error_fraction = 0.0;  ///< the same / truth box height (NaN when none)
  int track_id = -1;           ///< the tracker's worker id (−1 none)
  bool identity_started = false;  ///< a new id was started this frame (TrackStep::identity_changed)
  double render_ms = 0.0, detect_ms = 0.0, track_ms = 0.0, skeleton_ms = 0.0;  ///< wall clock
};

/// \brief A frame counts as "worker in view" when the visible box is at least this tall [px]
/// (the synthetic camera's smallest detectable box, CameraSensorConfig::min_box_height_px).
inline constexpr int kMinTruthBoxHeightPx = 12;

/// \brief One bin of the summary.
struct PerceptionBin {
  std::string label;      ///< e.g. "6-9" [m] or "15-30" [deg]
  double lo = 0.0, hi = 0.0;
  int frames = 0;         ///< in view
  int detected = 0;       ///< of those, detected
  double detection_rate = 0.0;            ///< NaN when frames = 0
  double keypoint_error_px_median = 0.0;  ///< median of the frames' medians (NaN when none)
  double keypoint_error_fraction_median = 0.0;
  double iou_median = 0.0;                ///< over detected frames in view (NaN when none)
};

/// \brief The metrics.json `perception` section.
struct PerceptionSummary {
  int frames = 0, frames_in_view = 0, detected_in_view = 0, detected_not_in_view = 0;
  double detection_rate = 0.0;
  double keypoint_error_px_median = 0.0, keypoint_error_fraction_median = 0.0, iou_median = 0.0;
  std::vector<PerceptionBin> by_distance;   ///< <6, 6-9, 9-12, ≥12 m
  std::vector<PerceptionBin> by_elevation;  ///< <15, 15-30, 30-45, ≥45 deg
  int identities = 0;          ///< ids started over all UAVs
  int identity_switches = 0;   ///< ids started after each UAV's first (re-initialisations)
  double render_ms_median = 0.0, detect_ms_median = 0.0, track_ms_median = 0.0, skeleton_ms_median = 0.0;
  double frame_ms_median = 0.0;  ///< render + detect + track + skeleton per frame
};

/// \brief Summarises the records (NaN where a figure has no sample).
PerceptionSummary summarizePerception(const std::vector<PerceptionRecord>& records);
/// \brief The section as JSON (an object, NaN → null), indented by `indent` spaces.
std::string perceptionJson(const PerceptionSummary& s, int indent = 2);
/// \brief perception.csv: one line per record, with a header.
std::string perceptionCsv(const std::vector<PerceptionRecord>& records);

}  // namespace gesture_formation::sim

#pragma once
/// \file
/// \brief Gesture-frame aggregation — the one home of what the leader's GestureCommander nodelet
/// and `gfctl simulate` do with the formation's classifications (docs/gestures.md §4.1):
/// every camera's classification of a frame is an observation stamped with the frame's time;
/// observations are grouped by that stamp — with `merge_window_s` > 0 (cameras that are not
/// synchronised, e.g. onboard) an observation joins the earliest open frame within that window of
/// it that its view has not reported in yet, and the frame takes the latest stamp of its
/// observations (one observation per view per frame: the filter sees frames at the camera rate,
/// not at the rate of all cameras together); a frame is closed once every view has reported it,
/// or `close_after_s` = max(frame_wait_s, view_fusion.fusion_lag_s) after its stamp (a view
/// that did not classify it, an offline follower, a delayed link). A closed frame with at least
/// one accepted observation is fused at its own time (gesture::ViewFusion: the vote, the
/// envelope, the 3-D confirmation) and given to the filter (gesture::GestureFilter); a fired
/// gesture is mapped to its action (gesture::GestureMapping). An observation of a frame that
/// is already closed still votes in the later frames. With view_fusion.min_agreeing_views 1
/// only the leader's camera counts (the paper's pipeline): its classification goes to the
/// filter unchanged and the followers' observations are ignored.
/// Thread safety: not thread-safe; one instance (the leader's).

#include <optional>
#include <string>
#include <vector>

#include "gesture_formation/gesture/gesture_filter.hpp"
#include "gesture_formation/gesture/gesture_mapping.hpp"
#include "gesture_formation/gesture/view_fusion.hpp"

namespace gesture_formation::gesture {

/// \brief One closed frame: what the vote fused and what the filter made of it.
struct GestureFrame {
  double t_s = 0.0;              ///< the frame's stamp (also the filter's time)
  int reported = 0;              ///< observations received for it (accepted or not)
  FusedGesture fused;            ///< the fused id and its vote
  GestureFilterOutput filter;    ///< the filter's output; filter.fired: a command
  /// When the filter fired: the gesture's action (null: unmapped id).
  const GestureAction* action = nullptr;
};

/// \brief See the file comment.
class GestureFrames {
 public:
  /// \param uav_count cameras of the formation (leader + followers), ≥ 1.
  /// \param frame_wait_s how long after its stamp a frame waits for missing views, ≥ 0.
  /// \param merge_window_s 0: a frame is one exact stamp (synchronised cameras: gfctl simulate);
  /// > 0: see the file comment (the GestureCommander's frame_merge_s).
  /// Preconditions: filter.validate() and fusion.validate() are empty.
  GestureFrames(const GestureFilterConfig& filter, const ViewFusionConfig& fusion, GestureMapping mapping,
                int uav_count, double frame_wait_s, double merge_window_s = 0.0);

  /// \brief Takes one camera's observation (o.view = the UAV index). Returns the frames it
  /// completed (every view reported), in time order; `accepted` / `reason` say whether the
  /// vote took it and why not. A follower's observation is ignored (nothing returned, not
  /// accepted) when only the leader's camera counts.
  std::vector<GestureFrame> observe(const ViewObservation& o, bool* accepted = nullptr, std::string* reason = nullptr);

  /// \brief Closes every pending frame stamped at or before t_s − closeAfterS(), in time order.
  std::vector<GestureFrame> closeDue(double t_now_s);

  /// \brief A new leader's frames: the filter waits for the gesture in progress (if any) to be
  /// released before it fires (GestureFilter::awaitRelease) — its predecessor may already have
  /// fired for that performance, and its parameters, which the new leader took over, hold that
  /// command. Call right after constructing the frames of a take-over.
  void awaitRelease() { filter_.awaitRelease(); }

  /// Cameras that vote: uav_count, or 1 with min_agreeing_views ≤ 1.
  int views() const { return views_; }
  /// max(frame_wait_s, fusion_lag_s when several views vote).
  double closeAfterS() const { return close_after_s_; }
  const GestureMapping& mapping() const { return mapping_; }

 private:
  struct Pending {
    double t_s = 0.0;  ///< its stamp (merging: the latest of its observations)
    int reported = 0;
    bool accepted = false;
    int own_id = 0;  ///< the leader's classification (single-camera mode)
    std::vector<bool> seen;      ///< views that reported in it (merging)
    std::vector<double> view_t;  ///< … and their observations' stamps (a duplicated copy is not counted again)
  };
  /// Counts `o` (accepted by the vote: `ok`) in the open frame it belongs to, opened if none;
  /// pending_ stays in stamp order. Returns that frame.
  const Pending& addToFrame(const ViewObservation& o, bool ok);
  std::vector<GestureFrame> closeUpTo(double t_s);
  GestureFrame process(const Pending& p);

  GestureFilter filter_;
  ViewFusion fusion_;
  GestureMapping mapping_;
  int views_ = 1;
  double close_after_s_ = 0.0;
  double merge_window_s_ = 0.0;
  std::vector<Pending> pending_;  ///< open frames in stamp order
  double last_closed_s_ = -1e300;
  double last_filtered_s_ = -1e300;  ///< the filter's time never goes back (merged stamps may overlap)
};

}  // namespace gesture_formation::gesture

#pragma once
/// \file
/// \brief `ScaledTracker`: an OpenCV visual tracker (KCF or CSRT) run on a down-scaled copy of the
/// frame, so that its cost does not grow with the person's box (docs/perception.md, "Tracker cost").
///
/// KCF and CSRT work on a window of about 2.5× the box around it: their cost grows with the box's
/// area (KCF ~2 ms on a 35 × 83 px pedestrian, 32–36 ms on a person a third of a 640 × 480 frame
/// tall). When the box given to `init` is longer than `max_side_px` on either side, every frame is
/// shrunk (INTER_AREA, the whole frame, so that the tracker's coordinates stay fixed) by the integer
/// factor n = ⌈max(w, h) / max_side_px⌉ (s = 1/n: the box then measures between max_side_px / 2 and
/// max_side_px; an integer factor takes INTER_AREA's fast path) before the tracker sees it, and the
/// boxes are mapped back (box_frame = box_scaled / s). The scale is chosen at `init` and kept until
/// the next `init`.
/// Boxes no longer than `max_side_px` are tracked at full resolution, exactly as before.
/// Cost per update: the tracker on a box of at most `max_side_px` plus one resize of the frame.
/// Thread safety: not reentrant (one per WorkerTracker).

#include <opencv2/core.hpp>
#include <opencv2/tracking.hpp>

namespace gesture_formation::perception {

/// Visual tracker used between detections.
enum class TrackerKind { kKcf, kCsrt };

class ScaledTracker {
 public:
  /// \param max_side_px longest box side [px] the tracker works on; 0: always full resolution.
  ScaledTracker(TrackerKind kind, float max_side_px) : kind_(kind), max_side_px_(max_side_px) {}

  /// \brief Starts tracking `box_px` (frame pixels) in `frame`. False when OpenCV refuses (the
  /// tracker is then empty and `update` fails).
  bool init(const cv::Mat& frame, const cv::Rect& box_px);
  /// \brief The box in `frame` (frame pixels); false when the tracker lost it or none is running.
  bool update(const cv::Mat& frame, cv::Rect2f& box_px);
  void reset() { tracker_.reset(); }
  bool active() const { return !tracker_.empty(); }
  /// Scale of the frames the tracker sees (1: full resolution).
  double scale() const { return scale_; }

 private:
  /// `frame` at scale_ (a view of `frame` itself when scale_ is 1).
  const cv::Mat& scaled(const cv::Mat& frame);

  TrackerKind kind_;
  float max_side_px_;
  double scale_ = 1.0;
  cv::Ptr<cv::Tracker> tracker_;
  cv::Mat small_;  ///< reused buffer of the down-scaled frame
  cv::Mat view_;
};

}  // namespace gesture_formation::perception

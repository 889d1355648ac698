#pragma once
/// \file
/// \brief `WorkerTracker`: detector–tracker alternation that follows ONE person (the worker)
/// and keeps its identity when several people are visible (docs/design.md §2).
///
/// Per frame: if a track exists, the visual tracker (OpenCV contrib KCF or CSRT) predicts
/// the box. The detector runs when (a) no track exists, (b) `detect_every_k` frames have
/// passed since the last detection, or (c) the tracker reports failure. On a detection
/// frame the worker is associated with a detection: the one with the highest IoU with the
/// current box if ≥ `associate_min_iou`, else the nearest centre within
/// `associate_gate` · max(w, h) of the current box. The associated detection re-initialises
/// the tracker (it fixes the KCF scale and removes drift; a tracker box whose IoU with it is
/// < `drift_iou` is counted as drift). Identity never jumps to another person while the
/// current one is associated. If no detection is associated the tracker box is kept for up
/// to `max_missed_detections` detection rounds, then the track is lost; after a loss the
/// nearest detection within `reacquire_gate` · max(w, h) of the last box keeps the id during
/// `reacquire_frames` frames; after that the best-scoring person starts a new id (unless the
/// operator's choice holds, below).
///
/// While a track exists, the detector runs on a square window around the worker
/// (`roi_scale` · max(w, h), at least `roi_min_side_px`, shifted inside the frame) instead
/// of the whole frame: a 60–120 px worker then reaches the network at ~full resolution
/// rather than shrunk 2.5× by letterboxing a 640×480 frame into 256×256. If that window
/// holds nobody, the whole frame is searched in the same step.
///
/// Identity by appearance (`appearance`, perception/appearance.hpp): once the worker's colour model
/// is established, a detection that does not look like the worker is never associated with it nor
/// re-acquired as it, and a tracker box that stops looking like the worker counts as a tracker
/// failure (the tracker slid onto someone crossing in front). A detection whose feet are not where
/// the worker's are (`associate_max_foot_shift`) is not associated either: a person passing in front
/// or behind stands on another image row, and a box merging the worker with them reaches down to
/// the nearer one's feet. After a loss the worker is found
/// again by appearance anywhere in the frame (same id). When the operator chose the worker
/// (`selectWorker`), the tracker does not start a new identity by itself: without the chosen person
/// it reports nobody — but re-acquisition after a loss is by position or colour alone, so a
/// look-alike can be taken under the lock (docs/perception.md, Known limits).

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/tracking.hpp>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/perception/appearance.hpp"
#include "gesture_formation/perception/person_detector.hpp"
#include "gesture_formation/perception/scaled_tracker.hpp"

namespace gesture_formation::common {
template <class Config>
struct FieldTable;
}  // namespace gesture_formation::common

namespace gesture_formation::perception {

common::Result<TrackerKind> parseTrackerKind(const std::string& text);
std::string toString(TrackerKind kind);

/// Smallest non-zero `WorkerTrackerConfig::track_max_side_px` [px]: below it the trackers' features
/// (KCF's 4-px cells, CSRT's HOG) have too few cells on the person.
constexpr float kMinTrackSidePx = 16.0f;

/// \brief Configuration of `WorkerTracker` (defaults: docs/perception.md measurements).
struct WorkerTrackerConfig {
  TrackerKind tracker = TrackerKind::kKcf;  ///< KCF: ~1–3 ms on a worker-sized box; CSRT ~10×
  /// The visual tracker works on the frame shrunk so that the box's longer side is at most this
  /// [px] (ScaledTracker), so its cost does not grow with a close worker's box; 0: full
  /// resolution (cost grows with the box). 0 or [16, 4096].
  float track_max_side_px = 96.0f;
  int detect_every_k = 5;             ///< run the detector at least every k frames, ≥ 1
  float min_detection_score = 0.25f;  ///< detections below are ignored, [0, 1)
  float associate_min_iou = 0.2f;     ///< IoU to keep the identity, (0, 1]
  float associate_gate = 1.0f;        ///< centre distance gate / max(w, h) of the current box, > 0
  /// A detection whose bottom edge lies further than this × the worker's height (at its last
  /// detection) from the worker's feet (the tracked box's centre + half that height) is not
  /// associated with the worker: someone in front of or behind him stands on another image row, and
  /// a box merging him with someone in front reaches down to that person's feet. After a loss the
  /// allowance grows with the frames since, to 4× at reacquire_frames (docs/perception.md
  /// "Identity by appearance"); [0, 10], 0 disables.
  float associate_max_foot_shift = 0.10f;
  float drift_iou = 0.5f;             ///< tracker-vs-detection IoU below this counts as drift, (0, 1]
  int max_missed_detections = 2;      ///< detection rounds without the worker before the track is lost, ≥ 0
  int reacquire_frames = 30;          ///< frames after a loss during which the old id can be reacquired, ≥ 0
  float reacquire_gate = 2.0f;        ///< centre gate / max(w, h) of the last box when reacquiring, > 0
  float min_box_px = 8.0f;            ///< tracker boxes smaller than this (w or h) [px] are failures, ≥ 1
  bool roi_detection = true;          ///< detect in a window around the worker while tracking
  float roi_scale = 2.5f;             ///< window side / max(w, h) of the worker box, ≥ 1
  float roi_min_side_px = 256.0f;     ///< smallest window side [px], ≥ 32 (256 = multipose input)
  AppearanceConfig appearance;        ///< keys tracker.appearance.*

  /// \brief Every problem, each naming the key (`tracker.*`); empty when valid.
  std::vector<std::string> validate() const;
};

/// \brief WorkerTrackerConfig's numbers (keys `tracker.*`) with their ranges: the only place they
/// are written, used by validate() and by the Perception nodelet's parameters.
const common::FieldTable<WorkerTrackerConfig>& workerTrackerFields();

/// \brief Where this frame's box came from.
enum class BoxSource { kNone, kDetector, kTracker };
std::string toString(BoxSource source);

/// \brief Result of one frame.
struct TrackStep {
  bool found = false;            ///< the worker's box is valid this frame
  int id = -1;                   ///< worker identity (increments when a new person is chosen), −1 none
  cv::Rect2f box_px;             ///< worker box in the frame's pixels (clipped to the image)
  BoxSource source = BoxSource::kNone;
  bool detector_ran = false;     ///< the detector ran this frame
  bool roi_used = false;         ///< the detector ran on `roi_px` (else or also on the whole frame)
  cv::Rect roi_px;               ///< detection window of this frame when roi_used
  bool tracker_failed = false;   ///< the visual tracker reported failure this frame
  bool drift = false;            ///< re-initialised because the tracker drifted from the detection
  bool identity_changed = false; ///< a new id was started this frame
  bool stream_reset = false;     ///< the image size changed: the track restarted (a gesture window must not span it)
  std::vector<Detection> detections;  ///< all detections of this frame (empty if none ran)
  int worker_detection = -1;     ///< index in `detections` of the worker, −1 none
  double similarity = -1.0;      ///< appearance similarity of the worker's box, −1 not computed
  int appearance_rejected = 0;   ///< detections near the worker refused for their appearance this frame
  bool reidentified = false;     ///< the lost worker was found again by appearance (same id)
  double detect_ms = 0.0;        ///< detector wall time this frame [ms]
  double track_ms = 0.0;         ///< tracker update + init wall time this frame [ms]
};

/// \brief Running counters (for logs and tests).
struct TrackCounters {
  int frames = 0, detections_run = 0, tracker_failures = 0, drifts = 0, identities = 0, lost = 0;
  int appearance_rejections = 0;  ///< detections refused for their appearance
  int appearance_tracker_failures = 0;  ///< tracker boxes refused for their appearance
  int reidentifications = 0;      ///< losses ended by finding the worker again by appearance
};

/// \brief Detector–tracker alternation. Thread safety: not reentrant.
class WorkerTracker {
 public:
  /// Takes ownership of `detector`; fails with the first config problem or a null detector.
  static common::Result<std::unique_ptr<WorkerTracker>> create(const WorkerTrackerConfig& config,
                                                               std::unique_ptr<PersonDetector> detector);

  /// \brief Processes the next frame (8-bit BGR, same size for the whole sequence). A bad
  /// frame fails with the reason and leaves the track unchanged.
  common::Result<TrackStep> step(const cv::Mat& frame_bgr);

  /// Forgets the track (next frame detects and starts a new id).
  void reset();

  /// \brief Tells the tracker where the worker is (e.g. an operator's click, or a hand
  /// label in tests): forgets the current track; the next detection nearest to `box_px`
  /// (within `reacquire_gate` · max(w, h)) becomes the worker with a new id.
  void setWorkerHint(const cv::Rect2f& box_px);

  /// \brief The operator's choice: the person of the last detection round whose box contains
  /// `point_px` becomes the worker with a new id — its track starts at once on that round's frame —
  /// and the tracker is locked to that person (it does not start another identity by itself;
  /// `unlock()` ends that). Fails, changing nothing, when no detection of the last round contains
  /// the point, or more than one does (people overlapping: choose by candidate index).
  common::Result<cv::Rect2f> selectWorker(const cv::Point2f& point_px);
  /// \brief The operator's choice by candidate index (into `lastDetections()`); fails, changing
  /// nothing, when out of range.
  common::Result<cv::Rect2f> selectCandidate(int index);
  /// \brief Ends the operator's lock: after a loss the best-scoring person may become the worker.
  void unlock() { locked_ = false; }
  bool locked() const { return locked_; }
  /// The people of the last detection round (the candidates the operator can choose from).
  const std::vector<Detection>& lastDetections() const { return last_detections_; }
  const AppearanceModel& appearance() const { return appearance_; }

  const TrackCounters& counters() const { return counters_; }
  const WorkerTrackerConfig& config() const { return config_; }
  PersonDetector& detector() { return *detector_; }

 private:
  WorkerTracker(WorkerTrackerConfig config, std::unique_ptr<PersonDetector> detector);
  bool initTracker(const cv::Mat& frame, const cv::Rect2f& box);
  /// Detections in `window` of `frame`, boxes in frame pixels.
  common::Result<std::vector<Detection>> detectIn(const cv::Mat& frame, const cv::Rect& window);
  /// Which of the last round's detections may be the worker by appearance (1) — all when the model
  /// is not established.
  std::vector<char> lookAlikes() const;
  /// `allowed` without the detections whose bottom edge is further than associate_max_foot_shift ×
  /// `allowance` × the worker's detected height from the worker's feet (ref's centre + half that
  /// height): those do not stand where the worker stands.
  std::vector<char> standingAt(const cv::Rect2f& ref, const std::vector<Detection>& dets, std::vector<char> allowed,
                               float allowance) const;
  /// The appearance descriptor of the last round's detection `i` (empty with appearance off).
  const cv::Mat& descriptor(int i) const { return round_descriptors_[static_cast<std::size_t>(i)]; }
  /// Associates this round's detections with the live track; true when the track was lost now.
  bool associate(const cv::Mat& frame, const cv::Rect2f& predicted, bool have_pred, TrackStep& out);
  /// Starts or resumes a track from this round's detections when none is live.
  void acquire(const cv::Mat& frame, bool lost_now, TrackStep& out);
  /// Takes detection `idx` as the worker's box (tracker re-initialised).
  void take(const cv::Mat& frame, int idx, TrackStep& out);

  WorkerTrackerConfig config_;
  std::unique_ptr<PersonDetector> detector_;
  ScaledTracker tracker_;
  bool tracking_ = false;        ///< a live track exists
  cv::Rect2f box_;               ///< current (or last) worker box
  float detected_height_ = 0.0f; ///< the worker's box height at its last detection [px] (0: none yet)
  int id_ = -1;                  ///< current (or last) id
  int next_id_ = 0;
  int frames_since_detection_ = 0;
  int missed_detections_ = 0;
  int frames_since_lost_ = -1;   ///< −1: never lost / no previous box
  bool hint_pending_ = false;    ///< setWorkerHint was called and not yet resolved
  bool locked_ = false;          ///< the operator chose the worker: never a new person by itself
  bool announce_new_id_ = false; ///< selectCandidate started a new id: the next step says so
  cv::Mat last_detection_frame_; ///< the frame of last_detections_
  std::vector<cv::Mat> round_descriptors_;  ///< appearance descriptors of last_detections_, in order
  AppearanceModel appearance_;
  std::vector<Detection> last_detections_;
  cv::Size frame_size_;
  TrackCounters counters_;
};

}  // namespace gesture_formation::perception

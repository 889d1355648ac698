#include "gesture_formation/perception/worker_tracker.hpp"

#include <algorithm>
#include <cmath>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/perception/dnn_model.hpp"

namespace gesture_formation::perception {

namespace {

double msSince(int64_t t0) { return static_cast<double>(cv::getTickCount() - t0) * 1000.0 / cv::getTickFrequency(); }

cv::Point2f centre(const cv::Rect2f& r) { return {r.x + r.width / 2, r.y + r.height / 2}; }

/// Index of the detection nearest (centre distance) to `ref` within gate · max(w, h), or −1;
/// only detections with allowed[i] (all when `allowed` is empty).
int nearestWithin(const cv::Rect2f& ref, const std::vector<Detection>& dets, float gate,
                  const std::vector<char>& allowed = {}) {
  const float limit = gate * std::max(ref.width, ref.height);
  int best = -1;
  float best_d = limit;
  for (std::size_t i = 0; i < dets.size(); ++i) {
    if (!allowed.empty() && !allowed[i]) continue;
    const float d = static_cast<float>(cv::norm(centre(dets[i].box_px) - centre(ref)));
    if (d <= best_d) {
      best_d = d;
      best = static_cast<int>(i);
    }
  }
  return best;
}

/// Index of the detection overlapping `ref` most (IoU in best_iou), -1 when none overlaps; only
/// detections with allowed[i] (all when `allowed` is empty).
int bestOverlap(const cv::Rect2f& ref, const std::vector<Detection>& dets, float& best_iou,
                const std::vector<char>& allowed = {}) {
  int idx = -1;
  best_iou = 0.0f;
  for (std::size_t i = 0; i < dets.size(); ++i) {
    if (!allowed.empty() && !allowed[i]) continue;
    const float o = iou(ref, dets[i].box_px);
    if (o > best_iou) {
      best_iou = o;
      idx = static_cast<int>(i);
    }
  }
  return idx;
}

/// The square detection window around `ref` (roi_scale · max side, at least roi_min_side_px),
/// shifted inside the frame.
cv::Rect detectionWindow(const cv::Rect2f& ref, const cv::Size& frame, const WorkerTrackerConfig& config) {
  const int side = std::min({std::max(static_cast<int>(std::lround(config.roi_scale * std::max(ref.width, ref.height))),
                                      static_cast<int>(std::lround(config.roi_min_side_px))),
                             frame.width, frame.height});
  const cv::Point2f c = centre(ref);
  const int x = std::clamp(static_cast<int>(std::lround(c.x - side / 2.0f)), 0, frame.width - side);
  const int y = std::clamp(static_cast<int>(std::lround(c.y - side / 2.0f)), 0, frame.height - side);
  return cv::Rect(x, y, side, side);
}

/// True when detection `idx` overlaps no other detection of the round (its colours are its own).
bool clearOfOthers(const std::vector<Detection>& dets, int idx) {
  for (std::size_t i = 0; i < dets.size(); ++i) {
    if (static_cast<int>(i) != idx && iou(dets[i].box_px, dets[static_cast<std::size_t>(idx)].box_px) > 0.0f) return false;
  }
  return true;
}

}  // namespace

common::Result<TrackerKind> parseTrackerKind(const std::string& text) {
  if (text == "kcf") return common::Result<TrackerKind>::ok(TrackerKind::kKcf);
  if (text == "csrt") return common::Result<TrackerKind>::ok(TrackerKind::kCsrt);
  return common::Result<TrackerKind>::fail("tracker must be kcf or csrt, got '" + text + "'");
}

std::string toString(TrackerKind kind) { return kind == TrackerKind::kKcf ? "kcf" : "csrt"; }

std::string toString(BoxSource source) {
  switch (source) {
    case BoxSource::kDetector: return "detector";
    case BoxSource::kTracker: return "tracker";
    case BoxSource::kNone: break;
  }
  return "none";
}

const common::FieldTable<WorkerTrackerConfig>& workerTrackerFields() {
  using C = WorkerTrackerConfig;
  using common::Range;
  static const common::FieldTable<WorkerTrackerConfig> t{{
      {"tracker.detect_every_k", Range::closed(1, 1000), [](C& c) { return &c.detect_every_k; }},
      {"tracker.min_detection_score", Range{0.0, 1.0, true, false}, [](C& c) { return &c.min_detection_score; }},
      {"tracker.associate_min_iou", Range::openClosed(0.0, 1.0), [](C& c) { return &c.associate_min_iou; }},
      {"tracker.associate_gate", Range::positive(), [](C& c) { return &c.associate_gate; }},
      {"tracker.associate_max_foot_shift", Range::closed(0.0, 10.0), [](C& c) { return &c.associate_max_foot_shift; }},
      {"tracker.drift_iou", Range::openClosed(0.0, 1.0), [](C& c) { return &c.drift_iou; }},
      {"tracker.max_missed_detections", Range::nonNegative(), [](C& c) { return &c.max_missed_detections; }},
      {"tracker.reacquire_frames", Range::nonNegative(), [](C& c) { return &c.reacquire_frames; }},
      {"tracker.reacquire_gate", Range::positive(), [](C& c) { return &c.reacquire_gate; }},
      {"tracker.min_box_px", Range::atLeast(1.0), [](C& c) { return &c.min_box_px; }},
      {"tracker.roi_scale", Range::atLeast(1.0), [](C& c) { return &c.roi_scale; }},
      {"tracker.roi_min_side_px", Range::atLeast(32.0), [](C& c) { return &c.roi_min_side_px; }},
      {"tracker.track_max_side_px", Range::closed(0.0, 4096.0), [](C& c) { return &c.track_max_side_px; }},
  }};
  return t;
}

std::vector<std::string> WorkerTrackerConfig::validate() const {
  auto lines = common::problemLines(workerTrackerFields().rangeProblems(*this));
  if (track_max_side_px > 0.0f && track_max_side_px < kMinTrackSidePx) {
    lines.push_back("tracker.track_max_side_px must be 0 (full resolution) or at least " +
                    std::to_string(static_cast<int>(kMinTrackSidePx)) + " px, got " + std::to_string(track_max_side_px));
  }
  for (auto& line : appearance.validate()) lines.push_back(std::move(line));
  return lines;
}

common::Result<std::unique_ptr<WorkerTracker>> WorkerTracker::create(const WorkerTrackerConfig& config,
                                                                     std::unique_ptr<PersonDetector> detector) {
  using R = common::Result<std::unique_ptr<WorkerTracker>>;
  const auto problems = config.validate();
  if (!problems.empty()) return R::fail(problems.front());
  if (!detector) return R::fail("worker tracker: no person detector given");
  return R::ok(std::unique_ptr<WorkerTracker>(new WorkerTracker(config, std::move(detector))));
}

WorkerTracker::WorkerTracker(WorkerTrackerConfig config, std::unique_ptr<PersonDetector> detector)
    : config_(std::move(config)),
      detector_(std::move(detector)),
      tracker_(config_.tracker, config_.track_max_side_px),
      appearance_(config_.appearance) {}

void WorkerTracker::reset() {
  tracker_.reset();
  tracking_ = false;
  id_ = -1;
  frames_since_detection_ = 0;
  missed_detections_ = 0;
  frames_since_lost_ = -1;
  hint_pending_ = false;
  locked_ = false;
  announce_new_id_ = false;
  detected_height_ = 0.0f;
  appearance_.reset();
}

void WorkerTracker::setWorkerHint(const cv::Rect2f& box_px) {
  reset();
  if (!(box_px.width > 0 && box_px.height > 0)) return;
  box_ = box_px;
  hint_pending_ = true;
  frames_since_lost_ = 0;
}

common::Result<cv::Rect2f> WorkerTracker::selectWorker(const cv::Point2f& point_px) {
  int best = -1;
  std::vector<int> containing;
  for (std::size_t i = 0; i < last_detections_.size(); ++i) {
    const cv::Rect2f& b = last_detections_[i].box_px;
    if (!b.contains(point_px)) continue;
    containing.push_back(static_cast<int>(i));
    best = static_cast<int>(i);
  }
  // A point in two people's boxes (one standing behind the other) does not say whom: refused, the
  // operator picks by candidate index (the smallest box, the old rule, is often the farther person).
  if (containing.size() > 1) {
    std::string list;
    for (const int i : containing) list += (list.empty() ? "" : ", ") + std::to_string(i);
    return common::Result<cv::Rect2f>::fail("select worker: the point (" + std::to_string(point_px.x) + ", " +
                                            std::to_string(point_px.y) + ") px lies in the boxes of candidates " + list +
                                            " of the last detection round: choose one by its candidate index in the newest "
                                            "WorkerCandidates");
  }
  if (best < 0) {
    return common::Result<cv::Rect2f>::fail("select worker: no person of the last detection round contains the point (" +
                                            std::to_string(point_px.x) + ", " + std::to_string(point_px.y) + ") px; " +
                                            std::to_string(last_detections_.size()) + " candidate(s)");
  }
  return selectCandidate(best);
}

common::Result<cv::Rect2f> WorkerTracker::selectCandidate(int index) {
  if (index < 0 || index >= static_cast<int>(last_detections_.size())) {
    return common::Result<cv::Rect2f>::fail("select worker: candidate " + std::to_string(index) + " out of range [0, " +
                                            std::to_string(last_detections_.size()) + ")");
  }
  // The chosen person becomes the track at once, on the frame of its detection round — never
  // "whoever is nearest next time", which could be someone else if the chosen one is missed then.
  const cv::Rect2f box = last_detections_[static_cast<std::size_t>(index)].box_px;
  const std::vector<Detection> round = last_detections_;
  const cv::Mat frame = last_detection_frame_;
  const std::vector<cv::Mat> descriptors = round_descriptors_;
  reset();
  id_ = next_id_++;
  ++counters_.identities;
  announce_new_id_ = true;
  locked_ = true;
  box_ = box;
  tracking_ = initTracker(frame, box);
  frames_since_detection_ = 0;
  if (clearOfOthers(round, index)) appearance_.update(descriptors[static_cast<std::size_t>(index)]);
  return common::Result<cv::Rect2f>::ok(box);
}

bool WorkerTracker::initTracker(const cv::Mat& frame, const cv::Rect2f& box) {
  const cv::Rect r(static_cast<int>(std::lround(box.x)), static_cast<int>(std::lround(box.y)),
                   std::max(1, static_cast<int>(std::lround(box.width))), std::max(1, static_cast<int>(std::lround(box.height))));
  return tracker_.init(frame, r);
}

common::Result<std::vector<Detection>> WorkerTracker::detectIn(const cv::Mat& frame, const cv::Rect& window) {
  auto dets = detector_->detect(frame(window));
  if (!dets) return dets;
  for (auto& d : *dets) {
    d.box_px.x += static_cast<float>(window.x);
    d.box_px.y += static_cast<float>(window.y);
    for (auto& k : d.keypoints) {
      if (k.c > 0.0f) {
        k.x += static_cast<float>(window.x);
        k.y += static_cast<float>(window.y);
      }
    }
    d.roi.center_px += cv::Point2f(static_cast<float>(window.x), static_cast<float>(window.y));
  }
  return dets;
}

std::vector<char> WorkerTracker::lookAlikes() const {
  std::vector<char> alike(last_detections_.size(), 1);
  if (!appearance_.established()) return alike;
  for (std::size_t i = 0; i < alike.size(); ++i) {
    alike[i] = appearance_.accepts(descriptor(static_cast<int>(i)), config_.appearance.min_similarity) ? 1 : 0;
  }
  return alike;
}

void WorkerTracker::take(const cv::Mat& frame, int idx, TrackStep& out) {
  const cv::Rect2f det = out.detections[static_cast<std::size_t>(idx)].box_px;
  const int64_t t1 = cv::getTickCount();
  tracking_ = initTracker(frame, det);  // on failure: re-detect next frame; this frame's box stands
  out.track_ms += msSince(t1);
  missed_detections_ = 0;
  box_ = det;
  detected_height_ = det.height;
  out.found = true;
  out.source = BoxSource::kDetector;
  out.worker_detection = idx;
  const cv::Mat d = descriptor(idx);
  out.similarity = appearance_.established() ? appearance_.similarity(d) : -1.0;
  if (clearOfOthers(out.detections, idx)) appearance_.update(d);
}

std::vector<char> WorkerTracker::standingAt(const cv::Rect2f& ref, const std::vector<Detection>& dets, std::vector<char> allowed,
                                            float allowance) const {
  if (config_.associate_max_foot_shift <= 0.0f || detected_height_ <= 0.0f) return allowed;
  // The feet: the box's centre (the visual trackers follow it well) and half the height the detector
  // last gave the worker (a tracker's scale is not trusted: CSRT's grows, KCF's is fixed).
  const float feet = ref.y + 0.5f * ref.height + 0.5f * detected_height_;
  const float tolerance = config_.associate_max_foot_shift * allowance * detected_height_;
  for (std::size_t i = 0; i < allowed.size() && i < dets.size(); ++i) {
    const cv::Rect2f& b = dets[i].box_px;
    if (std::abs(b.y + b.height - feet) > tolerance) allowed[i] = 0;
  }
  return allowed;
}

bool WorkerTracker::associate(const cv::Mat& frame, const cv::Rect2f& predicted, bool have_pred, TrackStep& out) {
  const cv::Rect2f ref = have_pred ? predicted : box_;
  const std::vector<char> alike = lookAlikes();
  const std::vector<char> eligible = standingAt(ref, out.detections, alike, 1.0f);
  float best_iou = 0.0f;
  int idx = bestOverlap(ref, out.detections, best_iou, eligible);
  if (best_iou < config_.associate_min_iou) idx = nearestWithin(ref, out.detections, config_.associate_gate, eligible);
  // Detections the geometry alone would have taken but that do not look like the worker.
  float geo_iou = 0.0f;
  int geo = bestOverlap(ref, out.detections, geo_iou);
  if (geo_iou < config_.associate_min_iou) geo = nearestWithin(ref, out.detections, config_.associate_gate);
  if (geo >= 0 && geo != idx && !alike[static_cast<std::size_t>(geo)]) {
    ++out.appearance_rejected;
    ++counters_.appearance_rejections;
  }
  if (idx >= 0) {
    out.drift = have_pred && iou(predicted, out.detections[static_cast<std::size_t>(idx)].box_px) < config_.drift_iou;
    if (out.drift) ++counters_.drifts;
    take(frame, idx, out);
    return false;
  }
  ++missed_detections_;
  if (have_pred && missed_detections_ <= config_.max_missed_detections) {
    box_ = predicted;
    out.found = true;
    out.source = BoxSource::kTracker;
    return false;
  }
  tracking_ = false;
  tracker_.reset();
  frames_since_lost_ = 0;
  ++counters_.lost;
  return true;
}

void WorkerTracker::acquire(const cv::Mat& frame, bool lost_now, TrackStep& out) {
  // Never in the frame where the track was just lost, so the identity cannot hop to a neighbour
  // that the association rejected. While a hint or a recently lost worker is remembered, only a
  // detection near it (and looking like it) is taken, or one looking like it anywhere; a new
  // person only after that, and never while the operator's choice holds.
  if (tracking_ || out.found || lost_now || out.detections.empty()) {
    if (!tracking_ && !out.found && frames_since_lost_ >= 0) {
      ++frames_since_lost_;
      if (frames_since_lost_ > config_.reacquire_frames) hint_pending_ = false;
    }
    return;
  }
  const bool remembering = (id_ >= 0 || hint_pending_) && frames_since_lost_ >= 0 &&
                           frames_since_lost_ <= config_.reacquire_frames;
  // A worker lost moments ago (a hint is the operator's point, not a person) stands about where he
  // stood: a box on another feet line is someone else or a box merging him with someone in front.
  // The allowance grows with the time since the loss (he may walk), to 4× when the memory ends.
  const float allowance =
      1.0f + 3.0f * static_cast<float>(frames_since_lost_) / static_cast<float>(std::max(1, config_.reacquire_frames));
  const std::vector<char> alike =
      remembering && !hint_pending_ ? standingAt(box_, out.detections, lookAlikes(), allowance) : lookAlikes();
  int idx = remembering ? nearestWithin(box_, out.detections, config_.reacquire_gate, alike) : -1;
  if (idx >= 0 && hint_pending_) {
    id_ = next_id_++;
    out.identity_changed = true;
    ++counters_.identities;
  } else if (idx < 0 && !hint_pending_ && id_ >= 0 && appearance_.established()) {
    double best = config_.appearance.min_similarity;
    for (std::size_t i = 0; i < out.detections.size(); ++i) {
      if (!alike[i]) continue;
      const double s = appearance_.similarity(descriptor(static_cast<int>(i)));
      if (s >= best) {
        best = s;
        idx = static_cast<int>(i);
      }
    }
    if (idx >= 0) {
      out.reidentified = true;
      ++counters_.reidentifications;
    }
  }
  if (idx < 0 && !hint_pending_ && !locked_ && !remembering) {
    idx = 0;  // best score first: a new worker (never while the lost one is remembered)
    id_ = next_id_++;
    out.identity_changed = true;
    ++counters_.identities;
    appearance_.reset();
  }
  if (idx < 0) {
    if (frames_since_lost_ >= 0 && ++frames_since_lost_ > config_.reacquire_frames) hint_pending_ = false;
    return;
  }
  take(frame, idx, out);
  frames_since_lost_ = -1;
  hint_pending_ = false;
}

common::Result<TrackStep> WorkerTracker::step(const cv::Mat& frame) {
  using R = common::Result<TrackStep>;
  const std::string bad = checkBgrImage(frame, "frame");
  if (!bad.empty()) return R::fail("worker tracker: " + bad);
  bool stream_reset = false;
  if (frame_size_ != frame.size()) {
    if (frame_size_.area() > 0) {  // a new stream: the track restarts
      // The operator's choice outlives it (else the next round took the best-scoring person): the
      // locked worker is kept with his colours and his last box scaled to the new size, lost, and
      // found again as after any loss (near that box, or by his colours) — or nobody.
      stream_reset = true;
      const bool locked = locked_ && id_ >= 0;
      const int id = id_;
      const bool announce = announce_new_id_;  // an operator's choice not yet reported
      AppearanceModel appearance = appearance_;
      const float sx = static_cast<float>(frame.cols) / static_cast<float>(frame_size_.width);
      const float sy = static_cast<float>(frame.rows) / static_cast<float>(frame_size_.height);
      const cv::Rect2f scaled(box_.x * sx, box_.y * sy, box_.width * sx, box_.height * sy);
      reset();
      if (locked) {
        locked_ = true;
        id_ = id;
        announce_new_id_ = announce;
        appearance_ = std::move(appearance);
        box_ = scaled;
        frames_since_lost_ = 0;
      }
    }
    frame_size_ = frame.size();
  }
  ++counters_.frames;
  const cv::Rect2f image_rect(0.0f, 0.0f, static_cast<float>(frame.cols), static_cast<float>(frame.rows));
  TrackStep out;
  out.identity_changed = announce_new_id_;  // the operator chose a person since the last frame
  out.stream_reset = stream_reset;
  announce_new_id_ = false;

  // 1. visual tracker prediction; a box that stopped looking like the worker is a failure
  cv::Rect2f predicted;
  bool have_pred = false;
  if (tracking_ && tracker_.active()) {
    const int64_t t0 = cv::getTickCount();
    cv::Rect2f r;
    const bool ok = tracker_.update(frame, r);
    predicted = r & image_rect;
    have_pred = ok && predicted.width >= config_.min_box_px && predicted.height >= config_.min_box_px;
    if (have_pred && appearance_.established()) {
      out.similarity = appearance_.similarity(appearance_.describe(frame, predicted));
      if (out.similarity < config_.appearance.tracker_min_similarity) {
        have_pred = false;
        ++counters_.appearance_tracker_failures;
      }
    }
    out.track_ms += msSince(t0);
    if (!have_pred) {
      out.tracker_failed = true;
      ++counters_.tracker_failures;
    }
  }

  // 2. detection when due, when there is no track, or when the tracker failed
  const bool need_detect = !tracking_ || !have_pred || frames_since_detection_ + 1 >= config_.detect_every_k;
  if (!need_detect) {
    ++frames_since_detection_;
    box_ = predicted;
    out.found = true;
    out.source = BoxSource::kTracker;
    out.id = id_;
    out.box_px = box_;
    return R::ok(out);
  }

  const int64_t t0 = cv::getTickCount();
  const auto keep = [&](const std::vector<Detection>& dets) {
    out.detections.clear();
    for (const auto& d : dets) {
      if (d.score >= config_.min_detection_score && d.box_px.width > 0 && d.box_px.height > 0) out.detections.push_back(d);
    }
  };
  // The window around the worker while tracking, and around its last box while it is remembered
  // after a loss or the operator's choice holds: a small, distant worker is found at ~full
  // resolution there, where the whole-frame search would shrink it below what the network sees.
  const bool remembered = box_.area() > 0.0f && (locked_ || ((id_ >= 0 || hint_pending_) && frames_since_lost_ >= 0 &&
                                                             frames_since_lost_ <= config_.reacquire_frames));
  if ((tracking_ || remembered) && config_.roi_detection) {
    out.roi_px = detectionWindow(have_pred ? predicted : box_, frame.size(), config_);
    out.roi_used = true;
    auto dets = detectIn(frame, out.roi_px);
    if (!dets) return R::fail("worker tracker: " + dets.reason());
    keep(*dets);
  }
  if (out.detections.empty()) {
    auto dets = detector_->detect(frame);
    if (!dets) return R::fail("worker tracker: " + dets.reason());
    keep(*dets);
  }
  out.detect_ms = msSince(t0);
  out.detector_ran = true;
  ++counters_.detections_run;
  frames_since_detection_ = 0;
  last_detections_ = out.detections;
  last_detection_frame_ = frame.clone();  // selectCandidate starts the chosen person's track on it
  round_descriptors_.clear();            // each person's colours, once per round
  for (const Detection& d : out.detections) {
    round_descriptors_.push_back(config_.appearance.enabled != 0 ? appearance_.describe(frame, d.box_px) : cv::Mat());
  }

  // 3. association with the live track, else (re)acquisition
  const bool lost_now = tracking_ && associate(frame, predicted, have_pred, out);
  acquire(frame, lost_now, out);
  if (out.found) {
    out.id = id_;
    out.box_px = box_;
  }
  return R::ok(out);
}

}  // namespace gesture_formation::perception

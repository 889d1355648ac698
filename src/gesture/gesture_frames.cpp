#include "gesture_formation/gesture/gesture_frames.hpp"

#include <algorithm>
#include <utility>

namespace gesture_formation::gesture {

GestureFrames::GestureFrames(const GestureFilterConfig& filter, const ViewFusionConfig& fusion, GestureMapping mapping,
                             int uav_count, double frame_wait_s)
    : filter_(filter),
      fusion_(fusion, fusion.min_agreeing_views > 1 ? std::max(1, uav_count) : 1, filter.max_gesture_id),
      mapping_(std::move(mapping)),
      views_(fusion.min_agreeing_views > 1 ? std::max(1, uav_count) : 1),
      close_after_s_(std::max(frame_wait_s, views_ > 1 ? fusion.fusion_lag_s : 0.0)) {}

std::vector<GestureFrame> GestureFrames::observe(const ViewObservation& o, bool* accepted, std::string* reason) {
  if (accepted != nullptr) *accepted = false;
  if (o.view < 0 || o.view >= views_) {
    if (reason != nullptr) *reason = "view " + std::to_string(o.view) + " does not vote (single camera)";
    return {};
  }
  const bool ok = fusion_.observe(o, reason);
  if (accepted != nullptr) *accepted = ok;
  if (o.t_s <= last_closed_s_) return {};  // its frame is closed: it votes in the next ones
  Pending& p = pending_[o.t_s];
  ++p.reported;
  p.accepted = p.accepted || ok;
  if (ok && o.view == 0) p.own_id = o.gesture_id;
  if (p.reported >= views_) return closeUpTo(o.t_s);
  return {};
}

std::vector<GestureFrame> GestureFrames::closeDue(double t_now_s) { return closeUpTo(t_now_s - close_after_s_); }

std::vector<GestureFrame> GestureFrames::closeUpTo(double t_s) {
  std::vector<GestureFrame> out;
  while (!pending_.empty() && pending_.begin()->first <= t_s) {
    const double t = pending_.begin()->first;
    const Pending p = pending_.begin()->second;
    pending_.erase(pending_.begin());
    last_closed_s_ = t;
    if (p.accepted) out.push_back(process(t, p));
  }
  return out;
}

GestureFrame GestureFrames::process(double t_s, const Pending& p) {
  GestureFrame f;
  f.t_s = t_s;
  f.reported = p.reported;
  if (views_ > 1) {
    f.fused = fusion_.fuse(t_s);
  } else {
    f.fused.gesture_id = p.own_id;
    f.fused.voting_views = f.fused.agreeing_views = 1;
  }
  // Release evidence: as many views see none as a gesture needs to agree (a view lost while the
  // worker holds a gesture leaves the vote short: id 0, but no release); one camera: its own none.
  const bool none_seen = views_ > 1 ? f.fused.none_views >= fusion_.config().min_agreeing_views : p.own_id == kGestureNone;
  f.filter = filter_.update(t_s, f.fused.gesture_id, none_seen);
  if (f.filter.fired) f.action = mapping_.find(f.filter.dominant_id);
  return f;
}

}  // namespace gesture_formation::gesture

#include "gesture_formation/gesture/gesture_frames.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

namespace gesture_formation::gesture {

GestureFrames::GestureFrames(const GestureFilterConfig& filter, const ViewFusionConfig& fusion, GestureMapping mapping,
                             int uav_count, double frame_wait_s, double merge_window_s)
    : filter_(filter),
      fusion_(fusion, fusion.min_agreeing_views > 1 ? std::max(1, uav_count) : 1, filter.max_gesture_id),
      mapping_(std::move(mapping)),
      views_(fusion.min_agreeing_views > 1 ? std::max(1, uav_count) : 1),
      close_after_s_(std::max(frame_wait_s, views_ > 1 ? fusion.fusion_lag_s : 0.0)),
      merge_window_s_(std::max(0.0, merge_window_s)) {}

const GestureFrames::Pending& GestureFrames::addToFrame(const ViewObservation& o, bool ok) {
  const auto view = static_cast<std::size_t>(o.view);
  const auto byStamp = [](const Pending& a, const Pending& b) { return a.t_s < b.t_s; };
  if (merge_window_s_ > 0.0) {  // a copy of an observation already counted (a duplicated datagram)
    for (const Pending& p : pending_) {
      if (p.seen[view] && p.view_t[view] == o.t_s) return p;
    }
  }
  auto it = std::find_if(pending_.begin(), pending_.end(), [&](const Pending& p) {
    return merge_window_s_ > 0.0 ? std::abs(o.t_s - p.t_s) <= merge_window_s_ && !p.seen[view]
                                 : o.t_s == p.t_s;  // exact stamps: every copy counts (as reported)
  });
  if (it == pending_.end()) {  // a new frame, in stamp order
    Pending fresh;
    fresh.t_s = o.t_s;
    fresh.seen.assign(static_cast<std::size_t>(views_), false);
    fresh.view_t.assign(static_cast<std::size_t>(views_), 0.0);
    it = pending_.insert(std::upper_bound(pending_.begin(), pending_.end(), fresh, byStamp), std::move(fresh));
  }
  ++it->reported;
  it->seen[view] = true;
  it->view_t[view] = o.t_s;
  it->accepted = it->accepted || ok;
  if (ok && o.view == 0) it->own_id = o.gesture_id;
  if (o.t_s <= it->t_s) return *it;
  // Merging: the frame takes the latest stamp of its observations and moves to its place in
  // stamp order (frames close, and are filtered, in time order).
  Pending moved = std::move(*it);
  moved.t_s = o.t_s;
  pending_.erase(it);
  return *pending_.insert(std::upper_bound(pending_.begin(), pending_.end(), moved, byStamp), std::move(moved));
}

std::vector<GestureFrame> GestureFrames::observe(const ViewObservation& o, bool* accepted, std::string* reason) {
  if (accepted != nullptr) *accepted = false;
  if (o.view < 0 || o.view >= views_) {
    if (reason != nullptr) *reason = "view " + std::to_string(o.view) + " does not vote (single camera)";
    return {};
  }
  const bool ok = fusion_.observe(o, reason);
  if (accepted != nullptr) *accepted = ok;
  if (o.t_s <= last_closed_s_) return {};  // its frame is closed: it votes in the next ones
  const Pending& p = addToFrame(o, ok);
  if (p.reported >= views_) return closeUpTo(p.t_s);  // it and every earlier frame, in time order
  return {};
}

std::vector<GestureFrame> GestureFrames::closeDue(double t_now_s) { return closeUpTo(t_now_s - close_after_s_); }

std::vector<GestureFrame> GestureFrames::closeUpTo(double t_s) {
  std::vector<GestureFrame> out;
  while (!pending_.empty() && pending_.front().t_s <= t_s) {
    const Pending p = std::move(pending_.front());
    pending_.erase(pending_.begin());
    last_closed_s_ = std::max(last_closed_s_, p.t_s);
    if (p.accepted) out.push_back(process(p));
  }
  return out;
}

GestureFrame GestureFrames::process(const Pending& p) {
  const double t_s = std::max(p.t_s, last_filtered_s_);
  last_filtered_s_ = t_s;
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

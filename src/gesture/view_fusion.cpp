#include "gesture_formation/gesture/view_fusion.hpp"

#include <algorithm>
#include <cmath>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/gesture/gesture_geometry.hpp"

namespace gesture_formation::gesture {

using common::ConfigReader;
using common::Range;

namespace {

/// ViewFusionConfig's numbers: key, range — the only place it is written — and place.
const common::FieldTable<ViewFusionConfig>& fields() {
  using C = ViewFusionConfig;
  static const common::FieldTable<ViewFusionConfig> t{{
      {"view_fusion.min_agreeing_views", Range::closed(1, 16), [](C& c) { return &c.min_agreeing_views; }},
      {"view_fusion.max_age_s", Range::positive(), [](C& c) { return &c.max_age_s; }},
      {"view_fusion.distance_min_m", Range::nonNegative(), [](C& c) { return &c.distance_min_m; }},
      {"view_fusion.distance_max_m", Range::positive(), [](C& c) { return &c.distance_max_m; }},
      {"view_fusion.elevation_min_deg", Range::closed(-90.0, 90.0), [](C& c) { return &c.elevation_min_deg; }},
      {"view_fusion.elevation_max_deg", Range::closed(-90.0, 90.0), [](C& c) { return &c.elevation_max_deg; }},
      {"view_fusion.vote_window_s", Range::closed(0.0, 60.0), [](C& c) { return &c.vote_window_s; }},
      {"view_fusion.vote_min_fraction", Range::openClosed(0.0, 1.0), [](C& c) { return &c.vote_min_fraction; }},
      {"view_fusion.confirm_3d_min_fraction", Range::openClosed(0.0, 1.0), [](C& c) { return &c.confirm_3d_min_fraction; }},
      {"view_fusion.confirm_3d_min_frames", Range::closed(1, 1000), [](C& c) { return &c.confirm_3d_min_frames; }},
      {"view_fusion.confirm_3d_max_dt_s", Range::openClosed(0.0, 1.0), [](C& c) { return &c.confirm_3d_max_dt_s; }},
      {"view_fusion.require_3d_min_fraction", Range::openClosed(0.0, 1.0), [](C& c) { return &c.require_3d_min_fraction; }},
      {"view_fusion.require_3d_min_frames", Range::closed(1, 1000), [](C& c) { return &c.require_3d_min_frames; }},
      {"view_fusion.require_3d_median_frames", Range::closed(1, 31), [](C& c) { return &c.require_3d_median_frames; }},
      {"view_fusion.fusion_lag_s", Range::closed(0.0, 2.0), [](C& c) { return &c.fusion_lag_s; }},
      {"view_fusion.tolerant_3d.palms_max_separation_H", Range::openClosed(0.0, 0.5),
       [](C& c) { return &c.geometry.tolerant.palms_max_separation_H; }},
      {"view_fusion.tolerant_3d.palms_min_height_H", Range::closed(0.0, 1.2), [](C& c) { return &c.geometry.tolerant.palms_min_height_H; }},
      {"view_fusion.tolerant_3d.palms_max_height_H", Range::closed(0.0, 1.2), [](C& c) { return &c.geometry.tolerant.palms_max_height_H; }},
      {"view_fusion.tolerant_3d.tool_max_height_H", Range::closed(0.0, 1.2), [](C& c) { return &c.geometry.tolerant.tool_max_height_H; }},
      {"view_fusion.tolerant_3d.max_midline_offset_H", Range::openClosed(0.0, 0.5),
       [](C& c) { return &c.geometry.tolerant.max_midline_offset_H; }},
      {"view_fusion.tolerant_3d.palms_max_centre_offset_H", Range::openClosed(0.0, 0.5),
       [](C& c) { return &c.geometry.tolerant.palms_max_centre_offset_H; }},
      {"view_fusion.tolerant_3d.palms_forearm_max_deg", Range::closed(0.0, 90.0), [](C& c) { return &c.geometry.tolerant.palms_forearm_max_deg; }},
      {"view_fusion.tolerant_3d.cross_max_midline_offset_H", Range::openClosed(0.0, 0.5),
       [](C& c) { return &c.geometry.tolerant.cross_max_midline_offset_H; }},
      {"view_fusion.tolerant_3d.cross_min_height_H", Range::closed(0.0, 1.2), [](C& c) { return &c.geometry.tolerant.cross_min_height_H; }},
      {"view_fusion.tolerant_3d.cross_max_height_H", Range::closed(0.0, 1.2), [](C& c) { return &c.geometry.tolerant.cross_max_height_H; }},
      {"view_fusion.tolerant_3d.folded_max_height_H", Range::closed(0.0, 1.2), [](C& c) { return &c.geometry.tolerant.folded_max_height_H; }},
      {"view_fusion.tolerant_3d.extend_min_shoulder_wrist_deg", Range::closed(0.0, 180.0),
       [](C& c) { return &c.geometry.tolerant.extend_min_shoulder_wrist_deg; }},
      {"view_fusion.tolerant_3d.extend_max_shoulder_wrist_deg", Range::closed(0.0, 180.0),
       [](C& c) { return &c.geometry.tolerant.extend_max_shoulder_wrist_deg; }},
      {"view_fusion.tolerant_3d.extend_min_horizontal_deg", Range::closed(0.0, 90.0),
       [](C& c) { return &c.geometry.tolerant.extend_min_horizontal_deg; }},
      {"view_fusion.tolerant_3d.extend_min_elbow_deg", Range::closed(90.0, 180.0), [](C& c) { return &c.geometry.tolerant.extend_min_elbow_deg; }},
      {"view_fusion.tolerant_3d.pointing_max_shoulder_wrist_deg", Range::closed(0.0, 90.0),
       [](C& c) { return &c.geometry.tolerant.pointing_max_shoulder_wrist_deg; }},
      {"view_fusion.tolerant_3d.raise_min_shoulder_wrist_deg", Range::closed(90.0, 180.0),
       [](C& c) { return &c.geometry.tolerant.raise_min_shoulder_wrist_deg; }},
      {"view_fusion.tolerant_3d.raise_min_elbow_deg", Range::closed(90.0, 180.0), [](C& c) { return &c.geometry.tolerant.raise_min_elbow_deg; }},
      {"view_fusion.tolerant_3d.reach_max_shoulder_wrist_deg", Range::closed(90.0, 180.0),
       [](C& c) { return &c.geometry.tolerant.reach_max_shoulder_wrist_deg; }},
      {"view_fusion.tolerant_3d.reach_max_elbow_deg", Range::closed(90.0, 180.0), [](C& c) { return &c.geometry.tolerant.reach_max_elbow_deg; }},
      {"view_fusion.tolerant_3d.one_arm_max_trunk_tilt_deg", Range::openClosed(0.0, 90.0),
       [](C& c) { return &c.geometry.tolerant.one_arm_max_trunk_tilt_deg; }},
      {"view_fusion.tolerant_3d.one_arm_max_foot_offset_torso", Range::openClosed(0.0, 5.0),
       [](C& c) { return &c.geometry.tolerant.one_arm_max_foot_offset_torso; }},
  }};
  return t;
}

/// Each field outside its range, then the rules between fields, in table order.
std::vector<common::ConfigError> problems(const ViewFusionConfig& c) {
  std::vector<common::ConfigError> e = fields().rangeProblems(c);
  common::checkRule(e, c.distance_max_m > c.distance_min_m, "view_fusion.distance_max_m", c.distance_max_m,
                    "must exceed view_fusion.distance_min_m " + common::formatDouble(c.distance_min_m));
  common::checkRule(e, c.elevation_max_deg > c.elevation_min_deg, "view_fusion.elevation_max_deg", c.elevation_max_deg,
                    "must exceed view_fusion.elevation_min_deg " + common::formatDouble(c.elevation_min_deg));
  const TolerantGeometryNumbers& t = c.geometry.tolerant;
  const std::string k = "view_fusion.tolerant_3d.";
  common::checkRule(e, t.palms_max_height_H > t.palms_min_height_H, k + "palms_max_height_H", t.palms_max_height_H,
                    "must exceed " + k + "palms_min_height_H " + common::formatDouble(t.palms_min_height_H));
  common::checkRule(e, t.tool_max_height_H <= t.palms_min_height_H, k + "tool_max_height_H", t.tool_max_height_H,
                    "must not exceed " + k + "palms_min_height_H " + common::formatDouble(t.palms_min_height_H));
  common::checkRule(e, t.cross_max_height_H > t.cross_min_height_H, k + "cross_max_height_H", t.cross_max_height_H,
                    "must exceed " + k + "cross_min_height_H " + common::formatDouble(t.cross_min_height_H));
  common::checkRule(e, t.folded_max_height_H <= t.cross_min_height_H, k + "folded_max_height_H", t.folded_max_height_H,
                    "must not exceed " + k + "cross_min_height_H " + common::formatDouble(t.cross_min_height_H));
  common::checkRule(e, t.extend_max_shoulder_wrist_deg > t.extend_min_shoulder_wrist_deg, k + "extend_max_shoulder_wrist_deg",
                    t.extend_max_shoulder_wrist_deg,
                    "must exceed " + k + "extend_min_shoulder_wrist_deg " + common::formatDouble(t.extend_min_shoulder_wrist_deg));
  common::checkRule(e, t.extend_max_shoulder_wrist_deg < 180.0 - t.pointing_max_shoulder_wrist_deg, k + "extend_max_shoulder_wrist_deg",
                    t.extend_max_shoulder_wrist_deg,
                    "must be below 180 - " + k + "pointing_max_shoulder_wrist_deg " + common::formatDouble(t.pointing_max_shoulder_wrist_deg) +
                        " (an arm that high is raise's)");
  common::checkRule(e, t.pointing_max_shoulder_wrist_deg <= std::min(t.extend_min_shoulder_wrist_deg, t.extend_min_horizontal_deg),
                    k + "pointing_max_shoulder_wrist_deg", t.pointing_max_shoulder_wrist_deg,
                    "must not exceed " + k + "extend_min_shoulder_wrist_deg " + common::formatDouble(t.extend_min_shoulder_wrist_deg) +
                        " nor " + k + "extend_min_horizontal_deg " + common::formatDouble(t.extend_min_horizontal_deg));
  common::checkRule(e, t.reach_max_shoulder_wrist_deg <= t.raise_min_shoulder_wrist_deg, k + "reach_max_shoulder_wrist_deg",
                    t.reach_max_shoulder_wrist_deg,
                    "must not exceed " + k + "raise_min_shoulder_wrist_deg " + common::formatDouble(t.raise_min_shoulder_wrist_deg));
  common::checkRule(e, t.reach_max_elbow_deg <= t.raise_min_elbow_deg, k + "reach_max_elbow_deg", t.reach_max_elbow_deg,
                    "must not exceed " + k + "raise_min_elbow_deg " + common::formatDouble(t.raise_min_elbow_deg));
  common::checkRule(e, c.require_3d_median_frames % 2 == 1, "view_fusion.require_3d_median_frames",
                    c.require_3d_median_frames, "must be odd (frames centred on the one read)");
  fields().sortByTableOrder(e);
  return e;
}

/// Frame k of a window of triangulated frames as the 3-D tests read it: the per-keypoint median of the
/// median_frames (odd) frames centred on it, clamped to the window; 1: the frame itself.
Skeleton3D frameOnMedian(const std::vector<Skeleton3D>& frames, std::size_t k, int median_frames) {
  const auto half = static_cast<std::size_t>(std::max(0, (median_frames - 1) / 2));
  return half == 0 ? frames[k] : medianSkeleton(frames, k >= half ? k - half : 0, k + half);
}

}  // namespace

std::vector<std::string> ViewFusionConfig::validate() const { return common::problemLines(problems(*this)); }

ViewFusionConfig readViewFusionConfig(ConfigReader& r) {
  ViewFusionConfig c;
  const std::string k = "view_fusion.";
  r.readBool(k + "gate_envelope", c.gate_envelope);
  r.readBool(k + "confirm_3d", c.confirm_3d);
  std::string scope = c.confirm_3d_scope == ViewFusionConfig::ConfirmScope::kAll ? "all" : "one_arm";
  r.readString(k + "confirm_3d_scope", scope, {"one_arm", "all"});
  c.confirm_3d_scope = scope == "all" ? ViewFusionConfig::ConfirmScope::kAll : ViewFusionConfig::ConfirmScope::kOneArm;
  r.readBool(k + "require_3d", c.require_3d);
  r.readBool(k + "resolve_sides", c.resolve_sides);
  std::string rules = toString(c.geometry.rules);
  r.readString(k + "geometry_3d", rules, {toString(GeometryRules::kDesign), toString(GeometryRules::kNetworkTolerant)});
  c.geometry.rules = rules == toString(GeometryRules::kNetworkTolerant) ? GeometryRules::kNetworkTolerant : GeometryRules::kDesign;
  fields().readFields(r, "", c);
  // The rules between fields, always (a key outside its range kept its default while reading).
  common::addProblems(r, "", problems(c));
  return c;
}

ViewFusion::ViewFusion(const ViewFusionConfig& config, int views, int max_gesture_id)
    : config_(config),
      max_gesture_id_(std::max(1, max_gesture_id)),
      history_(static_cast<std::size_t>(std::max(1, views))) {
  config_.min_agreeing_views = std::max(1, config_.min_agreeing_views);
  config_.fusion_lag_s = std::isfinite(config_.fusion_lag_s) ? std::clamp(config_.fusion_lag_s, 0.0, 2.0) : 0.0;
}

bool ViewFusion::observe(const ViewObservation& o, std::string* reason) {
  const auto fail = [&](const std::string& why) {
    if (reason) *reason = why;
    return false;
  };
  if (o.view < 0 || o.view >= views()) {
    return fail("view " + std::to_string(o.view) + " outside 0.." + std::to_string(views() - 1));
  }
  if (!std::isfinite(o.t_s)) return fail("view " + std::to_string(o.view) + ": t not finite");
  if (o.gesture_id < 0 || o.gesture_id > max_gesture_id_) {
    return fail("view " + std::to_string(o.view) + ": gesture_id " + std::to_string(o.gesture_id) + " outside 0.." +
                std::to_string(max_gesture_id_));
  }
  const auto i = static_cast<std::size_t>(o.view);
  auto& h = history_[i];
  if (!h.empty() && o.t_s < h.back().t_s - config_.fusion_lag_s) {
    return fail("view " + std::to_string(o.view) + ": t " + common::formatDouble(o.t_s) + " older than the stored " +
                common::formatDouble(h.back().t_s) + " by more than fusion_lag_s " +
                common::formatDouble(config_.fusion_lag_s));
  }
  // After every stored observation of the same or an earlier time (arrival order among equals).
  const auto at = std::upper_bound(h.begin(), h.end(), o.t_s,
                                   [](double t, const ViewObservation& stored) { return t < stored.t_s; });
  h.insert(at, o);
  const double keep_s = config_.vote_window_s + config_.max_age_s + config_.fusion_lag_s;
  const double newest_s = h.back().t_s;
  while (!h.empty() && h.front().t_s < newest_s - keep_s) h.pop_front();
  return true;
}

const ViewObservation* ViewFusion::newestAt(std::size_t i, double t_now) const {
  const auto& h = history_[i];
  for (auto it = h.rbegin(); it != h.rend(); ++it) {
    if (it->t_s <= t_now + config_.max_age_s) return &*it;
  }
  return nullptr;
}

int ViewFusion::viewVote(std::size_t i, const ViewObservation& newest, double t_now) const {
  if (!(config_.vote_window_s > 0.0)) return newest.gesture_id;
  std::vector<int> count(static_cast<std::size_t>(max_gesture_id_ + 1), 0);
  int total = 0;
  for (const ViewObservation& o : history_[i]) {
    if (!(o.t_s > t_now - config_.vote_window_s && o.t_s <= t_now + config_.max_age_s)) continue;
    if (!inEnvelope(o.distance_m, o.elevation_deg)) continue;
    ++total;
    ++count[static_cast<std::size_t>(o.gesture_id)];
  }
  int best = 0, best_count = 0;  // the most frequent gesture (≠ none); ties: the lower id
  for (int g = 1; g <= max_gesture_id_; ++g) {
    if (count[static_cast<std::size_t>(g)] > best_count) {
      best = g;
      best_count = count[static_cast<std::size_t>(g)];
    }
  }
  return best_count > 0 && best_count >= config_.vote_min_fraction * total ? best : 0;
}

bool ViewFusionConfig::inEnvelope(double distance_m, double elevation_deg) const {
  if (!gate_envelope) return true;
  if (!(std::isfinite(distance_m) && distance_m >= 0.0 && std::isfinite(elevation_deg))) return false;  // unknown
  return distance_m >= distance_min_m && distance_m <= distance_max_m && elevation_deg >= elevation_min_deg &&
         elevation_deg <= elevation_max_deg;
}

bool ViewFusion::inEnvelope(double distance_m, double elevation_deg) const {
  return config_.inEnvelope(distance_m, elevation_deg);
}

FusedGesture ViewFusion::fuse(double t_now) const {
  FusedGesture out;
  std::vector<int> votes(static_cast<std::size_t>(max_gesture_id_ + 1), 0);
  for (std::size_t i = 0; i < history_.size(); ++i) {
    const ViewObservation* o = newestAt(i, t_now);
    if (o == nullptr || !(t_now - o->t_s <= config_.max_age_s)) continue;
    if (!inEnvelope(o->distance_m, o->elevation_deg)) continue;
    ++out.voting_views;
    ++votes[static_cast<std::size_t>(viewVote(i, *o, t_now))];
  }
  int best = 0, best_votes = 0;
  bool unique = false;
  for (int g = 1; g <= max_gesture_id_; ++g) {
    const int v = votes[static_cast<std::size_t>(g)];
    if (v > best_votes) {
      best = g;
      best_votes = v;
      unique = true;
    } else if (v == best_votes && v > 0) {
      unique = false;
    }
  }
  out.agreeing_views = best_votes;
  out.none_views = votes[0];
  const bool one_short = config_.confirm_3d && unique && best_votes + 1 == config_.min_agreeing_views &&
                         (config_.confirm_3d_scope == ViewFusionConfig::ConfirmScope::kAll || best == kExtendArmSide ||
                          best == kRaiseArmUp);
  const bool passed = best_votes >= config_.min_agreeing_views && unique;
  if (!passed && !one_short) return out;
  // The 3-D frames of the window, triangulated once for both tests.
  const std::vector<Skeleton3D> frames = framesIn3D(t_now);
  out.frames_3d = static_cast<int>(frames.size());
  if (passed) {
    out.gesture_id = best;
  } else if (confirmedIn3D(best, frames)) {
    out.gesture_id = best;
    out.confirmed_3d = true;
  }
  // Two calibrated views in the window make the geometry the judge even when none of their
  // observations pair up in time (frames_3d 0 < require_3d_min_frames: refused) — a missing
  // triangulation is no licence to skip the check.
  if (out.gesture_id != 0 && config_.require_3d && (out.frames_3d > 0 || calibratedViews(t_now) >= 2)) {
    out.checked_3d = true;
    if (out.frames_3d < config_.require_3d_min_frames || !holdsIn3D(best, frames)) {
      out.gesture_id = 0;
      out.confirmed_3d = false;
      out.rejected_3d = true;
    }
  }
  return out;
}

bool ViewFusion::usableFor3D(const ViewObservation& o, double t_now) const {
  return o.calibrated && o.t_s > t_now - config_.vote_window_s && o.t_s <= t_now + config_.max_age_s &&
         inEnvelope(o.distance_m, o.elevation_deg);
}

int ViewFusion::calibratedViews(double t_now) const {
  int n = 0;
  for (const auto& h : history_) {
    n += std::any_of(h.begin(), h.end(), [&](const ViewObservation& o) { return usableFor3D(o, t_now); }) ? 1 : 0;
  }
  return n;
}

std::vector<Skeleton3D> ViewFusion::framesIn3D(double t_now) const {
  // One 3-D frame per observation of the most observed view inside the window and the envelope:
  // with it, every other view's observation nearest in time (≤ confirm_3d_max_dt_s) that carries a
  // calibrated skeleton; triangulated when at least two views take part.
  std::vector<Skeleton3D> out;
  const auto usable = [&](const ViewObservation& o) { return usableFor3D(o, t_now); };
  std::size_t ref = 0, ref_count = 0;
  for (std::size_t i = 0; i < history_.size(); ++i) {
    const auto c = static_cast<std::size_t>(std::count_if(history_[i].begin(), history_[i].end(), usable));
    if (c > ref_count) {
      ref = i;
      ref_count = c;
    }
  }
  if (ref_count == 0) return out;
  TriangulationConfig triangulation;
  triangulation.resolve_sides = config_.resolve_sides;
  std::vector<CalibratedSkeleton> views;
  for (const ViewObservation& o : history_[ref]) {
    if (!usable(o)) continue;
    views.assign(1, *o.calibrated);
    for (std::size_t i = 0; i < history_.size(); ++i) {
      if (i == ref) continue;
      const ViewObservation* nearest = nullptr;
      for (const ViewObservation& p : history_[i]) {
        if (!usable(p) || std::abs(p.t_s - o.t_s) > config_.confirm_3d_max_dt_s) continue;
        if (nearest == nullptr || std::abs(p.t_s - o.t_s) < std::abs(nearest->t_s - o.t_s)) nearest = &p;
      }
      if (nearest != nullptr) views.push_back(*nearest->calibrated);
    }
    if (views.size() >= 2) out.push_back(triangulate(views, triangulation));
  }
  return out;
}

std::size_t ViewFusion::framesInRegion(int g, const std::vector<Skeleton3D>& frames) const {
  std::size_t holds = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const Skeleton3D s = frameOnMedian(frames, k, config_.require_3d_median_frames);
    if (classifyPose3D(s, config_.geometry).gesture_id == g) ++holds;
  }
  return holds;
}

bool ViewFusion::holdsIn3D(int g, const std::vector<Skeleton3D>& frames) const {
  return static_cast<double>(framesInRegion(g, frames)) >=
         config_.require_3d_min_fraction * static_cast<double>(frames.size());
}

bool ViewFusion::confirmedIn3D(int g, const std::vector<Skeleton3D>& frames3d) const {
  // Two-arm gestures (scope all) on their region; one-arm gestures always on oneArmGesture3D, whose
  // upright-stance test keeps a lunge's or a side kick's arm out (the regions have no stance).
  if (config_.confirm_3d_scope == ViewFusionConfig::ConfirmScope::kAll && g != kExtendArmSide && g != kRaiseArmUp) {
    const auto n = static_cast<int>(frames3d.size());
    return n >= config_.confirm_3d_min_frames &&
           static_cast<double>(framesInRegion(g, frames3d)) >= config_.confirm_3d_min_fraction * n;
  }
  int frames = 0, hits = 0;
  for (std::size_t k = 0; k < frames3d.size(); ++k) {
    const Skeleton3D s = frameOnMedian(frames3d, k, config_.require_3d_median_frames);
    if (!bodyFrameOf(s)) continue;
    ++frames;
    if (oneArmGesture3D(s) == g) ++hits;
  }
  return frames >= config_.confirm_3d_min_frames && hits >= config_.confirm_3d_min_fraction * frames;
}

}  // namespace gesture_formation::gesture

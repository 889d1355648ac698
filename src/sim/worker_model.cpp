#include "gesture_formation/sim/worker_model.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

#include <Eigen/Geometry>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/sim/random.hpp"
#include "gesture_formation/common/format_number.hpp"

namespace gesture_formation::sim {

using common::degToRad;
using common::radToDeg;
using common::formatNumber;

const char* toString(RouteLeg::Kind k) {
  switch (k) {
    case RouteLeg::Kind::kWalk: return "walk";
    case RouteLeg::Kind::kClimb: return "climb";
    case RouteLeg::Kind::kDescend: return "descend";
    case RouteLeg::Kind::kWork: return "work";
    case RouteLeg::Kind::kWait: return "wait";
  }
  return "?";
}

gesture::Motion motionOfGesture(int gesture_id) {
  switch (gesture_id) {
    case 1: return gesture::Motion::kCrossArms;
    case 2: return gesture::Motion::kExtendArmSide;
    case 3: return gesture::Motion::kPalmsTogether;
    case 4: return gesture::Motion::kRaiseArmUp;
    default: return gesture::Motion::kIdle;
  }
}

namespace {
bool moving(RouteLeg::Kind k) {
  return k == RouteLeg::Kind::kWalk || k == RouteLeg::Kind::kClimb || k == RouteLeg::Kind::kDescend;
}
}  // namespace

const common::FieldTable<WorkerConfig>& workerConfigFields() {
  using common::Range;
  using C = WorkerConfig;
  static const common::FieldTable<C> t{{
      {"height_m", Range::closed(1.0, 2.3), [](C& c) { return &c.height_m; }},
      {"start_facing_deg", kFacingDegRange, [](C& c) { return &c.start_facing_deg; }},
      {"gesture_hold_min_s", Range::positive(), [](C& c) { return &c.gesture_hold_min_s; }},
      {"gesture_hold_max_s", Range::openClosed(0.0, 30.0), [](C& c) { return &c.gesture_hold_max_s; }},
  }};
  return t;
}

const common::FieldTable<RouteLeg>& routeLegFields() {
  using common::Range;
  static const common::FieldTable<RouteLeg> t{{
      {"speed_mps", Range::openClosed(0.0, 3.0), [](RouteLeg& l) { return &l.speed_mps; }},
      {"duration_s", Range::positive(), [](RouteLeg& l) { return &l.duration_s; }},
  }};
  return t;
}

const common::FieldTable<ScheduledGesture>& scheduledGestureFields() {
  using common::Range;
  static const common::FieldTable<ScheduledGesture> t{{
      {"t_s", Range::nonNegative(), [](ScheduledGesture& g) { return &g.t_s; }},
      {"gesture", Range::closed(1, 4), [](ScheduledGesture& g) { return &g.gesture_id; }},
  }};
  return t;
}

namespace {

/// Appends the range problem of the table field `key` of `c`, if any, as a validate() line.
template <class Config>
void checkField(std::vector<std::string>& e, const common::FieldTable<Config>& table, const Config& c,
                const std::string& prefix, const char* key) {
  for (const auto& p : table.rangeProblems(c)) {
    if (p.key == key) e.push_back(prefix + p.key + " " + p.message);
  }
}

}  // namespace

std::vector<std::string> WorkerConfig::validate(const std::string& prefix) const {
  auto problems = workerConfigFields().rangeProblems(*this);
  common::checkRule(problems, gesture_hold_min_s <= gesture_hold_max_s, "gesture_hold_min_s", gesture_hold_min_s,
                    "must be <= gesture_hold_max_s");
  std::vector<std::string> e = common::problemLines(problems, prefix);
  if (!start_feet_world.allFinite()) e.push_back(prefix + "start must be finite");
  if (route.empty()) e.push_back(prefix + "route must have at least one leg");
  for (std::size_t i = 0; i < route.size(); ++i) {
    const RouteLeg& l = route[i];
    const std::string p = prefix + "route[" + std::to_string(i) + "].";
    if (moving(l.kind)) {
      if (!l.to_feet_world.allFinite()) e.push_back(p + "to must be finite");
      checkField(e, routeLegFields(), l, p, "speed_mps");
    } else {
      checkField(e, routeLegFields(), l, p, "duration_s");
    }
    if (l.facing_deg && !kFacingDegRange.contains(*l.facing_deg)) {
      e.push_back(p + "facing_deg " + common::rangeProblem(kFacingDegRange, *l.facing_deg));
    }
  }
  if (work_motions.empty()) e.push_back(prefix + "work_motions must not be empty");
  for (std::size_t i = 0; i < work_motions.size(); ++i) {
    if (gesture::gestureIdOf(work_motions[i]) != 0) {
      e.push_back(prefix + "work_motions[" + std::to_string(i) + "] must be a non-gesture motion, got " +
                  gesture::toString(work_motions[i]));
    }
  }
  for (const auto& s : synth.validate()) e.push_back(prefix + "synth: " + s);
  // Gestures: ascending, ids 1..4, inside a work/wait leg with room for the longest gesture.
  const double longest = gesture_hold_max_s + 2.0 * 0.9 / synth.tempo_min + 2.0 * synth.lead_max_s;
  double leg_t = 0.0;
  std::vector<std::pair<double, double>> stationary;
  Eigen::Vector3d at = start_feet_world;
  for (const auto& l : route) {
    double d = l.duration_s;
    if (moving(l.kind)) {
      d = (l.to_feet_world - at).norm() / std::max(1e-9, l.speed_mps);
      at = l.to_feet_world;
    } else {
      stationary.emplace_back(leg_t, leg_t + d);
    }
    leg_t += d;
  }
  for (std::size_t i = 0; i < gestures.size(); ++i) {
    const auto& g = gestures[i];
    const std::string p = prefix + "gestures[" + std::to_string(i) + "].";
    for (auto& line : common::problemLines(scheduledGestureFields().rangeProblems(g), p)) e.push_back(std::move(line));
    if (i > 0 && !(g.t_s > gestures[i - 1].t_s)) e.push_back(p + "t_s must increase, got " + formatNumber(g.t_s));
    if (i > 0 && g.t_s - gestures[i - 1].t_s < longest) {
      e.push_back(p + "t_s " + formatNumber(g.t_s) + " is within " + formatNumber(longest) + " s of the previous gesture");
    }
    bool inside = false;
    for (const auto& [a, b] : stationary) inside = inside || (g.t_s >= a && g.t_s + longest <= b);
    if (!inside) {
      e.push_back(p + "t_s " + formatNumber(g.t_s) + " must lie in a work or wait leg with " + formatNumber(longest) +
                  " s left (the worker stands still while gesturing)");
    }
  }
  return e;
}

double WorkerConfig::routeDuration() const {
  double t = 0.0;
  Eigen::Vector3d at = start_feet_world;
  for (const auto& l : route) {
    if (moving(l.kind)) {
      t += (l.to_feet_world - at).norm() / l.speed_mps;
      at = l.to_feet_world;
    } else {
      t += l.duration_s;
    }
  }
  return t;
}

namespace {
gesture::SynthConfig synthFor(gesture::SynthConfig c, double height_m) {
  c.height_min_m = height_m;
  c.height_max_m = height_m;
  return c;
}
gesture::SynthConfig gestureSynthFor(gesture::SynthConfig c, const WorkerConfig& w) {
  c = synthFor(c, w.height_m);
  c.hold_min_s = w.gesture_hold_min_s;
  c.hold_max_s = w.gesture_hold_max_s;
  return c;
}
}  // namespace

WorkerModel::WorkerModel(const WorkerConfig& config, std::uint64_t seed)
    : config_(config),
      synth_(synthFor(config.synth, config.height_m), mixSeed(seed ^ 0x5EED0001ULL)),
      gesture_synth_(gestureSynthFor(config.synth, config), mixSeed(seed ^ 0x5EED0002ULL)) {
  double t = 0.0;
  Eigen::Vector3d at = config_.start_feet_world;
  double heading = degToRad(config_.start_facing_deg);
  for (const auto& l : config_.route) {
    leg_start_s_.push_back(t);
    leg_start_feet_.push_back(at);
    if (l.facing_deg) {
      heading = degToRad(*l.facing_deg);
    } else if (l.kind == RouteLeg::Kind::kWalk) {
      const Eigen::Vector3d d = l.to_feet_world - at;
      if (d.head<2>().norm() > 0.1) heading = std::atan2(d.y(), d.x());
    }
    leg_heading_rad_.push_back(common::wrapAngle(heading));
    if (moving(l.kind)) {
      t += (l.to_feet_world - at).norm() / l.speed_mps;
      at = l.to_feet_world;
    } else {
      t += l.duration_s;
    }
  }
  leg_start_s_.push_back(t);
  leg_start_feet_.push_back(at);
  leg_heading_rad_.push_back(leg_heading_rad_.empty() ? degToRad(config_.start_facing_deg) : leg_heading_rad_.back());
}

void WorkerModel::divert(double t_s, const Eigen::Vector3d& to_feet_world, double speed_mps) {
  Detour d;
  d.t_s = t_s;
  d.from_feet_world = stateAt(t_s).feet_world;
  d.to_feet_world = Eigen::Vector3d(to_feet_world.x(), to_feet_world.y(), d.from_feet_world.z());
  d.speed_mps = speed_mps;
  const Eigen::Vector3d way = d.to_feet_world - d.from_feet_world;
  d.heading_rad = way.head<2>().norm() > 1e-9 ? std::atan2(way.y(), way.x()) : stateAt(t_s).heading_rad;
  detour_.reset();
  detour_ = d;
}

WorkerState WorkerModel::detourStateAt(double t_s) const {
  const Detour& d = *detour_;
  WorkerState s;
  const Eigen::Vector3d way = d.to_feet_world - d.from_feet_world;
  const double len = way.norm();
  const double along = std::min(len, (t_s - d.t_s) * d.speed_mps);
  s.feet_world = len > 1e-9 ? Eigen::Vector3d(d.from_feet_world + way * (along / len)) : d.from_feet_world;
  const bool walking = along < len;
  s.v_world = walking ? Eigen::Vector3d(way * (d.speed_mps / len)) : Eigen::Vector3d::Zero();
  s.kind = walking ? RouteLeg::Kind::kWalk : RouteLeg::Kind::kWait;
  s.heading_rad = d.heading_rad;
  s.leg = static_cast<int>(config_.route.size());  // off the route
  s.p_world = s.feet_world + Eigen::Vector3d(0.0, 0.0, 0.5 * config_.height_m);
  return s;
}

WorkerState WorkerModel::stateAt(double t_s) const {
  if (detour_ && t_s >= detour_->t_s) return detourStateAt(t_s);
  WorkerState s;
  const std::size_t n = config_.route.size();
  std::size_t leg = 0;
  while (leg < n && t_s >= leg_start_s_[leg + 1]) ++leg;
  s.leg = static_cast<int>(leg);
  const Eigen::Vector3d half(0.0, 0.0, 0.5 * config_.height_m);
  if (leg >= n || t_s < 0.0) {
    const std::size_t i = t_s < 0.0 ? 0 : n;
    s.feet_world = leg_start_feet_[i];
    s.p_world = s.feet_world + half;
    s.heading_rad = t_s < 0.0 ? degToRad(config_.start_facing_deg) : leg_heading_rad_[n];
    s.kind = RouteLeg::Kind::kWait;
    return s;
  }
  const RouteLeg& l = config_.route[leg];
  s.kind = l.kind;
  s.heading_rad = leg_heading_rad_[leg];
  if (moving(l.kind)) {
    const Eigen::Vector3d a = leg_start_feet_[leg];
    const Eigen::Vector3d d = l.to_feet_world - a;
    const double len = d.norm();
    const double along = std::min(len, (t_s - leg_start_s_[leg]) * l.speed_mps);
    s.feet_world = len > 0 ? Eigen::Vector3d(a + d * (along / len)) : a;
    s.v_world = len > 0 ? Eigen::Vector3d(d * (l.speed_mps / len)) : Eigen::Vector3d::Zero();
  } else {
    s.feet_world = leg_start_feet_[leg];
  }
  s.p_world = s.feet_world + half;
  return s;
}

gesture::Motion WorkerModel::motionFor(const WorkerState& s) {
  switch (s.kind) {
    case RouteLeg::Kind::kWalk: return gesture::Motion::kWalking;
    case RouteLeg::Kind::kClimb:
    case RouteLeg::Kind::kDescend: return gesture::Motion::kClimbingLadder;
    case RouteLeg::Kind::kWork: {
      const auto m = config_.work_motions[next_work_motion_ % config_.work_motions.size()];
      ++next_work_motion_;
      return m;
    }
    case RouteLeg::Kind::kWait: return gesture::Motion::kIdle;
  }
  return gesture::Motion::kIdle;
}

void WorkerModel::startMotion(double t_s, gesture::Motion motion, const std::vector<Eigen::Vector3d>& cameras,
                              bool is_scheduled, double scheduled_s) {
  const WorkerState s = stateAt(t_s);
  std::vector<gesture::SkeletonSynthesizer::View> views;
  for (const Eigen::Vector3d& camera_world : cameras) {
    const Eigen::Vector3d diff = camera_world - s.p_world;
    const formation::ViewGeometry view = formation::viewGeometry(camera_world, s.p_world);
    const double d = std::max(1.5, view.distance_m);
    const double el = view.elevation_deg;
    const double az = radToDeg(common::wrapAngle(std::atan2(diff.y(), diff.x()) - s.heading_rad));
    views.push_back({d, el, az});
  }
  gesture::SkeletonSynthesizer& synth = is_scheduled ? gesture_synth_ : synth_;
  std::vector<gesture::SynthSequence> seqs = synth.generateViewsFrom(motion, views);
  current_ = std::move(seqs.front());
  other_views_.assign(std::make_move_iterator(seqs.begin() + 1), std::make_move_iterator(seqs.end()));
  current_start_s_ = t_s;
  has_current_ = true;
  if (is_scheduled) {
    GestureEpisode ep;
    ep.gesture_id = gesture::gestureIdOf(motion);
    ep.scheduled_s = scheduled_s;
    ep.start_s = t_s + current_.motion_start_s;
    ep.end_s = t_s + current_.motion_end_s;
    episodes_.push_back(ep);
  }
}

gesture::SynthFrame WorkerModel::skeletonAt(double t_s, const Eigen::Vector3d& camera_world) {
  return skeletonsAt(t_s, {camera_world}).front();
}

std::vector<gesture::SynthFrame> WorkerModel::skeletonsAt(double t_s, const std::vector<Eigen::Vector3d>& cameras) {
  const double fps = config_.synth.fps;
  if (next_gesture_ < config_.gestures.size() && t_s >= config_.gestures[next_gesture_].t_s) {
    const auto& g = config_.gestures[next_gesture_++];
    startMotion(t_s, motionOfGesture(g.gesture_id), cameras, true, g.t_s);
  } else if (!has_current_ || t_s - current_start_s_ >= static_cast<double>(current_.frames.size()) / fps ||
             other_views_.size() + 1 != cameras.size()) {
    startMotion(t_s, motionFor(stateAt(t_s)), cameras, false, 0.0);
  }
  const std::size_t k = frameIndex(t_s);
  std::vector<gesture::SynthFrame> out;
  out.reserve(cameras.size());
  out.push_back(current_.frames[k]);
  for (const auto& v : other_views_) out.push_back(v.frames[std::min(k, v.frames.size() - 1)]);
  for (auto& f : out) f.t_s = t_s;
  return out;
}

std::size_t WorkerModel::frameIndex(double t_s) const {
  const auto last = static_cast<long>(current_.frames.size()) - 1;
  return static_cast<std::size_t>(
      std::clamp(static_cast<long>(std::floor((t_s - current_start_s_) * config_.synth.fps + 0.5)), 0L, last));
}

gesture::Body3D WorkerModel::bodyAt(double t_s) const { return current_.bodies.at(frameIndex(t_s)); }

gesture::CalibratedSkeleton WorkerModel::calibrated(std::size_t view, const gesture::Skeleton2D& skeleton,
                                                    const WorkerState& ws) const {
  const gesture::SynthSequence& seq = view == 0 ? current_ : other_views_.at(view - 1);
  // The generator's camera in the body frame (the synthesizer aims at 0.55 of the height), then the world.
  gesture::CalibratedSkeleton c = gesture::cameraAround(seq.distance_m, seq.elevation_deg, seq.azimuth_deg,
                                                        0.55 * seq.height_m, config_.synth.camera);
  const Eigen::Matrix3d R_world_body = Eigen::AngleAxisd(ws.heading_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  c.skeleton = skeleton;
  c.R_world_camera = R_world_body * c.R_world_camera;
  c.p_world_camera = ws.feet_world + R_world_body * c.p_world_camera;
  return c;
}

int WorkerModel::performingAt(double t_s) const {
  for (auto it = episodes_.rbegin(); it != episodes_.rend(); ++it) {
    if (t_s >= it->start_s && t_s <= it->end_s) return it->gesture_id;
  }
  return 0;
}

}  // namespace gesture_formation::sim

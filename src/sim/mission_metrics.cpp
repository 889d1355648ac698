#include "gesture_formation/sim/mission_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <regex>
#include <sstream>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/planning/distance_field.hpp"

namespace gesture_formation::sim {

using common::formatDouble;
using common::radToDeg;
using common::wrapAngle;

namespace {

/// The planner's first failure reason without its numbers (so equal causes group together).
std::string reasonKey(const std::string& reason) {
  std::string first = reason.substr(0, reason.find(';'));
  static const std::regex number(R"([-+]?[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?)");
  first = std::regex_replace(first, number, "#");
  return first.empty() ? "(no reason given)" : first;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const auto idx = static_cast<std::size_t>(std::max(0.0, std::ceil(q * static_cast<double>(v.size())) - 1.0));
  return v[std::min(idx, v.size() - 1)];
}

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// Distance from p to a vertical cylinder (radius r) from the feet up to height h.
double cylinderDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& feet, double r, double h) {
  const double radial = std::max(0.0, (p - feet).head<2>().norm() - r);
  const double dz = p.z() < feet.z() ? feet.z() - p.z() : (p.z() > feet.z() + h ? p.z() - feet.z() - h : 0.0);
  return std::hypot(radial, dz);
}

constexpr double kWorkerCylinderRadiusM = 0.3;  ///< docs/simulation.md §4 collisions

}  // namespace

double ObstacleDistance::operator()(const Eigen::Vector3d& p) const {
  const double d_field = field->clearance(p);
  const double d_extra = extra ? extra(p) : std::numeric_limits<double>::infinity();
  if (solids == nullptr || d_field >= kExactWithinM) return std::min(d_field, d_extra);
  return std::min({solids->distance(p), p.z() - ground_height_m, d_extra});
}

std::string describeCommand(const formation::FormationCommand& c, const std::string& target_text) {
  std::ostringstream os;
  os << target_text << '.' << formation::parameterName(c.parameter) << ' '
     << (c.kind == formation::CommandKind::kSet ? "= " : (c.amount >= 0 ? "+" : "")) << c.amount;
  return os.str();
}

RequestRecord firedGestureRecord(double t_s, int gesture_id, const gesture::GestureMapping& mapping) {
  RequestRecord rec;
  rec.t_s = t_s;
  rec.source = "gesture";
  rec.gesture_id = gesture_id;
  const gesture::GestureAction* action = mapping.find(gesture_id);
  if (action == nullptr) {
    rec.status = "unmapped";
    rec.description = "gesture " + std::to_string(gesture_id) + " (unmapped)";
  } else if (action->kind == gesture::GestureAction::Kind::kEvent) {
    rec.status = "event";
    rec.description = std::string("gesture ") + std::to_string(gesture_id) + " → " + toString(action->event);
  } else {
    const auto cmd = gesture::toCommand(*action, 0);
    rec.status = "lost";
    rec.description = "gesture " + std::to_string(gesture_id) + " → " +
                      describeCommand(cmd, action->parameter_path.substr(0, action->parameter_path.find('.')));
  }
  return rec;
}

// --------------------------------------------------------------------------------------
MetricsAccumulator::MetricsAccumulator(const MissionConfig& config, const ObstacleDistance& obstacles,
                                       std::uint64_t seed)
    : cfg_(config), obstacles_(obstacles), n_(static_cast<int>(config.uavs.size())) {
  const auto n = static_cast<std::size_t>(n_);
  m_.seed = seed;
  m_.min_mutual_distance_m = m_.min_obstacle_distance_m = m_.min_human_distance_m =
      std::numeric_limits<double>::infinity();
  last_status_.assign(n, -1);
  in_obstacle_.assign(n, false);
  in_worker_.assign(n, false);
  pair_collision_.assign(n, std::vector<bool>(n, false));
}

void MetricsAccumulator::sampleSafety(double t_s, const std::vector<Eigen::Vector3d>& ps, const WorkerState& ws) {
  for (int i = 0; i < n_ && i < static_cast<int>(ps.size()); ++i) {
    const auto ui = static_cast<std::size_t>(i);
    const Eigen::Vector3d& p = ps[ui];
    const double r = cfg_.uavs[ui].plant.body_radius_m;
    const double d_o = obstacles_(p);
    if (d_o < m_.min_obstacle_distance_m) {
      m_.min_obstacle_distance_m = d_o;
      m_.min_obstacle_uav = i;
      m_.min_obstacle_t_s = t_s;
    }
    const bool in_obstacle = d_o < r;
    if (in_obstacle && !in_obstacle_[ui]) ++m_.collisions;
    in_obstacle_[ui] = in_obstacle;
    m_.min_human_distance_m = std::min(m_.min_human_distance_m, (p - ws.p_world).norm());
    const bool in_worker = cylinderDistance(p, ws.feet_world, kWorkerCylinderRadiusM, cfg_.worker.height_m) < r;
    if (in_worker && !in_worker_[ui]) ++m_.collisions;
    in_worker_[ui] = in_worker;
    for (int j = i + 1; j < n_ && j < static_cast<int>(ps.size()); ++j) {
      const auto uj = static_cast<std::size_t>(j);
      const double d = (p - ps[uj]).norm();
      m_.min_mutual_distance_m = std::min(m_.min_mutual_distance_m, d);
      const bool hit = d < r + cfg_.uavs[uj].plant.body_radius_m;
      if (hit && !pair_collision_[ui][uj]) ++m_.collisions;
      pair_collision_[ui][uj] = hit;
    }
  }
}

void MetricsAccumulator::sampleTimeline(const TimelineInput& in) {
  TimelineRow row;
  row.t_s = in.t_s;
  row.worker_world = in.worker.p_world;
  row.estimate_world = in.estimate_world;
  row.visible = in.visible;
  row.gesture_true = in.gesture_true;
  row.gesture_class = in.gesture_class;
  row.dominant_ratio = in.dominant_ratio;
  const formation::FormationParams& P = in.params;
  const Eigen::Vector3d& w = in.worker.p_world;
  const formation::UavReference lref = formation::leaderReference(w, in.human_heading_rad, P.leader);
  const int n = std::min(n_, static_cast<int>(in.uavs.size()));
  for (int u = 0; u < n; ++u) {
    const MultirotorState& s = in.uavs[static_cast<std::size_t>(u)];
    // The slot it flies (a leader hand-over moves slots): its references and errors are that slot's;
    // a UAV flying none (silent, or not yet told whose slot to take) has none and no errors.
    const bool no_slot = static_cast<std::size_t>(u) < in.slots.size() && in.slots[static_cast<std::size_t>(u)] < 0;
    const int i = static_cast<std::size_t>(u) < in.slots.size() && !no_slot ? in.slots[static_cast<std::size_t>(u)] : u;
    const formation::UavReference ref =
        i == 0 ? lref
               : formation::followerReference(w, lref.heading_rad, lref.pitch_rad,
                                              P.followers[static_cast<std::size_t>(i - 1)]);
    UavSample us;
    us.p_world = s.p_world;
    const Eigen::Vector3d to_worker = w - s.p_world;
    const formation::ViewGeometry view = formation::viewGeometry(s.p_world, w);
    us.d_t = view.distance_m;
    us.d_ref = P.uav(i).distance_m;
    us.d_o = obstacles_(s.p_world);
    us.phi_deg = radToDeg(std::atan2(to_worker.y(), to_worker.x()));
    us.phi_ref_deg = radToDeg(ref.heading_rad);
    us.elev_deg = view.elevation_deg;
    us.elev_ref_deg = formation::elevationDeg(P, i);
    us.heading_deg = radToDeg(s.heading_rad);
    us.pitch_deg = radToDeg(s.pitch_rad);
    us.speed_mps = s.v_world.norm();
    us.plan_status = last_status_[static_cast<std::size_t>(u)];
    if (no_slot) us.d_ref = us.phi_ref_deg = us.elev_ref_deg = std::numeric_limits<double>::quiet_NaN();
    row.uavs.push_back(us);
    if (!no_slot) {
      dist_sq_ += (us.d_t - us.d_ref) * (us.d_t - us.d_ref);
      const double ae = radToDeg(wrapAngle(common::degToRad(us.phi_deg - us.phi_ref_deg)));
      angle_sq_ += ae * ae;
      ++dist_n_;
    }
    for (int j = u + 1; j < n; ++j) {
      row.mutual_m.push_back((s.p_world - in.uavs[static_cast<std::size_t>(j)].p_world).norm());
    }
  }
  row.acting = in.acting;
  timeline_.push_back(std::move(row));
}

void MetricsAccumulator::cameraFrame(bool visible, const Eigen::Vector3d* estimate_world,
                                     const Eigen::Vector3d& worker_world) {
  ++frames_;
  if (visible) ++visible_frames_;
  if (estimate_world != nullptr) {
    est_sq_ += (*estimate_world - worker_world).squaredNorm();
    ++est_n_;
  }
}

void MetricsAccumulator::plan(int uav, double t_s, std::uint64_t params_version, planning::PlanStatus status,
                              double total_ms, const std::string& reason, int qp_sparse_timeouts) {
  ++m_.plans;
  m_.qp_sparse_timeouts += qp_sparse_timeouts;
  if (status == planning::PlanStatus::kFallbackPrevious) ++m_.plans_fallback_previous;
  if (status == planning::PlanStatus::kFallbackBrake) ++m_.plans_fallback_brake;
  if (status != planning::PlanStatus::kOptimized) ++m_.plan_failure_reasons[reasonKey(reason)];
  plan_ms_.push_back(total_ms);
  if (uav >= 0 && uav < n_) last_status_[static_cast<std::size_t>(uav)] = static_cast<int>(status);
  plan_events_.push_back(PlanEvent{uav, t_s, params_version});
  plan_log_.push_back(PlanRecord{t_s, uav, params_version, status, total_ms, reason});
}

int MetricsAccumulator::lastPlanStatus(int uav) const {
  return uav >= 0 && uav < n_ ? last_status_[static_cast<std::size_t>(uav)] : -1;
}

std::size_t MetricsAccumulator::addRequest(const RequestRecord& record) {
  requests_.push_back(record);
  return requests_.size() - 1;
}

std::optional<std::size_t> MetricsAccumulator::findPending(const std::string& source, double issued_s,
                                                           double tolerance_s) const {
  for (std::size_t i = 0; i < requests_.size(); ++i) {
    const RequestRecord& r = requests_[i];
    if (r.source == source && r.status == "lost" && std::abs(r.t_s - issued_s) <= tolerance_s) return i;
  }
  return std::nullopt;
}

void MetricsAccumulator::requestOutcome(std::size_t index, const std::string& status, double t_s,
                                        std::uint64_t params_version, const std::vector<int>& uavs) {
  RequestRecord& rec = requests_.at(index);
  if (rec.status == "applied") return;  // a copy of an applied command changes nothing
  rec.status = status;
  if (status == formation::toString(formation::CommandStatus::kApplied)) {
    rec.applied_s = t_s;
    rec.params_version = params_version;
    for (const int u : uavs) {
      if (std::find(rec.uavs.begin(), rec.uavs.end(), u) == rec.uavs.end()) rec.uavs.push_back(u);
    }
  }
}

void MetricsAccumulator::commandOutcome(const CommandOutcome& outcome, double tolerance_s) {
  unmatched_.push_back(outcome);
  resolveOutcomes(tolerance_s);
}

void MetricsAccumulator::resolveOutcomes(double tolerance_s) {
  for (auto it = unmatched_.begin(); it != unmatched_.end();) {
    const auto index = findPending(it->source, it->issued_s, tolerance_s);
    if (!index) {
      ++it;
      continue;
    }
    requestOutcome(*index, it->status, it->t_s, it->version, it->uavs);
    it = unmatched_.erase(it);
  }
}

void ParamsVersions::published(std::uint64_t version, const formation::FormationParams& params) {
  if (version > versions_.back().first) versions_.emplace_back(version, params);
}

std::optional<std::uint64_t> ParamsVersions::versionOf(const formation::FormationParams& used) const {
  for (auto it = versions_.rbegin(); it != versions_.rend(); ++it) {
    const formation::FormationParams& p = it->second;
    if (p.uavCount() != used.uavCount()) continue;
    bool same = true;
    for (int i = 0; i < p.uavCount() && same; ++i) {
      const auto &x = p.uav(i), &y = used.uav(i);
      same = x.beta_deg == y.beta_deg && x.gamma_deg == y.gamma_deg && x.distance_m == y.distance_m;
    }
    if (same) return it->first;
  }
  return std::nullopt;
}

MissionOutput MetricsAccumulator::finish(const std::vector<GestureEpisode>& gestures, double sim_time_s,
                                         double wall_time_s) {
  MissionOutput out;
  MissionMetrics& M = m_;
  // Adaptation start: the first replanning of an addressed UAV with the new parameters (the
  // earliest, whatever the order in which the UAVs' plans were fed).
  for (auto& rec : requests_) {
    if (std::isnan(rec.applied_s)) continue;
    for (const PlanEvent& e : plan_events_) {
      if (e.version >= rec.params_version && std::find(rec.uavs.begin(), rec.uavs.end(), e.uav) != rec.uavs.end() &&
          !(e.t_s >= rec.adaptation_start_s)) {
        rec.adaptation_start_s = e.t_s;
      }
    }
  }
  // Gestures: match fired gesture commands to performed gestures.
  out.gestures = gestures;
  std::vector<bool> used(out.gestures.size(), false);
  double latency_sum = 0.0;
  int latency_n = 0;
  for (auto& rec : requests_) {
    if (rec.source != "gesture") continue;
    for (std::size_t e = 0; e < out.gestures.size(); ++e) {
      const GestureEpisode& ep = out.gestures[e];
      if (!used[e] && ep.gesture_id == rec.gesture_id && ep.start_s <= rec.t_s &&
          rec.t_s - ep.start_s <= cfg_.gesture_match_window_s) {
        used[e] = true;
        rec.matched_episode = static_cast<int>(e);
        break;
      }
    }
    if (rec.matched_episode < 0) {
      ++M.false_adaptations;
      continue;
    }
    const GestureEpisode& ep = out.gestures[static_cast<std::size_t>(rec.matched_episode)];
    const double start = std::isnan(rec.adaptation_start_s) ? rec.t_s : rec.adaptation_start_s;
    if (!std::isnan(rec.adaptation_start_s) && rec.adaptation_start_s <= ep.end_s) ++M.gestures_successful;
    latency_sum += start - ep.start_s;
    ++latency_n;
  }
  M.gestures_performed = static_cast<int>(out.gestures.size());
  for (const auto& rec : requests_) {
    if (rec.status == "applied") {
      ++M.requests_applied;
      (rec.source == "operator" ? M.operator_requests_applied : M.gesture_requests_applied)++;
    }
  }
  M.requests_total = static_cast<int>(cfg_.requests.size()) + M.gestures_performed;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  M.gesture_success_rate = M.gestures_performed > 0 ? static_cast<double>(M.gestures_successful) / M.gestures_performed : nan;
  M.gesture_mean_latency_s = latency_n > 0 ? latency_sum / latency_n : nan;
  M.distance_error_rms_m = dist_n_ > 0 ? std::sqrt(dist_sq_ / static_cast<double>(dist_n_)) : nan;
  M.angle_error_rms_deg = dist_n_ > 0 ? std::sqrt(angle_sq_ / static_cast<double>(dist_n_)) : nan;
  M.human_estimate_error_rms_m = est_n_ > 0 ? std::sqrt(est_sq_ / static_cast<double>(est_n_)) : nan;
  M.planning_ms_median = median(plan_ms_);
  M.planning_ms_p99 = percentile(plan_ms_, 0.99);
  M.planning_ms_max = percentile(plan_ms_, 1.0);
  M.visible_fraction = frames_ > 0 ? static_cast<double>(visible_frames_) / static_cast<double>(frames_) : 0.0;
  M.sim_time_s = sim_time_s;
  M.wall_time_s = wall_time_s;
  M.real_time_factor = M.wall_time_s > 0 ? M.sim_time_s / M.wall_time_s : nan;
  out.metrics = M;
  out.timeline = std::move(timeline_);
  out.plans = std::move(plan_log_);
  out.requests = std::move(requests_);
  return out;
}

// --------------------------------------------------------------------------------------
std::string metricsJson(const MissionMetrics& m) {
  std::ostringstream os;
  auto num = [](double v) { return std::isfinite(v) ? formatDouble(v) : std::string("null"); };
  auto unmeasured = [&m](const char* key) {
    return std::find(m.not_measured.begin(), m.not_measured.end(), key) != m.not_measured.end();
  };
  // Diagnostic integers the producer may not observe (MissionMetrics::not_measured).
  auto count = [&unmeasured](const char* key, long v) { return unmeasured(key) ? std::string("null") : std::to_string(v); };
  os << "{\n";
  os << "  \"min_mutual_distance_m\": " << num(m.min_mutual_distance_m) << ",\n";
  os << "  \"min_obstacle_distance_m\": " << num(m.min_obstacle_distance_m) << ",\n";
  os << "  \"min_obstacle_uav\": " << m.min_obstacle_uav << ",\n";
  os << "  \"min_obstacle_t_s\": " << num(m.min_obstacle_t_s) << ",\n";
  os << "  \"min_human_distance_m\": " << num(m.min_human_distance_m) << ",\n";
  os << "  \"collisions\": " << m.collisions << ",\n";
  os << "  \"distance_error_rms_m\": " << num(m.distance_error_rms_m) << ",\n";
  os << "  \"angle_error_rms_deg\": " << num(m.angle_error_rms_deg) << ",\n";
  os << "  \"requests_applied\": " << m.requests_applied << ",\n";
  os << "  \"gesture_success_rate\": " << num(m.gesture_success_rate) << ",\n";
  os << "  \"gesture_mean_latency_s\": " << num(m.gesture_mean_latency_s) << ",\n";
  os << "  \"false_adaptations\": " << m.false_adaptations << ",\n";
  os << "  \"planning_ms_median\": " << num(m.planning_ms_median) << ",\n";
  os << "  \"planning_ms_p99\": " << num(m.planning_ms_p99) << ",\n";
  os << "  \"planning_ms_max\": " << num(m.planning_ms_max) << ",\n";
  os << "  \"human_estimate_error_rms_m\": " << num(m.human_estimate_error_rms_m) << ",\n";
  os << "  \"requests_total\": " << m.requests_total << ",\n";
  os << "  \"operator_requests_applied\": " << m.operator_requests_applied << ",\n";
  os << "  \"gesture_requests_applied\": " << m.gesture_requests_applied << ",\n";
  os << "  \"gestures_performed\": " << m.gestures_performed << ",\n";
  os << "  \"gestures_successful\": " << m.gestures_successful << ",\n";
  os << "  \"plans\": " << m.plans << ",\n";
  os << "  \"plans_fallback_previous\": " << m.plans_fallback_previous << ",\n";
  os << "  \"plans_fallback_brake\": " << m.plans_fallback_brake << ",\n";
  os << "  \"plans_skipped\": " << count("plans_skipped", m.plans_skipped) << ",\n";
  os << "  \"qp_sparse_timeouts\": " << count("qp_sparse_timeouts", m.qp_sparse_timeouts) << ",\n";
  os << "  \"plans_hold\": " << count("plans_hold", m.plans_hold) << ",\n";
  os << "  \"commands_stale\": " << count("commands_stale", m.commands_stale) << ",\n";
  os << "  \"commands_duplicate\": " << count("commands_duplicate", m.commands_duplicate) << ",\n";
  os << "  \"range_outliers\": " << count("range_outliers", m.range_outliers) << ",\n";
  os << "  \"messages_sent\": " << count("messages_sent", m.messages_sent) << ",\n";
  os << "  \"messages_lost\": " << count("messages_lost", m.messages_lost) << ",\n";
  os << "  \"messages_duplicated\": " << count("messages_duplicated", m.messages_duplicated) << ",\n";
  os << "  \"messages_reordered\": " << count("messages_reordered", m.messages_reordered) << ",\n";
  os << "  \"visible_fraction\": " << num(m.visible_fraction) << ",\n";
  os << "  \"sim_time_s\": " << num(m.sim_time_s) << ",\n";
  os << "  \"seed\": " << m.seed << ",\n";
  os << "  \"wall_time_s\": " << num(m.wall_time_s) << ",\n";
  os << "  \"real_time_factor\": " << num(m.real_time_factor) << ",\n";
  if (!m.not_measured.empty()) {
    os << "  \"not_measured_keys\": [";
    for (std::size_t i = 0; i < m.not_measured.size(); ++i) os << (i ? ", " : "") << '"' << m.not_measured[i] << '"';
    os << "],\n";
  }
  if (m.perception) os << "  \"perception\": " << perceptionJson(*m.perception, 2) << ",\n";
  if (m.abort) os << "  \"abort\": " << abortJson(*m.abort, 2) << ",\n";
  if (m.worker_approach) os << "  \"worker_approach\": " << approachJson(*m.worker_approach, 2) << ",\n";
  if (m.site_mapping) os << "  \"site_mapping\": " << siteMappingJson(*m.site_mapping, 2) << ",\n";
  if (m.leadership) os << "  \"leadership\": " << handoverJson(*m.leadership, 2) << ",\n";
  if (m.assistance) os << "  \"assistance\": " << assistanceJson(*m.assistance, 2) << ",\n";
  os << "  \"wall_clock_keys\": [\"planning_ms_median\", \"planning_ms_p99\", \"planning_ms_max\", \"wall_time_s\", \"real_time_factor\"";
  if (m.perception) {
    for (const char* k : {"render_ms_median", "detect_ms_median", "track_ms_median", "skeleton_ms_median", "frame_ms_median"}) {
      os << ", \"perception." << k << '"';
    }
  }
  if (m.site_mapping) os << ", \"site_mapping.depth_ms_median\", \"site_mapping.integrate_ms_median\", \"site_mapping.integrate_ms_p99\"";
  os << "]\n";
  os << "}\n";
  return os.str();
}

namespace {

/// Writes `path` with `body`; false and `error` naming the file when it cannot be opened or written.
bool writeTextFile(const std::string& path, std::string* error, const std::function<void(std::ostream&)>& body) {
  std::ofstream f(path);
  if (!f) {
    if (error) *error = path + ": cannot open for writing";
    return false;
  }
  body(f);
  f.flush();
  if (!f) {
    if (error) *error = path + ": write failed";
    return false;
  }
  return true;
}

/// Free text as one CSV field: commas become ';', line breaks spaces.
std::string csvText(std::string s) {
  std::replace(s.begin(), s.end(), ',', ';');
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}

}  // namespace

bool writeTimelineCsv(const std::string& path, const MissionOutput& out, int uav_count, std::string* error) {
  return writeTextFile(path, error, [&](std::ostream& f) {
    f << "t,worker_x,worker_y,worker_z,est_x,est_y,est_z,visible,gesture_true,gesture_class,dominant_ratio";
    for (int i = 0; i < uav_count; ++i) {
      const std::string u = formation::uavLabel(i) + "_";
      for (const char* c : {"x", "y", "z", "d_t", "d_ref", "d_o", "phi_deg", "phi_ref_deg", "elev_deg", "elev_ref_deg",
                            "heading_deg", "pitch_deg", "speed", "plan_status"}) {
        f << ',' << u << c;
      }
    }
    for (int i = 0; i < uav_count; ++i) {
      for (int j = i + 1; j < uav_count; ++j) f << ",d_m_" << formation::uavLabel(i) << '_' << formation::uavLabel(j);
    }
    // Who acts as leader (docs/safety.md §1.2): last, so that the columns before keep their places.
    const bool acting = !out.timeline.empty() && !out.timeline.front().acting.empty();
    for (int i = 0; acting && i < uav_count; ++i) f << ",acting_" << formation::uavLabel(i);
    f << '\n';
    for (const auto& r : out.timeline) {
      f << formatDouble(r.t_s);
      for (int k = 0; k < 3; ++k) f << ',' << formatDouble(r.worker_world(k));
      for (int k = 0; k < 3; ++k) f << ',' << formatDouble(r.estimate_world(k));
      f << ',' << r.visible << ',' << r.gesture_true << ',' << r.gesture_class << ',' << formatDouble(r.dominant_ratio);
      for (const auto& u : r.uavs) {
        for (int k = 0; k < 3; ++k) f << ',' << formatDouble(u.p_world(k));
        for (double v : {u.d_t, u.d_ref, u.d_o, u.phi_deg, u.phi_ref_deg, u.elev_deg, u.elev_ref_deg, u.heading_deg,
                         u.pitch_deg, u.speed_mps}) {
          f << ',' << formatDouble(v);
        }
        f << ',' << u.plan_status;
      }
      for (double d : r.mutual_m) f << ',' << formatDouble(d);
      for (std::size_t i = 0; acting && i < static_cast<std::size_t>(uav_count); ++i) {
        f << ',' << (i < r.acting.size() ? r.acting[i] : 0);
      }
      f << '\n';
    }
  });
}

bool writeEventsCsv(const std::string& path, const MissionOutput& out, std::string* error) {
  return writeTextFile(path, error, [&](std::ostream& f) {
    f << "t,source,description,status,applied_t,adaptation_start_t,gesture_id,gesture_start_t,gesture_end_t,uavs\n";
    for (const auto& r : out.requests) {
      std::string uavs;
      for (std::size_t i = 0; i < r.uavs.size(); ++i) uavs += (i ? ";" : "") + formation::uavLabel(r.uavs[i]);
      double gs = std::numeric_limits<double>::quiet_NaN(), ge = gs;
      if (r.matched_episode >= 0) {
        gs = out.gestures[static_cast<std::size_t>(r.matched_episode)].start_s;
        ge = out.gestures[static_cast<std::size_t>(r.matched_episode)].end_s;
      }
      f << formatDouble(r.t_s) << ',' << r.source << ',' << csvText(r.description) << ',' << r.status << ',' << formatDouble(r.applied_s)
        << ',' << formatDouble(r.adaptation_start_s) << ',' << r.gesture_id << ',' << formatDouble(gs) << ','
        << formatDouble(ge) << ',' << uavs << '\n';
    }
    // Performed gestures that never fired anything.
    for (std::size_t e = 0; e < out.gestures.size(); ++e) {
      bool matched = false;
      for (const auto& r : out.requests) matched = matched || r.matched_episode == static_cast<int>(e);
      if (!matched) {
        const auto& g = out.gestures[e];
        f << formatDouble(g.start_s) << ",worker,gesture " << g.gesture_id << " not recognised,missed,nan,nan,"
          << g.gesture_id << ',' << formatDouble(g.start_s) << ',' << formatDouble(g.end_s) << ",\n";
      }
    }
  });
}

bool writeModesCsv(const std::string& path, const MissionOutput& out, std::string* error) {
  return writeTextFile(path, error, [&](std::ostream& f) {
    f << "t,uav,mode,reason\n";
    for (const auto& m : out.modes) {
      f << formatDouble(m.t_s) << ',' << formation::uavLabel(m.uav) << ',' << m.mode << ',' << csvText(m.reason) << '\n';
    }
  });
}

bool writePlansCsv(const std::string& path, const MissionOutput& out, std::string* error) {
  return writeTextFile(path, error, [&](std::ostream& f) {
    f << "t,uav,status,params_version,planning_ms,reason\n";
    for (const auto& p : out.plans) {
      f << formatDouble(p.t_s) << ',' << formation::uavLabel(p.uav) << ',' << planning::toString(p.status) << ','
        << p.params_version << ',' << formatDouble(p.planning_ms) << ',' << csvText(p.reason) << '\n';
    }
  });
}

bool writeVotesCsv(const std::string& path, const MissionOutput& out, int uav_count, std::string* error) {
  return writeTextFile(path, error, [&](std::ostream& f) {
    f << "t,leader";
    for (int i = 0; i < uav_count; ++i) f << ",id_" << formation::uavLabel(i);
    f << ",fused_id,voting_views,agreeing_views,confirmed_3d,checked_3d,rejected_3d,frames_3d,dominant_id,dominant_ratio,fired\n";
    for (const VoteRecord& v : out.votes) {
      f << formatDouble(v.t_s) << ',' << formation::uavLabel(v.leader);
      for (int i = 0; i < uav_count; ++i) {
        f << ',' << (static_cast<std::size_t>(i) < v.view_ids.size() ? v.view_ids[static_cast<std::size_t>(i)] : -1);
      }
      const gesture::FusedGesture& g = v.fused;
      f << ',' << g.gesture_id << ',' << g.voting_views << ',' << g.agreeing_views << ',' << g.confirmed_3d << ','
        << g.checked_3d << ',' << g.rejected_3d << ',' << g.frames_3d << ',' << v.dominant_id << ','
        << formatDouble(v.dominant_ratio) << ',' << v.fired << '\n';
    }
  });
}

bool writeMissionFiles(const std::string& dir, const MissionOutput& out, int uav_count, bool with_modes,
                       std::string* error) {
  if (!writeTimelineCsv(dir + "/timeline.csv", out, uav_count, error) || !writeEventsCsv(dir + "/events.csv", out, error) ||
      (with_modes && !writeModesCsv(dir + "/modes.csv", out, error)) || !writePlansCsv(dir + "/plans.csv", out, error)) {
    return false;
  }
  if (!out.perception.empty() && !writeTextFile(dir + "/perception.csv", error, [&](std::ostream& f) {
        f << perceptionCsv(out.perception);
      })) {
    return false;
  }
  if (!out.votes.empty() && !writeVotesCsv(dir + "/votes.csv", out, uav_count, error)) return false;
  const std::string tmp = dir + "/metrics.json.tmp", path = dir + "/metrics.json";
  {
    std::ofstream f(tmp);
    f << metricsJson(out.metrics);
    if (!f.good()) {
      if (error) *error = tmp + ": write failed";
      return false;
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    if (error) *error = path + ": rename from " + tmp + " failed";
    return false;
  }
  return true;
}

std::vector<OperatorSchedule::Due> OperatorSchedule::due(double t_s) {
  std::vector<Due> out;
  while (next_ < requests_.size() && requests_[next_].t_s <= t_s + 1e-9) {
    const OperatorRequest& q = requests_[next_++];
    Due d;
    d.command.id = {id_source_, next_};
    d.command.source = formation::CommandSource::kOperator;
    d.command.target = q.target;
    d.command.parameter = q.parameter;
    d.command.kind = q.kind;
    d.command.amount = q.amount;
    d.record.t_s = t_s;
    d.record.source = "operator";
    d.record.description = describeCommand(d.command, q.target_text);
    d.record.status = "lost";  // until an outcome
    out.push_back(std::move(d));
  }
  return out;
}

}  // namespace gesture_formation::sim

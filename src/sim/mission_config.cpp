#include "gesture_formation/sim/mission_config.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/onboard/onboard_settings.hpp"
#include "validate_util.hpp"

namespace gesture_formation::sim {

using common::ConfigReader;
using common::Range;
using detail::check;

std::vector<std::string> LinkConfig::validate(const std::string& prefix) const {
  std::vector<std::string> e;
  check(e, delay_s >= 0, delay_s, prefix, "delay_s", ">= 0");
  check(e, jitter_s >= 0, jitter_s, prefix, "jitter_s", ">= 0");
  check(e, loss >= 0 && loss <= 1, loss, prefix, "loss", "in [0, 1]");
  check(e, duplicate >= 0 && duplicate <= 1, duplicate, prefix, "duplicate", "in [0, 1]");
  check(e, reorder >= 0 && reorder <= 1, reorder, prefix, "reorder", "in [0, 1]");
  check(e, reorder_extra_delay_s >= 0, reorder_extra_delay_s, prefix, "reorder_extra_delay_s", ">= 0");
  return e;
}

std::vector<std::string> FaultConfig::validate(const std::string& prefix) const {
  std::vector<std::string> e;
  auto windows = [&](const std::vector<std::pair<double, double>>& w, const char* name) {
    for (std::size_t i = 0; i < w.size(); ++i) {
      const auto& [a, b] = w[i];
      if (!(std::isfinite(a) && std::isfinite(b) && a < b)) {
        e.push_back(prefix + name + "[" + std::to_string(i) + "] must be [from, to] with from < to, got [" +
                    common::formatNumber(a) + ", " + common::formatNumber(b) + "]");
      }
    }
  };
  windows(camera_blackouts, "camera_blackouts");
  windows(uwb_dropouts, "uwb_dropouts");
  windows(stereo_dropouts, "stereo_dropouts");
  for (std::size_t i = 0; i < planner_outages.size(); ++i) {
    const auto& o = planner_outages[i];
    if (!(o.from_s < o.to_s)) e.push_back(prefix + "planner_outages[" + std::to_string(i) + "] needs from_s < to_s");
  }
  for (std::size_t i = 0; i < follower_dropouts.size(); ++i) {
    const auto& o = follower_dropouts[i];
    const std::string k = prefix + "follower_dropouts[" + std::to_string(i) + "]";
    if (!(o.from_s < o.to_s)) {
      e.push_back(k + " needs from_s < to_s, got from_s " + common::formatNumber(o.from_s) + ", to_s " + common::formatNumber(o.to_s));
    }
    if (o.uav < 1) e.push_back(k + ".uav must be a follower (>= 1), got " + std::to_string(o.uav));
  }
  const RangeOutlierConfig& ro = range_outliers;
  check(e, ro.probability >= 0 && ro.probability <= 1, ro.probability, prefix, "range_outliers.probability", "in [0, 1]");
  check(e, ro.min_error_m >= 0, ro.min_error_m, prefix, "range_outliers.min_error_m", ">= 0");
  check(e, ro.max_error_m >= ro.min_error_m, ro.max_error_m, prefix, "range_outliers.max_error_m", ">= min_error_m");
  check(e, max_share_age_s > 0, max_share_age_s, prefix, "max_share_age_s", "> 0");
  check(e, max_worker_age_s > 0, max_worker_age_s, prefix, "max_worker_age_s", "> 0");
  check(e, max_command_age_s > 0, max_command_age_s, prefix, "max_command_age_s", "> 0");
  check(e, max_plan_age_s > 0, max_plan_age_s, prefix, "max_plan_age_s", "> 0");
  for (auto& problem : search.validate(prefix)) e.push_back(std::move(problem));
  return e;
}

bool FaultConfig::followerOffline(int uav, double t_s) const {
  for (const auto& o : follower_dropouts) {
    if (o.uav == uav && t_s >= o.from_s && t_s < o.to_s) return true;
  }
  return false;
}

bool inWindow(const std::vector<std::pair<double, double>>& windows, double t_s) {
  for (const auto& [a, b] : windows) {
    if (t_s >= a && t_s < b) return true;
  }
  return false;
}

namespace {

/// The keys of one link (mission.links.* and their mission.faults.* overlays) under `k`.
void readLinkKeys(ConfigReader& r, const std::string& k, LinkConfig& lc) {
  r.readDouble(k + "delay_s", lc.delay_s, Range::nonNegative());
  r.readDouble(k + "jitter_s", lc.jitter_s, Range::nonNegative());
  r.readDouble(k + "loss", lc.loss, Range::closed(0.0, 1.0));
  r.readDouble(k + "duplicate", lc.duplicate, Range::closed(0.0, 1.0));
  r.readDouble(k + "reorder", lc.reorder, Range::closed(0.0, 1.0));
  r.readDouble(k + "reorder_extra_delay_s", lc.reorder_extra_delay_s, Range::nonNegative());
}

std::string joinPath(const std::string& base, const std::string& p) {
  if (p.empty() || p[0] == '/' || base.empty()) return p;
  return base + "/" + p;
}

Eigen::Vector3d vec3(ConfigReader& r, const std::string& key, const Eigen::Vector3d& def, bool* present = nullptr) {
  std::vector<double> v{def.x(), def.y(), def.z()};
  if (present) *present = r.has(key);
  r.readDoubleList(key, v, 3, 3, Range::any());
  if (v.size() != 3) return def;
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

const std::vector<std::pair<std::string, gesture::Motion>>& motionNames() {
  static const std::vector<std::pair<std::string, gesture::Motion>> names = [] {
    std::vector<std::pair<std::string, gesture::Motion>> v;
    for (int i = 0; i < static_cast<int>(gesture::Motion::kCount); ++i) {
      const auto m = static_cast<gesture::Motion>(i);
      v.emplace_back(gesture::toString(m), m);
    }
    return v;
  }();
  return names;
}

void readPlant(ConfigReader& r, const std::string& p, MultirotorParams& m) {
  // Physical limits: every key required (docs/conventions.md, code style 4).
  const auto req = [&](const std::string& k, double& v, const Range& range) {
    if (!r.has(p + k)) {
      r.addError(p + k, "missing (required: physical limits have no defaults)");
      return;
    }
    r.readDouble(p + k, v, range);
  };
  req("mass_kg", m.mass_kg, Range::positive());
  req("max_thrust_to_weight", m.max_thrust_to_weight, Range{1.0, 10.0, false, true});
  req("min_thrust_to_weight", m.min_thrust_to_weight, Range{0.0, 1.0, true, false});
  req("max_tilt_deg", m.max_tilt_deg, Range::openClosed(0.0, 80.0));
  req("attitude_time_constant_s", m.attitude_time_constant_s, Range::positive());
  req("drag_linear_ns_per_m", m.drag_linear_ns_per_m, Range::nonNegative());
  req("drag_quadratic_ns2_per_m2", m.drag_quadratic_ns2_per_m2, Range::nonNegative());
  req("max_yaw_rate_dps", m.max_yaw_rate_dps, Range::positive());
  req("max_pitch_rate_dps", m.max_pitch_rate_dps, Range::positive());
  req("min_pitch_deg", m.min_pitch_deg, Range::closed(-90.0, 90.0));
  req("max_pitch_deg", m.max_pitch_deg, Range::closed(-90.0, 90.0));
  req("body_radius_m", m.body_radius_m, Range::positive());
  for (const auto& e : m.validate()) r.addError(p.substr(0, p.size() - 1), e);
}

void readRoute(ConfigReader& r, const std::string& p, WorkerConfig& w) {
  const YAML::Node route = r.node(p + "route");
  if (!route.IsDefined() || !route.IsSequence()) {
    r.addError(p + "route", "missing or not a list (required)");
    return;
  }
  for (std::size_t i = 0; i < route.size(); ++i) {
    const std::string k = p + "route[" + std::to_string(i) + "].";
    RouteLeg leg;
    int kinds = 0;
    const std::pair<const char*, RouteLeg::Kind> moving[] = {
        {"walk_to", RouteLeg::Kind::kWalk}, {"climb_to", RouteLeg::Kind::kClimb}, {"descend_to", RouteLeg::Kind::kDescend}};
    for (const auto& [name, kind] : moving) {
      if (r.has(k + name)) {
        ++kinds;
        leg.kind = kind;
        leg.to_feet_world = vec3(r, k + name, Eigen::Vector3d::Zero());
        r.readDouble(k + "speed_mps", leg.speed_mps, Range::openClosed(0.0, 3.0));
      }
    }
    const std::pair<const char*, RouteLeg::Kind> still[] = {{"work_s", RouteLeg::Kind::kWork},
                                                            {"wait_s", RouteLeg::Kind::kWait}};
    for (const auto& [name, kind] : still) {
      if (r.has(k + name)) {
        ++kinds;
        leg.kind = kind;
        r.readDouble(k + name, leg.duration_s, Range::positive());
      }
    }
    if (kinds != 1) {
      r.addError(k.substr(0, k.size() - 1), "needs exactly one of walk_to, climb_to, descend_to, work_s, wait_s");
    }
    if (r.has(k + "facing_deg")) {
      double f = 0.0;
      r.readDouble(k + "facing_deg", f, Range::closed(-360.0, 360.0));
      leg.facing_deg = f;
    }
    w.route.push_back(leg);
  }
}

void readWind(ConfigReader& r, const std::string& k, WindConfig& wd) {
  wd.mean_mps = vec3(r, k + "mean_mps", wd.mean_mps);
  r.readDouble(k + "turbulence_std_mps", wd.turbulence_std_mps, Range::nonNegative());
  r.readDouble(k + "turbulence_time_constant_s", wd.turbulence_time_constant_s, Range::positive());
  r.readDouble(k + "gusts_per_minute", wd.gusts_per_minute, Range::nonNegative());
  r.readDouble(k + "gust_peak_mps", wd.gust_peak_mps, Range::nonNegative());
  r.readDouble(k + "gust_duration_s", wd.gust_duration_s, Range::positive());
}

void readScheduledGestures(ConfigReader& r, const std::string& wk, WorkerConfig& w) {
  const YAML::Node gestures = r.node(wk + "gestures");
  if (gestures.IsDefined() && gestures.IsSequence()) {
    for (std::size_t i = 0; i < gestures.size(); ++i) {
      const std::string k = wk + "gestures[" + std::to_string(i) + "].";
      ScheduledGesture g;
      if (!r.has(k + "t_s") || !r.has(k + "gesture")) r.addError(k + "t_s", "each gesture needs t_s and gesture");
      r.readDouble(k + "t_s", g.t_s, Range::nonNegative());
      r.readInt(k + "gesture", g.gesture_id, Range::closed(1, 4));
      w.gestures.push_back(g);
    }
  } else if (gestures.IsDefined() && !gestures.IsNull()) {
    r.addError(wk + "gestures", "must be a list");
  }
}

void readWorkMotions(ConfigReader& r, const std::string& wk, WorkerConfig& w) {
  const YAML::Node motions = r.node(wk + "work_motions");
  if (!motions.IsDefined()) return;
  if (!motions.IsSequence()) {
    r.addError(wk + "work_motions", "must be a list of motion names");
    return;
  }
  w.work_motions.clear();
  for (std::size_t i = 0; i < motions.size(); ++i) {
    const std::string name = motions[i].IsScalar() ? motions[i].Scalar() : "";
    bool found = false;
    for (const auto& [n, mo] : motionNames()) {
      if (n == name) {
        w.work_motions.push_back(mo);
        found = true;
      }
    }
    if (!found) r.addError(wk + "work_motions[" + std::to_string(i) + "]", "unknown motion '" + name + "'");
  }
}

/// mission.worker: body, start, route, scheduled gestures, work motions, skeleton synthesis.
void readWorker(ConfigReader& r, const std::string& m, WorkerConfig& w) {
  const std::string wk = m + "worker.";
  r.readDouble(wk + "height_m", w.height_m, Range::closed(1.0, 2.3));
  if (!r.has(wk + "start")) r.addError(wk + "start", "missing (required)");
  w.start_feet_world = vec3(r, wk + "start", Eigen::Vector3d::Zero());
  r.readDouble(wk + "start_facing_deg", w.start_facing_deg, Range::closed(-360.0, 360.0));
  r.readDouble(wk + "gesture_hold_min_s", w.gesture_hold_min_s, Range::positive());
  r.readDouble(wk + "gesture_hold_max_s", w.gesture_hold_max_s, Range::positive());
  readRoute(r, wk, w);
  readScheduledGestures(r, wk, w);
  readWorkMotions(r, wk, w);
  for (const char* key : {"keypoint_noise_max", "dropout_max", "box_jitter", "tempo_min", "tempo_max"}) {
    gesture::synthConfigFields().readField(r, wk + "synth.", w.synth, key);  // the synthesiser's ranges
  }
}

/// mission.uavs: the leader first, then the followers.
void readUavs(ConfigReader& r, const std::string& m, std::vector<UavConfig>& out) {
  const YAML::Node uavs = r.node(m + "uavs");
  if (!uavs.IsDefined() || !uavs.IsSequence() || uavs.size() == 0) {
    r.addError(m + "uavs", "missing or empty (required: the leader first, then the followers)");
    return;
  }
  for (std::size_t i = 0; i < uavs.size(); ++i) {
    const std::string k = m + "uavs[" + std::to_string(i) + "].";
    UavConfig u;
    u.name = i == 0 ? "leader" : "follower" + std::to_string(i);
    r.readString(k + "name", u.name);
    readPlant(r, k + "plant.", u.plant);
    bool present = false;
    const Eigen::Vector3d p = vec3(r, k + "initial_position", Eigen::Vector3d::Zero(), &present);
    if (present) u.initial_position = p;
    out.push_back(u);
  }
}

void readControllerGains(ConfigReader& r, const std::string& m, ControllerConfig& ct) {
  const std::string ck = m + "controller.";
  for (auto [name, v] : std::initializer_list<std::pair<const char*, double*>>{
           {"kp_xy", &ct.kp_xy}, {"kp_z", &ct.kp_z}, {"kd_xy", &ct.kd_xy}, {"kd_z", &ct.kd_z},
           {"ki_xy", &ct.ki_xy}, {"ki_z", &ct.ki_z}, {"integral_limit_mps2", &ct.integral_limit_mps2},
           {"integral_zone_m", &ct.integral_zone_m}, {"integral_zone_mps", &ct.integral_zone_mps},
           {"max_accel_mps2", &ct.max_accel_mps2}, {"k_heading", &ct.k_heading}, {"k_pitch", &ct.k_pitch},
           {"hover_speed_mps", &ct.hover_speed_mps}}) {
    r.readDouble(ck + name, *v, Range::nonNegative());
  }
}

/// The product's settings (replanning, safety limits, formation, gestures, planner, estimator):
/// one parse with the onboard nodelets (onboard::readOnboardSettings).
void readOnboard(ConfigReader& r, const std::string& m, MissionConfig& c) {
  onboard::OnboardSettings onboard;
  onboard::readOnboardSettings(r, m, onboard);
  c.replanning_period_s = onboard.replanning_period_s;
  c.horizon_dt_s = onboard.horizon_dt_s;
  c.horizon_steps = onboard.horizon_steps;
  c.controller.brake_accel_mps2 = onboard.brake_accel_mps2;
  c.faults.max_share_age_s = onboard.freshness.max_share_age_s;
  c.faults.max_worker_age_s = onboard.freshness.max_worker_age_s;
  c.faults.search = onboard.search;
  c.faults.max_command_age_s = onboard.max_command_age_s;
  c.faults.max_plan_age_s = onboard.rule.max_plan_age_s;
  c.faults.avoid_all_plans = onboard.rule.avoid_all_plans;
  c.formation = onboard.formation;
  c.gesture_filter = onboard.gesture_filter;
  c.gesture_mapping = onboard.gesture_mapping;
  c.view_fusion = onboard.view_fusion;
  c.planner = onboard.planner;
  c.estimator = onboard.estimator;
  c.abort = onboard.abort;
}

void readOdometry(ConfigReader& r, const std::string& m, OdometryConfig& od) {
  const std::string ok = m + "odometry.";
  r.readDouble(ok + "position_noise_m", od.position_noise_m, Range::nonNegative());
  r.readDouble(ok + "velocity_noise_mps", od.velocity_noise_mps, Range::nonNegative());
  r.readDouble(ok + "heading_noise_deg", od.heading_noise_deg, Range::nonNegative());
  r.readDouble(ok + "pitch_noise_deg", od.pitch_noise_deg, Range::nonNegative());
  r.readDouble(ok + "bias_std_m", od.bias_std_m, Range::nonNegative());
  r.readDouble(ok + "bias_time_constant_s", od.bias_time_constant_s, Range::positive());
}

/// mission.sensors (camera, stereo, UWB) and mission.links.
void readSensorsAndLinks(ConfigReader& r, const std::string& m, MissionConfig& c) {
  const std::string sk = m + "sensors.";
  r.readDouble(sk + "camera.rate_hz", c.camera.rate_hz, Range::openClosed(0.0, 60.0));
  r.readDouble(sk + "camera.pixel_noise_px", c.camera.pixel_noise_px, Range::nonNegative());
  r.readDouble(sk + "camera.detection_dropout", c.camera.detection_dropout, Range{0.0, 1.0, true, false});
  r.readDouble(sk + "camera.max_detection_range_m", c.camera.max_detection_range_m, Range::positive());
  r.readDouble(sk + "camera.min_box_height_px", c.camera.min_box_height_px, Range::atLeast(1.0));
  r.readDouble(sk + "camera.min_visible_fraction", c.camera.min_visible_fraction, Range::openClosed(0.0, 1.0));
  r.readDouble(sk + "camera.occlusion_ignore_near_worker_m", c.camera.occlusion_ignore_near_worker_m,
               Range::nonNegative());
  for (auto [name, rs] : std::initializer_list<std::pair<const char*, RangeSensorConfig*>>{{"stereo", &c.stereo},
                                                                                         {"uwb", &c.uwb}}) {
    const std::string k = sk + name + ".";
    r.readDouble(k + "noise_m", rs->noise_m, Range::nonNegative());
    r.readDouble(k + "max_range_m", rs->max_range_m, Range::positive());
    r.readDouble(k + "dropout", rs->dropout, Range::closed(0.0, 1.0));
  }
  for (auto [name, lc] : std::initializer_list<std::pair<const char*, LinkConfig*>>{{"links.uav", &c.link},
                                                                                  {"links.operator", &c.operator_link}}) {
    readLinkKeys(r, m + name + ".", *lc);
  }
}

void readWindows(ConfigReader& r, const std::string& key, std::vector<std::pair<double, double>>& out) {
  const YAML::Node bl = r.node(key);
  if (!bl.IsDefined()) return;
  if (!bl.IsSequence()) {
    r.addError(key, "must be a list of [from_s, to_s] windows");
    return;
  }
  for (std::size_t i = 0; i < bl.size(); ++i) {
    std::vector<double> v;
    r.readDoubleList(key + "[" + std::to_string(i) + "]", v, 2, 2, Range::nonNegative());
    if (v.size() == 2) out.emplace_back(v[0], v[1]);
  }
}

void readPlannerOutages(ConfigReader& r, const std::string& fk, std::vector<PlannerOutage>& out) {
  const YAML::Node po = r.node(fk + "planner_outages");
  if (!po.IsDefined() || !po.IsSequence()) return;
  for (std::size_t i = 0; i < po.size(); ++i) {
    const std::string k = fk + "planner_outages[" + std::to_string(i) + "].";
    PlannerOutage o;
    r.readInt(k + "uav", o.uav, Range::closed(0, 63));
    r.readDouble(k + "from_s", o.from_s, Range::nonNegative());
    r.readDouble(k + "to_s", o.to_s, Range::nonNegative());
    out.push_back(o);
  }
}

void readFollowerDropouts(ConfigReader& r, const std::string& fk, std::vector<UavDropout>& out) {
  const YAML::Node fd = r.node(fk + "follower_dropouts");
  if (fd.IsDefined() && fd.IsSequence()) {
    for (std::size_t i = 0; i < fd.size(); ++i) {
      const std::string k = fk + "follower_dropouts[" + std::to_string(i) + "].";
      UavDropout o;
      for (const char* key : {"uav", "from_s", "to_s"}) {
        if (!r.has(k + key)) r.addError(k + key, "missing (required)");
      }
      r.readInt(k + "uav", o.uav, Range::closed(1, 63));
      r.readDouble(k + "from_s", o.from_s, Range::nonNegative());
      r.readDouble(k + "to_s", o.to_s, Range::nonNegative());
      out.push_back(o);
    }
  } else if (fd.IsDefined()) {
    r.addError(fk + "follower_dropouts", "must be a list of {uav, from_s, to_s}");
  }
}

/// mission.faults: link and wind overlays (key by key over mission.links.* / mission.wind),
/// sensor windows, planner outages, follower dropouts, range outliers.
void readFaults(ConfigReader& r, const std::string& m, MissionConfig& c) {
  const std::string fk = m + "faults.";
  for (auto [name, lc] : std::initializer_list<std::pair<const char*, LinkConfig*>>{{"link", &c.link},
                                                                                  {"operator_link", &c.operator_link}}) {
    readLinkKeys(r, fk + name + ".", *lc);
  }
  readWind(r, fk + "wind.", c.wind);
  readWindows(r, fk + "camera_blackouts", c.faults.camera_blackouts);
  readWindows(r, fk + "uwb_dropouts", c.faults.uwb_dropouts);
  readWindows(r, fk + "stereo_dropouts", c.faults.stereo_dropouts);
  readPlannerOutages(r, fk, c.faults.planner_outages);
  readFollowerDropouts(r, fk, c.faults.follower_dropouts);
  readAbortEvent(r, fk + "abort", c.faults.abort);
  const std::string k = fk + "range_outliers.";
  r.readDouble(k + "probability", c.faults.range_outliers.probability, Range::closed(0.0, 1.0));
  r.readDouble(k + "min_error_m", c.faults.range_outliers.min_error_m, Range::nonNegative());
  r.readDouble(k + "max_error_m", c.faults.range_outliers.max_error_m, Range::nonNegative());
  for (const auto& e : c.faults.validate()) r.addError(m + "faults", e);
}

/// Cross-section checks: the UAV list, outages and dropouts against the formation's UAV count.
void checkUavCount(ConfigReader& r, const std::string& m, const MissionConfig& c) {
  const int n_uavs = c.formation.params.uavCount();
  const std::string fk = m + "faults.";
  if (!c.uavs.empty() && static_cast<int>(c.uavs.size()) != n_uavs) {
    r.addError(m + "uavs", "has " + std::to_string(c.uavs.size()) + " entries but mission.formation has " +
                               std::to_string(n_uavs) + " UAVs (leader + followers)");
  }
  for (const auto& o : c.faults.planner_outages) {
    if (o.uav >= n_uavs) r.addError(fk + "planner_outages", "uav " + std::to_string(o.uav) + " does not exist");
  }
  for (const auto& o : c.faults.follower_dropouts) {
    if (o.uav >= n_uavs) r.addError(fk + "follower_dropouts", "uav " + std::to_string(o.uav) + " does not exist");
  }
}

/// A request's target: a list of UAV indices or a name (formation::parseTarget).
void readRequestTarget(ConfigReader& r, const std::string& k, int n_uavs, OperatorRequest& q) {
  const YAML::Node tn = r.node(k + "target");
  if (!tn.IsDefined()) {
    r.addError(k + "target", "missing (required)");
  } else if (tn.IsSequence()) {
    std::vector<int> ids;
    std::string text = "[";
    for (std::size_t j = 0; j < tn.size(); ++j) {
      int id = -1;
      try {
        id = tn[j].as<int>();
      } catch (const YAML::Exception&) {
      }
      if (id < 0 || id >= n_uavs) {
        r.addError(k + "target[" + std::to_string(j) + "]", "must be a UAV index in [0, " + std::to_string(n_uavs - 1) + "]");
      }
      ids.push_back(id);
      text += (j ? "," : "") + std::to_string(id);
    }
    if (ids.empty()) r.addError(k + "target", "empty list");
    q.target = formation::CommandTarget::list(ids);
    q.target_text = text + "]";
  } else {
    q.target_text = tn.IsScalar() ? tn.Scalar() : "";
    const auto t = formation::parseTarget(q.target_text);
    if (!t) {
      r.addError(k + "target", t.reason());
    } else {
      q.target = *t;
      if (!q.target.resolve(n_uavs)) r.addError(k + "target", "'" + q.target_text + "' does not exist in the formation");
    }
  }
}

/// mission.requests: the operator's formation requests, in time order.
void readRequests(ConfigReader& r, const std::string& m, int n_uavs, std::vector<OperatorRequest>& out) {
  const YAML::Node reqs = r.node(m + "requests");
  if (!reqs.IsDefined() || !reqs.IsSequence()) return;
  for (std::size_t i = 0; i < reqs.size(); ++i) {
    const std::string k = m + "requests[" + std::to_string(i) + "].";
    OperatorRequest q;
    if (!r.has(k + "t_s")) r.addError(k + "t_s", "missing (required)");
    r.readDouble(k + "t_s", q.t_s, Range::nonNegative());
    readRequestTarget(r, k, n_uavs, q);
    std::string param;
    r.readString(k + "parameter", param, {"beta_deg", "gamma_deg", "distance_m"});
    if (!r.has(k + "parameter")) r.addError(k + "parameter", "missing (required)");
    q.parameter = param == "gamma_deg" ? formation::Parameter::kGamma
                  : param == "distance_m" ? formation::Parameter::kDistance
                                          : formation::Parameter::kBeta;
    const bool inc = r.has(k + "increment"), set = r.has(k + "set");
    if (inc == set) r.addError(k.substr(0, k.size() - 1), "needs exactly one of increment, set");
    q.kind = set ? formation::CommandKind::kSet : formation::CommandKind::kIncrement;
    r.readDouble(k + (set ? "set" : "increment"), q.amount, Range::any());
    if (i > 0 && q.t_s < out.back().t_s) r.addError(k + "t_s", "requests must be in time order");
    out.push_back(q);
  }
}

}  // namespace

common::Result<MissionConfig> parseMissionConfig(const std::string& yaml, const std::string& source_name,
                                                 const std::string& base_dir) {
  using R = common::Result<MissionConfig>;
  ConfigReader r = ConfigReader::fromString(yaml, source_name, ConfigReader::MissingKeys::kUseDefaults);
  MissionConfig c;
  c.source = source_name;
  if (!r.has("mission")) {
    r.addError("mission", "missing: the scenario has no mission section");
    return R::fail(r.errorReport());
  }
  const std::string m = "mission.";
  r.readDouble(m + "step_s", c.step_s, Range::openClosed(0.0, 0.05));
  r.readDouble(m + "timeline_rate_hz", c.timeline_rate_hz, Range::openClosed(0.0, 100.0));
  r.readDouble(m + "gesture_match_window_s", c.gesture_match_window_s, Range::positive());
  if (r.has(m + "gesture_model")) {
    r.readString(m + "gesture_model", c.gesture_model);
    c.gesture_model = joinPath(base_dir, c.gesture_model);
  }
  readWorker(r, m, c.worker);
  readUavs(r, m, c.uavs);
  readControllerGains(r, m, c.controller);
  readOnboard(r, m, c);
  for (const auto& e : c.controller.validate()) r.addError(m + "controller", e);
  readOdometry(r, m, c.odometry);
  readWind(r, m + "wind.", c.wind);
  readSensorsAndLinks(r, m, c);
  readFaults(r, m, c);

  c.camera.camera = c.estimator.camera;  // one camera: what the sensor sees is what the estimator models
  c.worker.synth.camera = c.estimator.camera;
  c.worker.synth.fps = c.camera.rate_hz;
  checkUavCount(r, m, c);
  readRequests(r, m, c.formation.params.uavCount(), c.requests);

  for (const auto& e : c.worker.validate(m + "worker.")) r.addError(m + "worker", e);
  c.duration_s = c.worker.routeDuration();
  r.readDouble(m + "duration_s", c.duration_s, Range::positive());
  for (const auto& u : r.unusedKeys()) {
    if (u.rfind("mission.", 0) == 0) r.addError(u, "unknown key");
  }
  if (!r.ok()) return R::fail(r.errorReport());
  return R::ok(c);
}

common::Result<MissionConfig> loadMissionConfig(const std::string& scenario_path) {
  return loadMissionConfig(scenario_path, "");
}

common::Result<MissionConfig> loadMissionConfig(const std::string& scenario_path, const std::string& faults_path) {
  auto yaml = onboard::loadMissionYaml(scenario_path, faults_path);
  if (!yaml) return common::Result<MissionConfig>::fail(yaml.reason());
  const auto slash = scenario_path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "." : scenario_path.substr(0, slash);
  return parseMissionConfig(*yaml, faults_path.empty() ? scenario_path : scenario_path + " + " + faults_path, dir);
}

std::vector<std::string> gestureReadabilityWarnings(const MissionConfig& m) {
  const gesture::ViewFusionConfig& vf = m.view_fusion;
  if (m.gesture_model.empty() || !vf.gate_envelope) return {};
  const formation::FormationParams& fp = m.formation.params;
  const formation::UavReference lref = formation::leaderReference(Eigen::Vector3d::Zero(), 0.0, fp.leader);
  std::vector<formation::UavReference> refs{lref};
  for (const auto& f : fp.followers) {
    refs.push_back(formation::followerReference(Eigen::Vector3d::Zero(), lref.heading_rad, lref.pitch_rad, f));
  }
  // Followers' cameras vote only when they are views of the fusion (min_agreeing_views > 1).
  const std::size_t cameras = vf.min_agreeing_views > 1 ? refs.size() : 1;
  int inside = 0;
  std::string outside;
  for (std::size_t i = 0; i < cameras; ++i) {
    const formation::ViewGeometry g = formation::viewGeometry(refs[i].p_world, Eigen::Vector3d::Zero());
    const double d = g.distance_m, e = g.elevation_deg;
    if (vf.inEnvelope(d, e)) {
      ++inside;
      continue;
    }
    std::ostringstream o;
    o.precision(3);
    o << (outside.empty() ? "" : ", ") << (i == 0 ? std::string("the leader") : "follower " + std::to_string(i)) << " at "
      << d << " m, " << e << " deg";
    outside += o.str();
  }
  if (inside >= vf.min_agreeing_views) return {};
  std::ostringstream w;
  w << "gestures: " << inside << " of " << cameras << " cameras inside the classifier's validated envelope ("
    << vf.distance_min_m << "-" << vf.distance_max_m << " m, " << vf.elevation_min_deg << "-" << vf.elevation_max_deg
    << " deg above the worker; view_fusion) at the mission's start, " << vf.min_agreeing_views
    << " needed to accept a gesture (min_agreeing_views): " << outside << " do not vote"
    << (vf.confirm_3d && inside + 1 == vf.min_agreeing_views ? " (a one-arm gesture may still pass the 3-D confirmation)" : "")
    << " (docs/gestures.md 4.1)";
  return {w.str()};
}

}  // namespace gesture_formation::sim

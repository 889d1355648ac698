#include "gesture_formation/sim/mission_config.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/format_number.hpp"
#include "gesture_formation/sim/assistance_drill.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/onboard/onboard_settings.hpp"

namespace gesture_formation::sim {

using common::ConfigReader;
using common::Range;

const common::FieldTable<RangeOutlierConfig>& rangeOutlierFields() {
  using C = RangeOutlierConfig;
  static const common::FieldTable<C> t{{
      {"probability", Range::closed(0.0, 1.0), [](C& c) { return &c.probability; }},
      {"min_error_m", Range::nonNegative(), [](C& c) { return &c.min_error_m; }},
      {"max_error_m", Range::nonNegative(), [](C& c) { return &c.max_error_m; }},
  }};
  return t;
}

const common::FieldTable<PlannerOutage>& plannerOutageFields() {
  static const common::FieldTable<PlannerOutage> t{{
      {"uav", Range::closed(0, 63), [](PlannerOutage& o) { return &o.uav; }},
      {"from_s", Range::nonNegative(), [](PlannerOutage& o) { return &o.from_s; }},
      {"to_s", Range::nonNegative(), [](PlannerOutage& o) { return &o.to_s; }},
  }};
  return t;
}

const common::FieldTable<UavDropout>& uavDropoutFields() {
  static const common::FieldTable<UavDropout> t{{
      {"uav", Range::closed(1, 63), [](UavDropout& o) { return &o.uav; }},
      {"from_s", Range::nonNegative(), [](UavDropout& o) { return &o.from_s; }},
      {"to_s", Range::nonNegative(), [](UavDropout& o) { return &o.to_s; }},
  }};
  return t;
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
  const auto entries = [&](const auto& list, const auto& table, const char* name) {
    for (std::size_t i = 0; i < list.size(); ++i) {
      const auto& o = list[i];
      const std::string k = prefix + name + "[" + std::to_string(i) + "]";
      for (auto& line : common::problemLines(table.rangeProblems(o), k + ".")) e.push_back(line);
      if (!(o.from_s < o.to_s)) {
        e.push_back(k + " needs from_s < to_s, got from_s " + common::formatNumber(o.from_s) + ", to_s " +
                    common::formatNumber(o.to_s));
      }
    }
  };
  entries(planner_outages, plannerOutageFields(), "planner_outages");
  entries(follower_dropouts, uavDropoutFields(), "follower_dropouts");
  entries(operator_outages, plannerOutageFields(), "operator_outages");
  auto outliers = rangeOutlierFields().rangeProblems(range_outliers);
  common::checkRule(outliers, range_outliers.max_error_m >= range_outliers.min_error_m, "max_error_m",
                    range_outliers.max_error_m, "must be >= min_error_m");
  for (auto& line : common::problemLines(outliers, prefix + "range_outliers.")) e.push_back(line);
  if (!onboard::ranges::kMaxCommandAgeS.contains(max_command_age_s)) {
    e.push_back(prefix + "max_command_age_s " + common::rangeProblem(onboard::ranges::kMaxCommandAgeS, max_command_age_s));
  }
  return e;
}

bool FaultConfig::followerOffline(int uav, double t_s) const {
  for (const auto& o : follower_dropouts) {
    if (o.uav == uav && t_s >= o.from_s && t_s < o.to_s) return true;
  }
  return false;
}

bool FaultConfig::operatorLinkDown(int uav, double t_s) const {
  for (const auto& o : operator_outages) {
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
void readLinkKeys(ConfigReader& r, const std::string& k, LinkConfig& lc) { comm::faultChannelFields().readFields(r, k, lc); }

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
  multirotorParamsFields().readRequiredFields(r, p, m, "physical limits have no defaults");
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
        routeLegFields().readField(r, k, leg, "speed_mps");
      }
    }
    const std::pair<const char*, RouteLeg::Kind> still[] = {{"work_s", RouteLeg::Kind::kWork},
                                                            {"wait_s", RouteLeg::Kind::kWait}};
    for (const auto& [name, kind] : still) {
      if (r.has(k + name)) {
        ++kinds;
        leg.kind = kind;
        r.readDouble(k + name, leg.duration_s, *routeLegFields().rangeOf("duration_s"));
      }
    }
    if (kinds != 1) {
      r.addError(k.substr(0, k.size() - 1), "needs exactly one of walk_to, climb_to, descend_to, work_s, wait_s");
    }
    if (r.has(k + "facing_deg")) {
      double f = 0.0;
      r.readDouble(k + "facing_deg", f, kFacingDegRange);
      leg.facing_deg = f;
    }
    w.route.push_back(leg);
  }
}

void readWind(ConfigReader& r, const std::string& k, WindConfig& wd) {
  wd.mean_mps = vec3(r, k + "mean_mps", wd.mean_mps);
  windConfigFields().readFields(r, k, wd);
}

void readScheduledGestures(ConfigReader& r, const std::string& wk, WorkerConfig& w) {
  const YAML::Node gestures = r.node(wk + "gestures");
  if (gestures.IsDefined() && gestures.IsSequence()) {
    for (std::size_t i = 0; i < gestures.size(); ++i) {
      const std::string k = wk + "gestures[" + std::to_string(i) + "].";
      ScheduledGesture g;
      if (!r.has(k + "t_s") || !r.has(k + "gesture")) r.addError(k + "t_s", "each gesture needs t_s and gesture");
      scheduledGestureFields().readFields(r, k, g);
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
  workerConfigFields().readFields(r, wk, w);
  if (!r.has(wk + "start")) r.addError(wk + "start", "missing (required)");
  w.start_feet_world = vec3(r, wk + "start", Eigen::Vector3d::Zero());
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
  controllerConfigFields().readFields(r, m + "controller.", ct);  // brake_accel_mps2: readOnboard
}

/// The product's settings (replanning, safety limits, formation, gestures, planner, estimator):
/// one parse with the onboard nodelets (onboard::readOnboardSettings).
void readOnboard(ConfigReader& r, const std::string& m, MissionConfig& c) {
  onboard::OnboardSettings onboard;
  onboard::readOnboardSettings(r, m, onboard);
  c.replanning_period_s = onboard.replanning_period_s;
  c.replan = onboard.replan;
  c.controller.brake_accel_mps2 = onboard.replan.brake_accel_mps2;  // the simulated flight controller brakes alike
  c.faults.max_command_age_s = onboard.max_command_age_s;
  c.formation = onboard.formation;
  c.gesture_filter = onboard.gesture_filter;
  c.gesture_mapping = onboard.gesture_mapping;
  c.view_fusion = onboard.view_fusion;
  c.planner = onboard.planner;
  c.estimator = onboard.estimator;
}

void readOdometry(ConfigReader& r, const std::string& m, OdometryConfig& od) {
  const std::string ok = m + "odometry.";
  odometryConfigFields().readFields(r, ok, od);
}

void readSensorsAndLinks(ConfigReader& r, const std::string& m, MissionConfig& c) {
  const std::string sk = m + "sensors.";
  cameraSensorFields().readFields(r, sk + "camera.", c.camera);
  for (auto [name, rs] : std::initializer_list<std::pair<const char*, RangeSensorConfig*>>{{"stereo", &c.stereo},
                                                                                         {"uwb", &c.uwb}}) {
    const std::string k = sk + name + ".";
    rangeSensorFields().readFields(r, k, *rs);
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
    plannerOutageFields().readFields(r, k, o);
    out.push_back(o);
  }
}

/// A required list of {uav, from_s, to_s} windows at fk + name, each entry's fields all required
/// (`missing` says what an entry must name); problems named by key.
template <class Window>
void readUavWindows(ConfigReader& r, const std::string& fk, const char* name, const common::FieldTable<Window>& fields,
                    const char* missing, std::vector<Window>& out) {
  const YAML::Node list = r.node(fk + name);
  if (list.IsDefined() && list.IsSequence()) {
    for (std::size_t i = 0; i < list.size(); ++i) {
      Window o;
      fields.readRequiredFields(r, fk + name + "[" + std::to_string(i) + "].", o, missing);
      out.push_back(o);
    }
  } else if (list.IsDefined()) {
    r.addError(fk + name, "must be a list of {uav, from_s, to_s}");
  }
}

/// mission.faults: link and wind overlays (key by key over mission.links.* / mission.wind),
/// sensor windows, planner outages, follower dropouts, operator-link outages, range outliers.
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
  readUavWindows(r, fk, "follower_dropouts", uavDropoutFields(), "a dropout names its follower and window",
                 c.faults.follower_dropouts);
  readUavWindows(r, fk, "operator_outages", plannerOutageFields(), "an outage names its UAV and window",
                 c.faults.operator_outages);
  readAbortEvent(r, fk + "abort", c.faults.abort);
  readWorkerApproach(r, fk + "worker_approach", c.faults.worker_approach);
  readLeaderSilence(r, fk + "leader_silence", c.faults.leader_silence);
  const std::string k = fk + "range_outliers.";
  rangeOutlierFields().readFields(r, k, c.faults.range_outliers);
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
  if (c.faults.worker_approach && c.faults.worker_approach->uav >= n_uavs) {
    r.addError(fk + "worker_approach.uav", "uav " + std::to_string(c.faults.worker_approach->uav) + " does not exist");
  }
  for (const auto& o : c.faults.follower_dropouts) {
    if (o.uav >= n_uavs) r.addError(fk + "follower_dropouts", "uav " + std::to_string(o.uav) + " does not exist");
  }
  for (const auto& o : c.faults.operator_outages) {
    if (o.uav >= n_uavs) r.addError(fk + "operator_outages", "uav " + std::to_string(o.uav) + " does not exist");
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
  readOdometry(r, m, c.odometry);
  readWind(r, m + "wind.", c.wind);
  readSensorsAndLinks(r, m, c);
  readFaults(r, m, c);
  c.mapping = readSiteMappingConfig(r, m + "mapping.");  // the UAVs' online mapping (site_mapping_config.hpp)

  c.camera.camera = c.estimator.camera;  // one camera: what the sensor sees is what the estimator models
  c.worker.synth.camera = c.estimator.camera;
  c.worker.synth.fps = c.camera.rate_hz;
  checkUavCount(r, m, c);
  readRequests(r, m, c.formation.params.uavCount(), c.requests);
  readAssistanceAcks(r, m + "assistance_acks_s", c.assistance_acks_s);
  readLeadership(r, m, c.formation.params.uavCount(), c.leadership);

  for (const auto& e : c.worker.validate(m + "worker.")) r.addError(m + "worker", e);
  // The verifier's clearance is the plan's last line against obstacles: a UAV whose frame and props
  // reach farther than it may be planned into contact (docs/planning.md §7).
  for (std::size_t i = 0; i < c.uavs.size(); ++i) {
    const double radius = c.uavs[i].plant.body_radius_m;
    if (radius > c.planner.verify_clearance_m) {
      std::ostringstream os;
      os << radius << " m exceeds the planner's verify.clearance_m " << c.planner.verify_clearance_m
         << " m: the verified clearance would let the frame or props touch (raise verify.clearance_m)";
      r.addError(m + "uavs[" + std::to_string(i) + "].plant.body_radius_m", os.str());
    }
  }
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

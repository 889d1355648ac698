// gfctl simulate --scenario FILE --out DIR [--seed N] [--seeds A..B] [--duration S] [--model ONNX] [--no-plot]
//                [--faults FILE | --fault-profile NAME] [--threads N]
//                [--camera synthetic|rendered] [--camera-rate HZ] [--camera-video DIR] [--models DIR]
//                [--mapping on|off] [--no-prior-map]
// (docs/design.md §8.4; docs/simulation.md)
#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>
#include <thread>

#include <opencv2/core/utility.hpp>

#include "commands.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/planning/catenary.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/sim/mission_runner.hpp"
#include "gesture_formation/sim/rendered_camera.hpp"
#include "gesture_formation/sim/site_mapping.hpp"
#include "gesture_formation/sim/unmapped_obstacles.hpp"

namespace gesture_formation::gfctl {

namespace {

using common::formatDouble;

int cmdSimulate(const Args& args);
const Registrar kRegistrar{
    "simulate",
    "--scenario FILE --out DIR [--seed N | --seeds A..B] [--duration S] [--model ONNX] [--no-plot] "
    "[--faults FILE | --fault-profile NAME] [--threads N] [--camera synthetic|rendered] [--camera-rate HZ] "
    "[--camera-video DIR] [--models DIR] [--mapping on|off] [--no-prior-map] [--map-share on|off]   closed-loop mission: metrics.json, timeline.csv, events.csv, modes.csv, "
    "timeline.png (docs/design.md §8.4); --faults replaces mission.faults with FILE's faults: section, --fault-profile NAME "
    "uses <scenario dir>/../faults/NAME.yaml (config/faults/; docs/safety.md); --threads N classifies the UAVs' "
    "camera views of a frame on N threads, with --camera rendered also runs their perception pipelines on them (default: "
    "the UAV count, at most the cores; results do not depend on it); "
    "--camera rendered renders every UAV's camera and runs the real perception pipeline on the images (EGL; "
    "docs/simulation.md §8): perception.csv and a metrics.json perception section; --camera-rate lowers its frame "
    "rate, --camera-video writes each UAV's annotated stream (MJPG .avi); --mapping on|off overrides mission.mapping.enabled "
    "(every UAV maps the site from its depth frames and plans on its live map; docs/mapping.md §7), --no-prior-map starts "
    "the live maps empty (mission.mapping.prior_map false), --map-share on|off overrides mission.mapping.share.enabled "
    "(every UAV sends its map changes to the others and merges theirs; docs/mapping.md §8); a scenario's unmapped_obstacles are in the world, not in the "
    "prior map (docs/simulation.md)",
    cmdSimulate};

bool makeDir(const std::string& path) {
  std::string cur;
  std::stringstream ss(path);
  std::string part;
  if (!path.empty() && path[0] == '/') cur = "/";
  while (std::getline(ss, part, '/')) {
    if (part.empty()) continue;
    cur += part + "/";
    if (mkdir(cur.c_str(), 0755) != 0 && errno != EEXIST) return false;
  }
  return true;
}

bool fileExists(const std::string& p) {
  struct stat st {};
  return stat(p.c_str(), &st) == 0;
}

bool parseUint(const std::string& s, std::uint64_t& v) {
  if (s.empty() || s.find_first_not_of("0123456789") != std::string::npos || s.size() > 18) return false;
  v = std::stoull(s);
  return true;
}

/// Towers, conductor polylines, boxes and cylinders for the plot (scene.json).
std::string sceneJson(const planning::Scenario& sc) {
  std::ostringstream os;
  auto v3 = [](const Eigen::Vector3d& v) {
    return "[" + formatDouble(v.x()) + ", " + formatDouble(v.y()) + ", " + formatDouble(v.z()) + "]";
  };
  os << "{\n  \"bounds\": {\"min\": " << v3(sc.map.bounds.min_world) << ", \"max\": " << v3(sc.map.bounds.max_world)
     << "},\n  \"towers\": [";
  for (std::size_t i = 0; i < sc.towers.size(); ++i) {
    const auto& t = sc.towers[i];
    os << (i ? ", " : "") << "{\"name\": \"" << t.name << "\", \"base\": " << v3(t.base_world)
       << ", \"yaw_rad\": " << formatDouble(t.yaw_rad) << ", \"height_m\": " << formatDouble(t.height_m)
       << ", \"base_width_m\": " << formatDouble(t.base_width_m) << ", \"top_width_m\": " << formatDouble(t.top_width_m)
       << ", \"arms\": [";
    for (std::size_t a = 0; a < t.cross_arms.size(); ++a) {
      os << (a ? ", " : "") << "{\"height_m\": " << formatDouble(t.cross_arms[a].height_m)
         << ", \"half_length_m\": " << formatDouble(t.cross_arms[a].half_length_m) << "}";
    }
    os << "]}";
  }
  os << "],\n  \"conductors\": [";
  for (std::size_t i = 0; i < sc.conductors.size(); ++i) {
    const auto& c = sc.conductors[i];
    const auto cat = planning::Catenary::fit(c.from_world, c.to_world, c.sag_m);
    os << (i ? ", " : "") << "[";
    for (int k = 0; k <= 40 && cat; ++k) os << (k ? ", " : "") << v3(cat->point(k / 40.0));
    os << "]";
  }
  os << "],\n  \"boxes\": [";
  for (std::size_t i = 0; i < sc.boxes.size(); ++i) {
    const auto& b = sc.boxes[i];
    os << (i ? ", " : "") << "{\"center\": " << v3(b.center_world) << ", \"size\": " << v3(b.size_m)
       << ", \"yaw_rad\": " << formatDouble(std::atan2(b.R_world_box(1, 0), b.R_world_box(0, 0))) << "}";
  }
  os << "],\n  \"cylinders\": [";
  for (std::size_t i = 0; i < sc.cylinders.size(); ++i) {
    const auto& c = sc.cylinders[i];
    os << (i ? ", " : "") << "{\"p0\": " << v3(c.p0_world) << ", \"p1\": " << v3(c.p1_world)
       << ", \"radius_m\": " << formatDouble(c.radius_m) << "}";
  }
  os << "]\n}\n";
  return os.str();
}

bool writeText(const std::string& path, const std::string& text) {
  std::ofstream f(path);
  f << text;
  f.flush();
  return static_cast<bool>(f);
}

/// The plotting script and the tools venv's python (tools/plot_timeline.py next to the models dir).
std::string plotCommand(const std::string& dir) {
  std::string root = GF_DEFAULT_MODELS_DIR;
  const auto slash = root.find_last_of('/');
  root = slash == std::string::npos ? "." : root.substr(0, slash);
  const char* env = std::getenv("GF_SOURCE_DIR");
  if (env != nullptr) root = env;
  const std::string script = root + "/tools/plot_timeline.py";
  const std::string python = "/opt/gesture_formation/venv/bin/python";
  if (!fileExists(script) || !fileExists(python)) return "";
  return python + " " + script + " " + dir;
}

/// --camera-video DIR for one run: DIR itself, or DIR/seed_N for a batch (`run_dir` ends in seed_N).
std::string videoDirFor(const std::string& dir, const std::string& run_dir, bool batch) {
  if (!batch) return dir;
  const auto slash = run_dir.find_last_of('/');
  return dir + "/" + (slash == std::string::npos ? run_dir : run_dir.substr(slash + 1));
}

struct Loaded {
  planning::Scenario scenario;
  sim::MissionConfig mission;
  std::shared_ptr<const planning::OccupancyMap> map;
  std::shared_ptr<const planning::DistanceField> field;
  std::unique_ptr<sim::MissionClassifier> classifier;
  planning::PrimitiveSet solids;  ///< exact geometry for the obstacle-distance metric
  std::vector<sim::UnmappedObstacle> unmapped;  ///< in the world, not in the prior map
  bool rendered = false;          ///< --camera rendered
  sim::RenderedCameraConfig camera;  ///< its settings (video_dir: per run)
};

constexpr int kExitNoRenderer = 1;  ///< no EGL display / OpenGL 3.3 context, or a frame failed

/// The rendered camera of one run; nullptr and `rc` set when it cannot be made.
std::unique_ptr<sim::RenderedCamera> makeRenderedCamera(const Args& args, const Loaded& L, std::uint64_t seed,
                                                        const std::string& video_dir, int& rc) {
  sim::RenderedCameraConfig cc = L.camera;
  cc.video_dir = video_dir;
  if (!video_dir.empty() && !makeDir(video_dir)) {
    rc = badInput(args, "--camera-video: cannot create directory " + video_dir);
    return nullptr;
  }
  auto cam = sim::RenderedCamera::create(cc, L.mission, L.scenario, L.map.get(), seed, L.unmapped);
  if (cam) return std::move(*cam);
  if (cam.reason().find("worker asset") != std::string::npos || cam.reason().find("perception networks") != std::string::npos ||
      cam.reason().find("--camera-video") != std::string::npos) {
    rc = badInput(args, cam.reason());
  } else {  // no EGL device / OpenGL context: not the input's fault; never a fall-back to synthetic inputs
    std::cerr << "gfctl simulate: --camera rendered: " << cam.reason() << "\n";
    rc = kExitNoRenderer;
  }
  return nullptr;
}

void printPerception(const sim::PerceptionSummary& p) {
  std::cout << "  perception: worker detected in " << p.detected_in_view << "/" << p.frames_in_view
            << " frames in view (rate " << p.detection_rate << "), keypoint error median " << p.keypoint_error_px_median
            << " px (" << p.keypoint_error_fraction_median << " of the figure), box IoU median " << p.iou_median
            << ", identity switches " << p.identity_switches << "; per frame render " << p.render_ms_median
            << " ms, detect " << p.detect_ms_median << " ms, track " << p.track_ms_median << " ms, skeleton "
            << p.skeleton_ms_median << " ms\n";
  for (const auto* bins : {&p.by_distance, &p.by_elevation}) {
    std::cout << "    " << (bins == &p.by_distance ? "distance m " : "elevation deg ");
    for (const auto& b : *bins) {
      std::cout << " [" << b.label << ": " << b.detected << "/" << b.frames << ", " << b.keypoint_error_px_median << " px]";
    }
    std::cout << "\n";
  }
}

void printSiteMapping(const sim::SiteMappingSummary& s) {
  std::cout << "  site mapping: " << (s.mapping ? "live maps" : "off (planners on the prior map only)")
            << (s.mapping && !s.prior_map ? " without a prior map" : "") << ", " << s.depth_frames
            << " depth frames (ray casting median " << s.depth_ms_median << " ms, integrate median "
            << s.integrate_ms_median << " ms p99 " << s.integrate_ms_p99 << " ms), coverage " << s.coverage
            << ", min distance to unmapped obstacles " << s.min_unmapped_distance_m << " m\n";
  for (const auto& o : s.obstacles) {
    std::cout << "    " << o.name << ": coverage " << o.coverage << " (" << o.surface_voxels_seen << "/" << o.surface_voxels
              << " surface voxels), first seen " << o.first_seen_s << " s by UAV " << o.first_seen_uav << ", avoided "
              << o.avoided_s << " s (sight to avoidance " << o.sight_to_avoidance_s << " s), min distance "
              << o.min_distance_m << " m (UAV " << o.min_distance_uav << " at " << o.min_distance_t_s << " s)\n";
  }
  const sim::MapShareSummary& m = s.share;
  if (!m.enabled) return;
  std::cout << "    map sharing: " << m.updates_sent << " updates sent (" << m.voxels_sent << " voxels), " << m.updates_merged
            << " merged, " << m.updates_lost << " lost, " << m.updates_refused << " refused; changes deferred "
            << m.changes_deferred << ", dropped " << m.changes_dropped << "; bytes/s per UAV p50 " << m.bytes_per_s_p50
            << " max " << m.bytes_per_s_max << "; age of received changes p50 " << m.age_s_p50 << " s max " << m.age_s_max
            << " s; merge median " << m.merge_ms_median << " ms p99 " << m.merge_ms_p99 << " ms\n";
}

int runOne(const Args& args, Loaded& L, std::uint64_t seed, double duration, const std::string& dir, bool plot,
           sim::MissionMetrics* metrics_out) {
  if (!makeDir(dir)) return badInput(args, dir + ": cannot create directory");
  sim::MissionWorld world;
  world.map = L.map.get();
  world.field = L.field.get();
  world.ground_height_m = L.scenario.ground.enabled ? L.scenario.ground.height_m : -1e9;
  world.solids = &L.solids;
  // The unmapped obstacles and the UAVs' live maps: a fresh site per run (site_mapping.hpp).
  std::unique_ptr<sim::SiteMapping> site;
  if (!L.unmapped.empty() || L.mission.mapping.enabled) {
    auto made = sim::SiteMapping::create(L.mission, L.scenario.map, L.map, L.solids, world.ground_height_m, L.unmapped);
    if (!made) return badInput(args, made.reason());
    site = std::move(*made);
    if (L.rendered && L.mission.mapping.enabled) site->useOfferedDepth();  // the live maps integrate the rendered depth images
    world.site = site.get();
  }
  const auto planners = site ? site->plannerFactory(L.mission.planner, L.map, L.field)
                             : sim::uavPlannerFactory(L.mission.planner, L.map, L.field);
  std::unique_ptr<sim::RenderedCamera> camera;
  if (L.rendered) {
    int rc = kExitOk;
    const std::string video = args.has("camera-video") ? videoDirFor(args.get("camera-video"), dir, args.has("seeds")) : "";
    camera = makeRenderedCamera(args, L, seed, video, rc);
    if (!camera) return rc;
    std::cout << "seed " << seed << ": rendered camera (" << camera->glRenderer() << "), " << L.mission.camera.rate_hz
              << " frames/s per UAV" << (video.empty() ? "" : ", video in " + video) << "\n";
  }
  const auto out = sim::runMission(L.mission, world, planners, L.classifier.get(), seed, duration, camera.get());
  if (!out) return badInput(args, out.reason());
  const auto& m = out->metrics;
  std::string err;
  if (!sim::writeMissionFiles(dir, *out, L.mission.formation.params.uavCount(), true, &err)) return badInput(args, err);
  if (!writeText(dir + "/scene.json", sceneJson(L.scenario))) return badInput(args, dir + "/scene.json: write failed");
  std::cout << std::fixed << std::setprecision(2) << "seed " << seed << ": " << m.sim_time_s << " s simulated in "
            << m.wall_time_s << " s wall: real-time factor " << m.real_time_factor << "x\n"
            << "  min mutual " << m.min_mutual_distance_m << " m, min obstacle " << m.min_obstacle_distance_m
            << " m, min human " << m.min_human_distance_m << " m, collisions " << m.collisions << "\n"
            << "  requests applied " << m.requests_applied << "/" << m.requests_total << " (operator "
            << m.operator_requests_applied << "/" << L.mission.requests.size() << ", gestures "
            << m.gesture_requests_applied << "/" << m.gestures_performed << "), gesture success "
            << m.gesture_success_rate << ", latency " << m.gesture_mean_latency_s << " s, false adaptations "
            << m.false_adaptations << "\n"
            << "  distance error rms " << m.distance_error_rms_m << " m, angle error rms " << m.angle_error_rms_deg
            << " deg, estimate error rms " << m.human_estimate_error_rms_m << " m, planning median "
            << m.planning_ms_median << " ms p99 " << m.planning_ms_p99 << " ms max " << m.planning_ms_max
            << " ms (fallback previous "
            << m.plans_fallback_previous << ", brake " << m.plans_fallback_brake << " of " << m.plans
            << ", QP sparse timeouts " << m.qp_sparse_timeouts << ")\n"
            << "  faults: hold plans " << m.plans_hold << ", skipped " << m.plans_skipped << ", stale commands "
            << m.commands_stale << ", duplicate commands " << m.commands_duplicate << ", range outliers "
            << m.range_outliers << ", inter-UAV messages " << m.messages_sent << " (lost " << m.messages_lost
            << ", duplicated " << m.messages_duplicated << ", reordered " << m.messages_reordered << ")\n";
  if (m.perception) printPerception(*m.perception);
  if (m.site_mapping) printSiteMapping(*m.site_mapping);
  if (camera && !camera->error().empty()) {
    std::cerr << "gfctl simulate: --camera rendered: a frame failed: " << camera->error() << "\n";
    return kExitNoRenderer;
  }
  {
    std::vector<std::pair<int, std::string>> reasons;
    for (const auto& [why, count] : m.plan_failure_reasons) reasons.emplace_back(count, why);
    std::sort(reasons.rbegin(), reasons.rend());
    for (std::size_t i = 0; i < reasons.size() && i < 5; ++i) {
      std::cout << "  failed replannings: " << reasons[i].first << " x " << reasons[i].second << "\n";
    }
  }
  if (plot) {
    const std::string cmd = plotCommand(dir);
    if (cmd.empty()) {
      std::cout << "  timeline.png not drawn: run  /opt/gesture_formation/venv/bin/python tools/plot_timeline.py "
                << dir << "  (needs matplotlib; tools/setup.sh installs the venv)\n";
    } else if (std::system((cmd + " > /dev/null").c_str()) != 0) {
      std::cout << "  timeline.png: the plot script failed: " << cmd << "\n";
    } else {
      std::cout << "  wrote " << dir << "/timeline.png\n";
    }
  }
  if (metrics_out) *metrics_out = m;
  return kExitOk;
}

/// --mapping / --no-prior-map (after the mission is loaded); the problem or empty.
std::string applyMappingOptions(const Args& args, Loaded& L) {
  if (args.has("mapping")) {
    const std::string v = args.get("mapping");
    if (v != "on" && v != "off") return "--mapping: expected on or off, got '" + v + "'";
    L.mission.mapping.enabled = v == "on";
  }
  if (args.has("no-prior-map")) {
    if (!L.mission.mapping.enabled) return "--no-prior-map needs mapping (mission.mapping.enabled or --mapping on)";
    L.mission.mapping.prior_map = false;
  }
  if (args.has("map-share")) {
    const std::string v = args.get("map-share");
    if (v != "on" && v != "off") return "--map-share: expected on or off, got '" + v + "'";
    if (v == "on" && !L.mission.mapping.enabled) return "--map-share on needs mapping (mission.mapping.enabled or --mapping on)";
    L.mission.mapping.live.share.enabled = v == "on";
  }
  return "";
}

/// --camera synthetic|rendered and the options only the rendered camera takes; the problem or empty.
std::string checkCameraOptions(const Args& args, const std::string& mode) {
  if (mode != "synthetic" && mode != "rendered") return "--camera: expected synthetic or rendered, got '" + mode + "'";
  if (mode == "rendered") return "";
  for (const char* o : {"camera-rate", "camera-video", "models"}) {
    if (args.has(o)) return std::string("--") + o + " needs --camera rendered";
  }
  return "";
}

/// --camera rendered: the camera rate (--camera-rate may lower it), the rectified camera, the
/// models folder. Returns the problem, empty when fine.
std::string setUpRendered(const Args& args, Loaded& L) {
  L.rendered = true;
  if (args.has("camera-rate")) {
    const auto hz = common::parseDouble(args.get("camera-rate"));
    const double max_hz = L.mission.camera.rate_hz;
    // Below 1 / LeaderCamera::kSkeletonGapS every frame would start a new FIFO.
    if (!hz || !(*hz >= 3.0 && *hz <= max_hz)) {
      return "--camera-rate: expected frames/s in [3, " + formatDouble(max_hz) + "] (the mission's camera.rate_hz), got '" +
             args.get("camera-rate") + "'";
    }
    L.mission.camera.rate_hz = *hz;
  }
  // The rendered image is the rectified one: the estimator gets the camera without distortion.
  auto& d = L.mission.estimator.camera.distortion;
  if (std::any_of(d.begin(), d.end(), [](double k) { return k != 0.0; })) {
    std::cerr << "gfctl simulate: note: --camera rendered: the rendered images are rectified; the estimator uses "
                 "mission.estimator.camera without its distortion\n";
    d.fill(0.0);
  }
  L.camera.models_root = modelsRoot(args);
  return "";
}

int cmdSimulate(const Args& args) {
  if (!checkOptions(args, {"scenario", "out"}, {"seed", "seeds", "duration", "model", "no-plot", "faults", "fault-profile", "threads",
                                                 "camera", "camera-rate", "camera-video", "models", "mapping", "map-share",
                                                 "no-prior-map"})) {
    return kExitBadInput;
  }
  const std::string camera_mode = args.get("camera", "synthetic");
  if (const std::string bad = checkCameraOptions(args, camera_mode); !bad.empty()) return badInput(args, bad);
  // A mission's simulation is one thread by design (deterministic; batches and the fault matrix
  // run missions in parallel processes); only the views of a camera frame are classified
  // concurrently (--threads: one network per thread, as each UAV classifies on its own
  // computer; the same values). OpenCV's own thread pool only adds synchronisation to the small
  // LSTM: one thread is ~5 % less CPU per mission, results unchanged (docs/simulation.md §3).
  cv::setNumThreads(1);
  std::uint64_t threads_arg = 0;
  if (args.has("threads") && (!parseUint(args.get("threads"), threads_arg) || threads_arg < 1 ||
                              threads_arg > static_cast<std::uint64_t>(sim::kMaxClassifierThreads))) {
    return badInput(args, "--threads: expected an integer 1.." + std::to_string(sim::kMaxClassifierThreads) + ", got '" +
                              args.get("threads") + "'");
  }
  std::uint64_t seed = 1, seed_lo = 0, seed_hi = 0;
  bool batch = false;
  if (args.has("seed") && !parseUint(args.get("seed"), seed)) return badInput(args, "--seed: expected a non-negative integer, got '" + args.get("seed") + "'");
  if (args.has("seeds")) {
    const std::string s = args.get("seeds");
    const auto dots = s.find("..");
    if (dots == std::string::npos || !parseUint(s.substr(0, dots), seed_lo) || !parseUint(s.substr(dots + 2), seed_hi) ||
        seed_hi < seed_lo) {
      return badInput(args, "--seeds: expected A..B with A <= B, got '" + s + "'");
    }
    if (args.has("seed")) return badInput(args, "--seed and --seeds are exclusive");
    batch = true;
  }
  double duration = 0.0;
  if (args.has("duration")) {
    const auto d = common::parseDouble(args.get("duration"));
    if (!d || !(*d > 0.0) || !std::isfinite(*d)) return badInput(args, "--duration: expected seconds > 0, got '" + args.get("duration") + "'");
    duration = *d;
  }
  const std::string path = args.get("scenario");
  Loaded L;
  auto sc = planning::loadScenario(path);
  if (args.has("faults") && args.has("fault-profile")) return badInput(args, "--faults and --fault-profile are exclusive");
  std::string faults_path;
  if (args.has("faults")) faults_path = args.get("faults");
  if (args.has("fault-profile")) {
    const std::string name = args.get("fault-profile");
    if (name.empty() || name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_-") != std::string::npos) {
      return badInput(args, "--fault-profile: expected a name of [a-z0-9_-], got '" + name + "'");
    }
    const auto slash = path.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash);
    faults_path = dir + "/../faults/" + name + ".yaml";
    if (!fileExists(faults_path)) return badInput(args, "--fault-profile: " + faults_path + " does not exist");
  }
  auto mission = faults_path.empty() ? sim::loadMissionConfig(path) : sim::loadMissionConfig(path, faults_path);
  auto unmapped = sim::loadUnmappedObstacles(path);  // unmapped_obstacles: in the world, not in the prior map
  if (!sc || !mission || !unmapped) {
    std::cerr << "gfctl simulate: invalid scenario:\n" << (sc ? "" : sc.reason()) << (mission ? "" : mission.reason())
              << (unmapped ? "" : unmapped.reason());
    return kExitBadInput;
  }
  L.unmapped = std::move(*unmapped);
  L.scenario = std::move(*sc);
  L.solids = L.scenario.primitives();
  L.mission = std::move(*mission);
  if (std::string bad = applyMappingOptions(args, L); !bad.empty()) return badInput(args, bad);
  if (const std::string bad = camera_mode == "rendered" ? setUpRendered(args, L) : ""; !bad.empty()) return badInput(args, bad);
  const std::string model = args.has("model") ? args.get("model") : L.mission.gesture_model;
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int threads = threads_arg > 0 ? static_cast<int>(threads_arg)
                                      : std::clamp(L.mission.formation.params.uavCount(), 1, std::min(cores, sim::kMaxClassifierThreads));
  L.camera.threads = threads;  // --camera rendered: the UAVs' perception pipelines of a frame, too
  if (!model.empty()) {
    auto c = sim::loadOnnxClassifier(model, threads);
    if (!c) return badInput(args, model + ": cannot load the gesture model: " + c.reason());
    L.classifier = std::move(*c);
  } else {
    std::cerr << "gfctl simulate: warning: no mission.gesture_model: gestures are not recognised\n";
  }
  for (const auto& w : sim::gestureReadabilityWarnings(L.mission)) std::cerr << "gfctl simulate: warning: " << w << "\n";
  const auto t0 = std::chrono::steady_clock::now();
  auto map = planning::OccupancyMap::fromScenario(L.scenario);
  if (!map) return badInput(args, path + ": map: " + map.reason());
  L.map = std::make_shared<const planning::OccupancyMap>(std::move(*map));
  L.field = std::make_shared<const planning::DistanceField>(*L.map);
  std::cout << "map and distance field: " << std::fixed << std::setprecision(2)
            << std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() << " s\n";
  const std::string out = args.get("out");
  const bool plot = !args.has("no-plot");
  if (!batch) return runOne(args, L, seed, duration, out, plot, nullptr);

  std::vector<sim::MissionMetrics> all;
  for (std::uint64_t s = seed_lo; s <= seed_hi; ++s) {
    sim::MissionMetrics m;
    const int rc = runOne(args, L, s, duration, out + "/seed_" + std::to_string(s), false, &m);
    if (rc != kExitOk) return rc;
    all.push_back(m);
  }
  const std::vector<std::pair<const char*, double sim::MissionMetrics::*>> dkeys = {
      {"min_mutual_distance_m", &sim::MissionMetrics::min_mutual_distance_m},
      {"min_obstacle_distance_m", &sim::MissionMetrics::min_obstacle_distance_m},
      {"min_human_distance_m", &sim::MissionMetrics::min_human_distance_m},
      {"distance_error_rms_m", &sim::MissionMetrics::distance_error_rms_m},
      {"angle_error_rms_deg", &sim::MissionMetrics::angle_error_rms_deg},
      {"gesture_success_rate", &sim::MissionMetrics::gesture_success_rate},
      {"gesture_mean_latency_s", &sim::MissionMetrics::gesture_mean_latency_s},
      {"planning_ms_median", &sim::MissionMetrics::planning_ms_median},
      {"planning_ms_p99", &sim::MissionMetrics::planning_ms_p99},
      {"planning_ms_max", &sim::MissionMetrics::planning_ms_max},
      {"human_estimate_error_rms_m", &sim::MissionMetrics::human_estimate_error_rms_m},
      {"real_time_factor", &sim::MissionMetrics::real_time_factor}};
  const std::vector<std::pair<const char*, int sim::MissionMetrics::*>> ikeys = {
      {"collisions", &sim::MissionMetrics::collisions},
      {"requests_applied", &sim::MissionMetrics::requests_applied},
      {"false_adaptations", &sim::MissionMetrics::false_adaptations},
      {"plans_fallback_brake", &sim::MissionMetrics::plans_fallback_brake},
      {"plans_hold", &sim::MissionMetrics::plans_hold},
      {"commands_stale", &sim::MissionMetrics::commands_stale}};
  std::ostringstream js;
  js << "{\n  \"seeds\": [" << seed_lo << ", " << seed_hi << "],\n";
  std::cout << "\n" << all.size() << " seeds " << seed_lo << ".." << seed_hi << ":\n"
            << std::left << std::setw(28) << "metric" << std::right << std::setw(12) << "min" << std::setw(12) << "median"
            << std::setw(12) << "max" << "\n";
  auto row = [&](const char* name, std::vector<double> v) {
    v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
    std::sort(v.begin(), v.end());
    const double nan = std::numeric_limits<double>::quiet_NaN();
    const double lo = v.empty() ? nan : v.front(), hi = v.empty() ? nan : v.back();
    const double med = v.empty() ? nan : (v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]));
    std::cout << std::left << std::setw(28) << name << std::right << std::fixed << std::setprecision(3) << std::setw(12)
              << lo << std::setw(12) << med << std::setw(12) << hi << "\n";
    auto n = [](double x) { return std::isfinite(x) ? formatDouble(x) : std::string("null"); };
    js << "  \"" << name << "\": {\"min\": " << n(lo) << ", \"median\": " << n(med) << ", \"max\": " << n(hi) << "},\n";
  };
  for (const auto& [name, ptr] : dkeys) {
    std::vector<double> v;
    for (const auto& m : all) v.push_back(m.*ptr);
    row(name, v);
  }
  for (const auto& [name, ptr] : ikeys) {
    std::vector<double> v;
    for (const auto& m : all) v.push_back(static_cast<double>(m.*ptr));
    row(name, v);
  }
  js << "  \"runs\": " << all.size() << "\n}\n";
  writeText(out + "/summary.json", js.str());
  return kExitOk;
}

}  // namespace

}  // namespace gesture_formation::gfctl

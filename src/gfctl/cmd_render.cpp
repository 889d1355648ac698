// gfctl render --scenario FILE --t T --uav I --out frame.png [--depth depth.png] [--seed S]
//              [--truth truth.csv] [--at reference|initial] [--motion NAME] [--progress S]
//              [--outfit hivis_helmet|work_clothes] [--skin-tone N] [--models DIR]
// Renders one frame of a scenario's mission from UAV I's camera (docs/rendering.md), the
// scenario's unmapped obstacles included (where they are at T).
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "commands.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/perception/types.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/render/renderer.hpp"
#include "gesture_formation/sim/mission_config.hpp"
#include "gesture_formation/sim/scene_renderer.hpp"
#include "gesture_formation/sim/unmapped_obstacles.hpp"
#include "gesture_formation/sim/worker_model.hpp"

namespace gesture_formation::gfctl {

namespace {

int cmdRender(const Args& args);
const Registrar kRegistrar{
    "render",
    "--scenario FILE --t T --uav I --out frame.png [--depth depth.png] [--seed S] [--truth truth.csv] "
    "[--at reference|initial] [--motion NAME] [--progress S] [--outfit hivis_helmet|work_clothes] [--skin-tone N] "
    "[--models DIR]   one rendered camera frame of the mission (docs/rendering.md)",
    cmdRender};

using Eigen::Vector3d;
constexpr int kExitNoRenderer = 1;  ///< no EGL display or OpenGL 3.3 context here
using Poses = std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>>;

bool parseNonNegInt(const std::string& s, long max, long& v) {
  if (s.empty() || s.size() > 18 || s.find_first_not_of("0123456789") != std::string::npos) return false;
  v = std::stol(s);
  return v <= max;
}

std::optional<gesture::Motion> parseMotion(const std::string& name) {
  for (int m = 0; m < static_cast<int>(gesture::Motion::kCount); ++m) {
    if (name == gesture::toString(static_cast<gesture::Motion>(m))) return static_cast<gesture::Motion>(m);
  }
  return std::nullopt;
}

/// The formation's references (UAV 0 leader, then followers) around the worker's state.
std::vector<formation::UavReference> references(const sim::MissionConfig& m, const sim::WorkerState& ws) {
  const auto& wh = m.formation.worker_heading;
  const double hphi = wh.mode == formation::WorkerHeadingMode::kConstant ? wh.constant_heading_deg * M_PI / 180.0 : ws.heading_rad;
  std::vector<formation::UavReference> refs{formation::leaderReference(ws.p_world, hphi, m.formation.params.leader)};
  for (const auto& f : m.formation.params.followers) {
    refs.push_back(formation::followerReference(ws.p_world, refs[0].heading_rad, refs[0].pitch_rad, f));
  }
  return refs;
}

/// What the worker does at `t_s`: a scheduled gesture in progress (its rise/hold/lower from the
/// episode's times), else the leg's motion (walking / climbing at their cycle phase, idle at
/// work and wait). The simulator's own motion sequence (work motions, their timing) is not
/// exposed by sim::WorkerModel, so this is the render command's approximation of it.
struct WorkerAction {
  gesture::Motion motion = gesture::Motion::kIdle;
  double progress = 1.0;
  double phase_rad = 0.0;
};
WorkerAction actionAt(sim::WorkerModel& worker, const sim::MissionConfig& m, double t_s) {
  const double fps = m.worker.synth.fps;
  const long frames = std::lround(std::floor(t_s * fps));
  for (long k = 0; k <= frames; ++k) {
    const double tk = static_cast<double>(k) / fps;
    const sim::WorkerState s = worker.stateAt(tk);
    worker.skeletonAt(tk, s.p_world + Vector3d(10.0, 0.0, 2.0));  // advances the schedule only
  }
  WorkerAction a;
  for (const auto& ep : worker.episodes()) {
    if (t_s < ep.start_s || t_s > ep.end_s) continue;
    const double ramp = std::min(1.0, 0.25 * (ep.end_s - ep.start_s));
    a.motion = sim::motionOfGesture(ep.gesture_id);
    a.progress = std::clamp(std::min(t_s - ep.start_s, ep.end_s - t_s) / ramp, 0.0, 1.0);
    return a;
  }
  const sim::WorkerState s = worker.stateAt(t_s);
  if (s.kind == sim::RouteLeg::Kind::kWalk) a.motion = gesture::Motion::kWalking;
  if (s.kind == sim::RouteLeg::Kind::kClimb || s.kind == sim::RouteLeg::Kind::kDescend) a.motion = gesture::Motion::kClimbingLadder;
  a.phase_rad = 2.0 * M_PI * (a.motion == gesture::Motion::kWalking ? 0.9 : 0.45) * t_s;
  return a;
}

bool writeTruth(const std::string& path, const render::WorkerTruth& t) {
  std::ofstream f(path);
  if (!f) return false;
  f << "keypoint,u_px,v_px,depth_m,in_image,visible\n";
  const auto& names = perception::cocoKeypointNames();
  for (int k = 0; k < gesture::kNumKeypoints; ++k) {
    const auto& p = t.keypoints[static_cast<std::size_t>(k)];
    f << names[static_cast<std::size_t>(k)] << ',' << p.uv_px.x() << ',' << p.uv_px.y() << ',' << p.depth_m << ','
      << (p.in_image ? 1 : 0) << ',' << (p.visible ? 1 : 0) << '\n';
  }
  f << "box,u=" << t.visible_box_px.x << ",v=" << t.visible_box_px.y << ",w=" << t.visible_box_px.width
    << ",h=" << t.visible_box_px.height << ",pixels=" << t.visible_pixels << '\n';
  return static_cast<bool>(f);
}

int cmdRender(const Args& args) {
  if (!checkOptions(args, {"scenario", "t", "uav", "out"},
                    {"depth", "seed", "truth", "at", "motion", "progress", "outfit", "skin-tone", "models"})) {
    return kExitBadInput;
  }
  const auto t = common::parseDouble(args.get("t"));
  if (!t || !std::isfinite(*t) || *t < 0.0) return badInput(args, "--t: expected a time >= 0 [s], got '" + args.get("t") + "'");
  long uav = 0, seed = 1, skin = -1;
  if (!parseNonNegInt(args.get("uav"), 64, uav)) return badInput(args, "--uav: expected a UAV index, got '" + args.get("uav") + "'");
  if (args.has("seed") && !parseNonNegInt(args.get("seed"), 1L << 40, seed)) return badInput(args, "--seed: expected a non-negative integer, got '" + args.get("seed") + "'");
  if (args.has("skin-tone") && !parseNonNegInt(args.get("skin-tone"), 5, skin)) return badInput(args, "--skin-tone: expected 0..5, got '" + args.get("skin-tone") + "'");
  const std::string at = args.get("at", "reference");
  if (at != "reference" && at != "initial") return badInput(args, "--at: expected reference or initial, got '" + at + "'");
  std::optional<gesture::Motion> motion;
  if (args.has("motion") && !(motion = parseMotion(args.get("motion")))) return badInput(args, "--motion: unknown motion '" + args.get("motion") + "'");
  std::optional<double> progress;
  if (args.has("progress")) {
    progress = common::parseDouble(args.get("progress"));
    if (!progress || !(*progress >= 0.0 && *progress <= 1.0)) return badInput(args, "--progress: expected 0..1, got '" + args.get("progress") + "'");
  }
  render::Appearance look = render::Appearance::fromSeed(static_cast<std::uint64_t>(seed));
  if (args.has("outfit")) {
    const std::string o = args.get("outfit");
    if (o == render::toString(render::Outfit::kHiVisHelmet)) look.outfit = render::Outfit::kHiVisHelmet;
    else if (o == render::toString(render::Outfit::kWorkClothes)) look.outfit = render::Outfit::kWorkClothes;
    else return badInput(args, "--outfit: expected hivis_helmet or work_clothes, got '" + o + "'");
  }
  if (skin >= 0) look.skin_tone = static_cast<int>(skin);

  const std::string path = args.get("scenario");
  auto scenario = planning::loadScenario(path);
  if (!scenario) return badInput(args, scenario.reason());
  auto mission = sim::loadMissionConfig(path);
  if (!mission) return badInput(args, mission.reason());
  auto unmapped = sim::loadUnmappedObstacles(path);
  if (!unmapped) return badInput(args, unmapped.reason());
  const sim::MissionConfig& m = *mission;
  if (uav >= static_cast<long>(m.uavs.size())) {
    return badInput(args, "--uav: " + std::to_string(uav) + " but " + path + " has " + std::to_string(m.uavs.size()) + " UAVs (0 = leader)");
  }

  // the worker at T and the formation around it
  sim::WorkerModel worker(m.worker, static_cast<std::uint64_t>(seed));
  WorkerAction action = actionAt(worker, m, *t);
  if (motion) action.motion = *motion, action.phase_rad = 0.0;
  if (progress) action.progress = *progress;
  const sim::WorkerState ws = worker.stateAt(*t);
  gesture::SynthConfig body_config = m.worker.synth;
  body_config.height_min_m = body_config.height_max_m = m.worker.height_m;
  gesture::SkeletonSynthesizer body(body_config, static_cast<std::uint64_t>(seed));
  body.generate(action.motion);  // draws the body's proportions
  const auto joints = render::WorkerJoints::fromBody(body.pose(action.motion, action.progress, action.phase_rad, true),
                                                     ws.feet_world, ws.heading_rad);
  const auto refs = references(m, at == "initial" ? worker.stateAt(0.0) : ws);
  if (static_cast<std::size_t>(uav) >= refs.size()) return badInput(args, "--uav: the formation has " + std::to_string(refs.size()) + " UAVs");
  Poses bodies;
  for (std::size_t i = 0; i < refs.size() && i < m.uavs.size(); ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = at == "initial" ? m.uavs[i].initial_position.value_or(refs[i].p_world) : refs[i].p_world;
    T.linear() = Eigen::AngleAxisd(refs[i].heading_rad, Vector3d::UnitZ()).toRotationMatrix();
    bodies.push_back(T);
  }
  const auto& me = refs[static_cast<std::size_t>(uav)];
  render::CameraView cam;
  cam.intrinsics = m.estimator.camera;
  cam.intrinsics.distortion.fill(0.0);  // the rendered image is the rectified one
  cam.T_world_camera = render::cameraPoseFromHeadingPitch(bodies[static_cast<std::size_t>(uav)].translation(), me.heading_rad, me.pitch_rad);

  render::RendererConfig rc;
  rc.worker_asset_path = modelsRoot(args) + "/mannequin/wooden_mannequin.glb";
  auto renderer = render::Renderer::create(rc);
  if (!renderer && renderer.reason().rfind("worker asset", 0) == 0) return badInput(args, renderer.reason());
  if (!renderer) {  // no EGL display / OpenGL context: not the input's fault
    std::cerr << "gfctl render: " << renderer.reason() << "\n";
    return kExitNoRenderer;
  }
  auto r = (*renderer)->setWorld(*scenario);
  if (r) r = (*renderer)->setSiteObstacles(sim::unmappedObstaclesMesh(*unmapped, *t));  // in the world, not in the prior map
  if (r) r = (*renderer)->setWorker(joints, m.worker.height_m, look);
  if (!r) return badInput(args, r.reason());
  (*renderer)->setUavs(bodies);
  auto frame = (*renderer)->render(cam, static_cast<std::size_t>(uav));
  if (!frame) return badInput(args, frame.reason());

  cv::Mat bgr;
  cv::cvtColor(frame->rgb, bgr, cv::COLOR_RGB2BGR);
  if (!cv::imwrite(args.get("out"), bgr)) return badInput(args, "--out: cannot write " + args.get("out"));
  if (args.has("depth")) {
    cv::Mat mm(frame->depth_m.size(), CV_16UC1);  // millimetres, 0 = nothing (the RealSense convention)
    frame->depth_m.forEach<float>([&](const float& d, const int* pos) {
      mm.at<std::uint16_t>(pos[0], pos[1]) = std::isfinite(d) ? cv::saturate_cast<std::uint16_t>(d * 1000.0f) : 0;
    });
    if (!cv::imwrite(args.get("depth"), mm)) return badInput(args, "--depth: cannot write " + args.get("depth"));
  }
  if (args.has("truth") && !writeTruth(args.get("truth"), frame->worker)) return badInput(args, "--truth: cannot write " + args.get("truth"));
  const Vector3d to_worker = ws.p_world - cam.T_world_camera.translation();
  const auto& b = frame->worker.visible_box_px;
  std::cout << "render: " << path << " t=" << *t << " s uav " << uav << " (" << m.uavs[static_cast<std::size_t>(uav)].name
            << ") at " << cam.T_world_camera.translation().transpose() << ", " << to_worker.norm() << " m from the worker; worker "
            << gesture::toString(action.motion) << " progress " << action.progress << ", outfit " << render::toString(look.outfit)
            << ", skin tone " << look.skin_tone << "; box " << b.x << "," << b.y << " " << b.width << "x" << b.height << " ("
            << frame->worker.visible_pixels << " px); " << (*renderer)->glRenderer() << "\n";
  return kExitOk;
}

}  // namespace
}  // namespace gesture_formation::gfctl

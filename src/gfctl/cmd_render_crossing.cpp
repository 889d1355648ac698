// gfctl render-crossing --seed S --count N --out DIR [--appearance 0|1] [--choose 0|1] [--models DIR]
// Two people on rendered frames (docs/perception.md "Identity by appearance", issue 35 item 4): the
// worker stands performing a motion (gesture or work motion) while a second person — the same
// mannequin, other clothes — walks across the camera's view, in front of the worker (hiding it) or
// behind it. One static camera per scene at 6-12 m, 0-25 deg above, within +-40 deg of the
// worker's front; the pixels go through the real perception pipeline (MoveNet multipose ⇄ KCF →
// MoveNet lightning) with the tracker's appearance cue on or off (--appearance). With --choose 1
// (default) the operator chooses the worker at the first detection round (WorkerTracker::selectWorker
// at the centre of the worker's visible box, as tools/gf_worker.py pick would); with 0 the tracker
// takes the best-scoring person, as at start-up.
// Per frame the reported box is matched to the truth: "worker" when its IoU with the worker's
// visible box is >= 0.3 and larger than with the walker's, "walker" when the same holds for the
// walker — an identity switch — else "none" (with --choose 1, frames before the choice could be made
// — the worker not yet detected — are "none" and counted as before_choice). Writes DIR/frames.csv (every frame) and
// DIR/scenes.csv (one row per scene: frames, worker visible, tracked on the worker, on the walker,
// ids used, first frame on the walker). --images DIR: per scene the annotated frame in which the
// walker hides most of the worker (worker's truth box green, walker's red, the tracker's box yellow
// with its id). Exit 0; 2 bad input; 1 no EGL / OpenGL here.
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <random>
#include <set>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "commands.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/gesture/skeleton_synth.hpp"
#include "gesture_formation/gesture/view_triangulation.hpp"
#include "gesture_formation/perception/perception_pipeline.hpp"
#include "gesture_formation/render/renderer.hpp"

namespace gesture_formation::gfctl {
namespace {

int cmdRenderCrossing(const Args& args);
const Registrar kRegistrar{
    "render-crossing",
    "--seed S --count N --out DIR [--appearance 0|1] [--choose 0|1] [--images DIR] [--models DIR]   a second person walks across "
    "the rendered worker; does the tracker keep the worker? (docs/perception.md)",
    cmdRenderCrossing};

constexpr int kExitNoRenderer = 1;
constexpr double kMatchIou = 0.3;

/// One scene drawn from the seed.
struct Scene {
  double distance_m = 8.0, elevation_deg = 10.0, azimuth_deg = 0.0;
  double walker_offset_m = 2.0;  ///< > 0: between the camera and the worker; < 0: behind
  double walker_speed_mps = 1.2;
  double half_path_m = 3.5;      ///< the walk runs from -half_path to +half_path across the view
  bool left_to_right = true;
  gesture::Motion worker_motion = gesture::Motion::kIdle;
};

Scene drawScene(std::mt19937_64& rng, int index) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Scene s;
  s.distance_m = 6.0 + 6.0 * u(rng);
  s.elevation_deg = 25.0 * u(rng);
  s.azimuth_deg = -40.0 + 80.0 * u(rng);
  const bool in_front = index % 2 == 0;  // alternate: hidden by the walker, then the walker behind
  s.walker_offset_m = (in_front ? 1.0 : -1.0) * (1.5 + 1.5 * u(rng));
  s.walker_speed_mps = 0.9 + 0.6 * u(rng);
  s.left_to_right = u(rng) < 0.5;
  static const gesture::Motion kMotions[] = {gesture::Motion::kIdle, gesture::Motion::kCrossArms, gesture::Motion::kToolAtWaist,
                                             gesture::Motion::kRaiseArmUp, gesture::Motion::kHoldObjectAtChest};
  s.worker_motion = kMotions[static_cast<std::size_t>(index) % 5];
  return s;
}

enum class Match { kNone, kWorker, kWalker };
const char* toString(Match m) { return m == Match::kWorker ? "worker" : m == Match::kWalker ? "walker" : "none"; }

float rectIou(const cv::Rect2f& a, const cv::Rect& b) {
  if (b.area() <= 0 || a.area() <= 0) return 0.0f;
  return perception::iou(a, cv::Rect2f(b));
}

Match matchBox(const perception::TrackStep& t, const render::RenderedFrame& f) {
  if (!t.found) return Match::kNone;
  const float w = rectIou(t.box_px, f.worker.visible_box_px);
  const float b = f.bystanders.empty() ? 0.0f : rectIou(t.box_px, f.bystanders[0].visible_box_px);
  if (w >= kMatchIou && w >= b) return Match::kWorker;
  if (b >= kMatchIou && b > w) return Match::kWalker;
  return Match::kNone;
}

/// Per-scene counts.
struct SceneResult {
  int frames = 0, worker_visible = 0, on_worker = 0, on_walker = 0, first_on_walker = -1;
  int before_choice = 0;  ///< frames before the operator could choose (the worker not yet detected)
  std::set<int> ids;
  bool chosen = false;
};

struct Run {
  render::Renderer* renderer = nullptr;
  perception::PerceptionPipeline* pipeline = nullptr;
  estimation::CameraIntrinsics intrinsics;
  bool choose = true;
  std::ofstream* frames_csv = nullptr;
  std::string images_dir;  ///< empty: no snapshots
};

/// The frame annotated: truth boxes (worker green, walker red), the tracker's box (yellow) and id.
cv::Mat annotate(const cv::Mat& bgr, const perception::TrackStep& t, const render::RenderedFrame& f, int scene, int frame) {
  cv::Mat img = bgr.clone();
  cv::rectangle(img, f.worker.visible_box_px, cv::Scalar(0, 200, 0), 1);
  if (!f.bystanders.empty()) cv::rectangle(img, f.bystanders[0].visible_box_px, cv::Scalar(0, 0, 230), 1);
  if (t.found) {
    cv::rectangle(img, cv::Rect(t.box_px), cv::Scalar(0, 230, 255), 2);
    cv::putText(img, "id " + std::to_string(t.id), cv::Point(static_cast<int>(t.box_px.x), std::max(12, static_cast<int>(t.box_px.y) - 4)),
                cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 230, 255), 1);
  }
  cv::putText(img, "scene " + std::to_string(scene) + " frame " + std::to_string(frame) + (t.found ? "" : "  worker not found"),
              cv::Point(8, 20), cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(255, 255, 255), 1);
  return img;
}

/// Renders and tracks one scene; "" or the error.
std::string runScene(Run& run, int index, const Scene& sc, const gesture::SynthSequence& worker,
                     const gesture::SynthSequence& walker, const render::Appearance& worker_look,
                     const render::Appearance& walker_look, SceneResult& res) {
  const gesture::CalibratedSkeleton cam_pose =
      gesture::cameraAround(sc.distance_m, sc.elevation_deg, sc.azimuth_deg, 0.55 * worker.height_m, run.intrinsics);
  render::CameraView cam;
  cam.intrinsics = run.intrinsics;
  cam.T_world_camera.linear() = cam_pose.R_world_camera;
  cam.T_world_camera.translation() = cam_pose.p_world_camera;
  const double a = sc.azimuth_deg * M_PI / 180.0;
  const Eigen::Vector3d towards_camera(std::cos(a), std::sin(a), 0.0);
  const Eigen::Vector3d across = (sc.left_to_right ? 1.0 : -1.0) * Eigen::Vector3d(-std::sin(a), std::cos(a), 0.0);
  const double fps = 15.0, lead_s = 1.5;
  const int frames = static_cast<int>(std::ceil((2.0 * lead_s + 2.0 * sc.half_path_m / sc.walker_speed_mps) * fps));
  const double heading = std::atan2(across.y(), across.x());
  run.pipeline->reset();
  double most_hidden = 0.0;  // the walker's box over the worker's (IoU), for the snapshot
  for (int k = 0; k < frames; ++k) {
    const double t = k / fps;
    const double along = std::clamp(-sc.half_path_m + sc.walker_speed_mps * (t - lead_s), -sc.half_path_m, sc.half_path_m);
    const Eigen::Vector3d feet = sc.walker_offset_m * towards_camera + along * across;
    const auto& wb = worker.bodies[static_cast<std::size_t>(k) % worker.bodies.size()];
    const auto& bb = walker.bodies[static_cast<std::size_t>(k) % walker.bodies.size()];
    if (auto r = run.renderer->setWorker(render::WorkerJoints::fromBody(wb, Eigen::Vector3d::Zero(), 0.0), worker.height_m, worker_look); !r) {
      return r.reason();
    }
    render::Bystander b;
    b.joints = render::WorkerJoints::fromBody(bb, feet, heading);
    b.height_m = walker.height_m;
    b.appearance = walker_look;
    if (auto r = run.renderer->setBystanders({b}); !r) return r.reason();
    auto frame = run.renderer->render(cam);
    if (!frame) return frame.reason();
    cv::Mat bgr;
    cv::cvtColor(frame->rgb, bgr, cv::COLOR_RGB2BGR);
    auto pf = run.pipeline->step(bgr);
    if (!pf) return pf.reason();
    // Until the operator's choice is made (the worker not yet detected) the tracker runs on its
    // start-up default; those frames, and the one of the choice, are counted apart.
    const bool waiting = run.choose && !res.chosen;
    if (run.choose && !res.chosen && pf->track.detector_ran && frame->worker.visible_pixels > 0) {
      const cv::Rect& wb_px = frame->worker.visible_box_px;
      const auto chosen = run.pipeline->tracker().selectWorker(cv::Point2f(wb_px.x + 0.5f * wb_px.width, wb_px.y + 0.5f * wb_px.height));
      res.chosen = static_cast<bool>(chosen);  // refused when no detection contains the point: try again next round
    }
    const Match m = waiting ? Match::kNone : matchBox(pf->track, *frame);
    const float hidden = frame->bystanders.empty() ? 0.0f : rectIou(cv::Rect2f(frame->bystanders[0].visible_box_px), frame->worker.visible_box_px);
    if (!run.images_dir.empty() && hidden > most_hidden) {
      most_hidden = hidden;
      cv::imwrite(run.images_dir + "/scene" + std::to_string(index) + ".png", annotate(bgr, pf->track, *frame, index, k));
    }
    ++res.frames;
    res.before_choice += waiting ? 1 : 0;
    const bool visible = !waiting && frame->worker.visible_pixels > 0;
    res.worker_visible += visible ? 1 : 0;
    res.on_worker += m == Match::kWorker ? 1 : 0;
    if (m == Match::kWalker) {
      ++res.on_walker;
      if (res.first_on_walker < 0) res.first_on_walker = k;
    }
    if (pf->track.found && !waiting) res.ids.insert(pf->track.id);
    const cv::Rect2f& tb = pf->track.box_px;
    const cv::Rect& wt = frame->worker.visible_box_px;
    const cv::Rect& bt = frame->bystanders.empty() ? cv::Rect() : frame->bystanders[0].visible_box_px;
    *run.frames_csv << index << ',' << k << ',' << (pf->track.found ? 1 : 0) << ',' << pf->track.id << ',' << tb.x << ',' << tb.y
                    << ',' << tb.width << ',' << tb.height << ',' << wt.x << ',' << wt.y << ',' << wt.width << ',' << wt.height << ','
                    << bt.x << ',' << bt.y << ',' << bt.width << ',' << bt.height << ',' << toString(m) << ','
                    << common::formatDouble(pf->track.similarity) << ',' << (pf->track.reidentified ? 1 : 0) << '\n';
  }
  return "";
}

int cmdRenderCrossing(const Args& args) {
  if (!checkOptions(args, {"seed", "count", "out"}, {"appearance", "choose", "images", "models"})) return kExitBadInput;
  const auto seed = common::parseDouble(args.get("seed"));
  const auto count = common::parseDouble(args.get("count"));
  if (!seed || *seed < 0 || *seed > 1e15 || *seed != std::floor(*seed)) {
    return badInput(args, "--seed: expected a non-negative integer, got '" + args.get("seed") + "'");
  }
  if (!count || *count < 1 || *count > 1000 || *count != std::floor(*count)) {
    return badInput(args, "--count: expected an integer in [1, 1000], got '" + args.get("count") + "'");
  }
  const auto flag = [&](const char* key, bool fallback, bool& out) {
    if (!args.has(key)) return (out = fallback, true);
    const std::string v = args.get(key);
    if (v != "0" && v != "1") return false;
    out = v == "1";
    return true;
  };
  bool appearance = true, choose = true;
  if (!flag("appearance", true, appearance)) return badInput(args, "--appearance: expected 0 or 1, got '" + args.get("appearance") + "'");
  if (!flag("choose", true, choose)) return badInput(args, "--choose: expected 0 or 1, got '" + args.get("choose") + "'");
  const std::string dir = args.get("out"), models = modelsRoot(args);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) return badInput(args, dir + ": cannot create directory");
  render::RendererConfig rc;
  rc.worker_asset_path = models + "/mannequin/wooden_mannequin.glb";
  auto renderer = render::Renderer::create(rc);
  if (!renderer && renderer.reason().rfind("worker asset", 0) == 0) return badInput(args, renderer.reason());
  if (!renderer) {
    std::cerr << "gfctl render-crossing: " << renderer.reason() << "\n";
    return kExitNoRenderer;
  }
  if (auto r = (*renderer)->setWorldMesh(render::TriangleMesh{}, 0.0, Eigen::Vector3d::Zero()); !r) return badInput(args, r.reason());
  (*renderer)->setUavs({});
  perception::PerceptionConfig pc;
  pc.models_root = models;
  pc.tracker.appearance.enabled = appearance ? 1 : 0;
  auto pipeline = perception::PerceptionPipeline::create(pc);
  if (!pipeline) return badInput(args, pipeline.reason() + " (models root: " + models + ")");
  std::ofstream frames_csv(dir + "/frames.csv"), scenes_csv(dir + "/scenes.csv");
  if (!frames_csv || !scenes_csv) return badInput(args, dir + ": cannot write frames.csv / scenes.csv");
  frames_csv << "scene,frame,found,id,u,v,w,h,worker_u,worker_v,worker_w,worker_h,walker_u,walker_v,walker_w,walker_h,match,"
                "similarity,reidentified\n";
  scenes_csv << "scene,worker_motion,distance_m,elevation_deg,azimuth_deg,walker_offset_m,walker_speed_mps,frames,worker_visible,"
                "on_worker,on_walker,first_on_walker,ids,chosen,before_choice,appearance\n";
  gesture::SynthConfig synth_cfg;
  synth_cfg.camera.distortion.fill(0.0);
  gesture::SkeletonSynthesizer synth(synth_cfg, static_cast<std::uint64_t>(*seed));
  std::seed_seq ss{static_cast<std::uint64_t>(*seed), std::uint64_t{0xc4055u}};
  std::mt19937_64 rng(ss);
  Run run{renderer->get(), pipeline->get(), synth_cfg.camera, choose, &frames_csv, args.has("images") ? args.get("images") : ""};
  if (!run.images_dir.empty()) {
    std::filesystem::create_directories(run.images_dir, ec);
    if (ec || !std::filesystem::is_directory(run.images_dir)) return badInput(args, "--images: " + run.images_dir + ": cannot create directory");
  }
  const auto t0 = std::chrono::steady_clock::now();
  int switched = 0;
  for (int i = 0; i < static_cast<int>(*count); ++i) {
    const Scene sc = drawScene(rng, i);
    const gesture::SynthSequence worker = synth.generate(sc.worker_motion);
    const gesture::SynthSequence walker = synth.generate(gesture::Motion::kWalking);
    const std::uint64_t base = static_cast<std::uint64_t>(*seed) * 1000003ULL + 2ULL * static_cast<std::uint64_t>(i);
    SceneResult res;
    if (const std::string e = runScene(run, i, sc, worker, walker, render::Appearance::fromSeed(base),
                                       render::Appearance::fromSeed(base + 1), res);
        !e.empty()) {
      return badInput(args, "scene " + std::to_string(i) + ": " + e);
    }
    switched += res.on_walker > 0 ? 1 : 0;
    const auto f = [](double x) { return common::formatDouble(x); };
    scenes_csv << i << ',' << gesture::toString(sc.worker_motion) << ',' << f(sc.distance_m) << ',' << f(sc.elevation_deg) << ','
               << f(sc.azimuth_deg) << ',' << f(sc.walker_offset_m) << ',' << f(sc.walker_speed_mps) << ',' << res.frames << ','
               << res.worker_visible << ',' << res.on_worker << ',' << res.on_walker << ',' << res.first_on_walker << ','
               << res.ids.size() << ',' << (res.chosen ? 1 : 0) << ',' << res.before_choice << ',' << (appearance ? 1 : 0) << '\n';
    scenes_csv.flush();
    std::cout << "render-crossing: scene " << i + 1 << "/" << *count << " (" << (sc.walker_offset_m > 0 ? "in front" : "behind")
              << ", " << gesture::toString(sc.worker_motion) << ", " << f(sc.distance_m) << " m): on the worker " << res.on_worker
              << "/" << res.worker_visible << " visible frames, on the walker " << res.on_walker << ", ids " << res.ids.size()
              << "\n"
              << std::flush;
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cout << "gfctl render-crossing: " << *count << " scenes, identity on the walker in " << switched << " (appearance "
            << (appearance ? "on" : "off") << ", operator's choice " << (choose ? "on" : "off") << "), "
            << common::formatDouble(wall_s) << " s -> " << dir << "\n";
  return kExitOk;
}

}  // namespace
}  // namespace gesture_formation::gfctl

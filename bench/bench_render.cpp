// Rendering (docs/rendering.md; issue 32 "Done when"): the time to render one 640×480 colour +
// depth frame of the worker and a tower — the power-tower scenario's world (two lattice towers,
// cross-arms, insulators, conductors), the worker at height beside the west tower performing a
// gesture, seen from the leader's formation reference 10 m away — on this machine's CPU cores
// through Mesa's llvmpipe. Every benchmark records the wall time of each iteration and reports
// its median (median_ms) and 90th percentile (p90_ms); the label is the GL renderer.
//   BM_WorkerFrame: per simulation frame and camera: pose + skin the worker (CPU), upload,
//                   render, read back colour, depth and classes, compute the truth.
//   BM_RenderOnly:  the same camera without re-posing (a second UAV's camera of the same frame).
//   BM_PoseWorker:  posing and skinning the 24k-vertex mannequin alone.
// Run: tools/bench_render.sh (2 cores, writes docs/results/render.md) or build/.../gf_bench_render
#include <algorithm>
#include <cmath>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>

#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/render/renderer.hpp"
#include "gesture_formation/sim/mission_config.hpp"
#include "gesture_formation/sim/worker_model.hpp"

namespace gr = gesture_formation::render;
namespace gs = gesture_formation::sim;
namespace gg = gesture_formation::gesture;

namespace {

std::string sourceRoot() { return GF_SOURCE_DIR; }  // set by CMake

/// CPU time of the whole process (every thread: llvmpipe's rasteriser threads too) [ms].
double processCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

double ms(int64_t t0) { return static_cast<double>(cv::getTickCount() - t0) * 1000.0 / cv::getTickFrequency(); }

void report(benchmark::State& state, std::vector<double> v, std::vector<double> cpu = {}) {
  if (v.empty()) return;
  std::sort(v.begin(), v.end());
  state.counters["median_ms"] = v[v.size() / 2];
  state.counters["p90_ms"] = v[std::min(v.size() - 1, v.size() * 9 / 10)];
  if (cpu.empty()) return;
  std::sort(cpu.begin(), cpu.end());
  state.counters["cpu_median_ms"] = cpu[cpu.size() / 2];  // all threads: the load-independent cost
}

/// The scene: the renderer with the power-tower world, the worker's body and the camera.
struct Scene {
  std::unique_ptr<gr::Renderer> renderer;
  gr::CameraView camera;
  std::unique_ptr<gg::SkeletonSynthesizer> body;
  gs::WorkerState worker;
  double height_m = 1.78;
  std::size_t world_triangles = 0;
  std::string error;
};

Scene& scene() {
  static Scene s = [] {
    Scene sc;
    const std::string path = sourceRoot() + "/config/scenarios/power_towers.yaml";
    auto world = gesture_formation::planning::loadScenario(path);
    auto mission = gs::loadMissionConfig(path);
    if (!world || !mission) {
      sc.error = !world ? world.reason() : mission.reason();
      return sc;
    }
    gr::RendererConfig rc;
    rc.worker_asset_path = sourceRoot() + "/third_party_models/mannequin/wooden_mannequin.glb";
    auto r = gr::Renderer::create(rc);
    if (!r) {
      sc.error = r.reason();
      return sc;
    }
    sc.renderer = std::move(*r);
    sc.world_triangles = gr::obstacleMesh(*world).triangleCount();
    auto ok = sc.renderer->setWorld(*world);
    if (!ok) sc.error = ok.reason();
    gs::WorkerModel worker(mission->worker, 1);
    sc.worker = worker.stateAt(75.0);  // at height beside the west tower
    sc.height_m = mission->worker.height_m;
    gg::SynthConfig bc = mission->worker.synth;
    bc.height_min_m = bc.height_max_m = sc.height_m;
    sc.body = std::make_unique<gg::SkeletonSynthesizer>(bc, 1);
    sc.body->generate(gg::Motion::kExtendArmSide);
    const auto ref = gesture_formation::formation::leaderReference(sc.worker.p_world, 0.0, mission->formation.params.leader);
    sc.camera.intrinsics = mission->estimator.camera;
    sc.camera.intrinsics.distortion.fill(0.0);
    sc.camera.intrinsics.width_px = 640;
    sc.camera.intrinsics.height_px = 480;
    sc.camera.T_world_camera = gr::cameraPoseFromHeadingPitch(ref.p_world, ref.heading_rad, ref.pitch_rad);
    return sc;
  }();
  return s;
}

gr::WorkerJoints jointsAt(const Scene& s, double progress) {
  return gr::WorkerJoints::fromBody(s.body->pose(gg::Motion::kExtendArmSide, progress, 0.0, true), s.worker.feet_world,
                                    s.worker.heading_rad);
}

bool ready(benchmark::State& state) {
  if (!scene().error.empty()) {
    state.SkipWithError(scene().error.c_str());
    return false;
  }
  state.SetLabel(scene().renderer->glRenderer());
  return true;
}

void BM_WorkerFrame(benchmark::State& state) {
  if (!ready(state)) return;
  Scene& s = scene();
  const gr::Appearance look;
  std::vector<double> t, cpu;
  int i = 0, visible = 0;
  for (auto _ : state) {
    const double progress = 0.5 + 0.5 * std::sin(0.1 * i++);
    const int64_t t0 = cv::getTickCount();
    const double c0 = processCpuMs();
    auto ok = s.renderer->setWorker(jointsAt(s, progress), s.height_m, look);
    auto f = s.renderer->render(s.camera);
    t.push_back(ms(t0));
    cpu.push_back(processCpuMs() - c0);
    if (!ok || !f) return state.SkipWithError(!ok ? ok.reason().c_str() : f.reason().c_str());
    visible += f->worker.visible_pixels > 0;
    benchmark::DoNotOptimize(f->depth_m.data);
  }
  report(state, t, cpu);
  state.counters["worker_seen_pct"] = 100.0 * visible / std::max(1, i);
  state.counters["world_triangles"] = static_cast<double>(s.world_triangles);
}
BENCHMARK(BM_WorkerFrame)->Iterations(100)->Unit(benchmark::kMillisecond);

void BM_RenderOnly(benchmark::State& state) {
  if (!ready(state)) return;
  Scene& s = scene();
  auto ok = s.renderer->setWorker(jointsAt(s, 1.0), s.height_m, gr::Appearance());
  if (!ok) return state.SkipWithError(ok.reason().c_str());
  std::vector<double> t, cpu;
  for (auto _ : state) {
    const int64_t t0 = cv::getTickCount();
    const double c0 = processCpuMs();
    auto f = s.renderer->render(s.camera);
    t.push_back(ms(t0));
    cpu.push_back(processCpuMs() - c0);
    if (!f) return state.SkipWithError(f.reason().c_str());
  }
  report(state, t, cpu);
}
BENCHMARK(BM_RenderOnly)->Iterations(100)->Unit(benchmark::kMillisecond);

void BM_PoseWorker(benchmark::State& state) {
  auto mesh = gr::WorkerMesh::load(sourceRoot() + "/third_party_models/mannequin/wooden_mannequin.glb");
  if (!mesh || !scene().body) return state.SkipWithError(!mesh ? mesh.reason().c_str() : scene().error.c_str());
  std::vector<double> t;
  int i = 0;
  for (auto _ : state) {
    const int64_t t0 = cv::getTickCount();
    auto ok = (*mesh)->pose(jointsAt(scene(), 0.5 + 0.5 * std::sin(0.1 * i++)), scene().height_m);
    t.push_back(ms(t0));
    if (!ok) return state.SkipWithError(ok.reason().c_str());
  }
  report(state, t);
}
BENCHMARK(BM_PoseWorker)->Iterations(100)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();

// Perception stages and the whole pipeline on 640×480 frames of Debian's vtest.avi
// (opencv-doc), 2 threads (cv::setNumThreads(2)). Every benchmark records the wall time of
// each iteration and reports its median (median_ms) and 90th percentile (p90_ms); frames/s
// of the pipeline = 1000 / median_ms.
//
// Then workers at 5, 10 and 15 m (bench/perception_distances.cpp): the whole pipeline on real
// frames (vtest.avi scaled so the walking woman is as tall as a worker at that distance) and on
// rendered frames (the project's renderer, the worker 5/10/15 m from the camera), the old path
// (visual tracker at full resolution) beside the new one (tracker on the shrunk frame).
// Run from anywhere: build/devel/lib/gesture_formation/gf_bench_perception
//   [--gf_results=docs/results/perception_distances.md]  (writes the distance tables there too)
#include <algorithm>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/tracking.hpp>
#include <opencv2/videoio.hpp>

#include "gesture_formation/perception/perception_pipeline.hpp"

namespace gp = gesture_formation::perception;

std::string benchModelsRoot();
/// Google Benchmark's main plus the distance tables (bench/perception_distances.cpp).
int benchPerceptionMain(int argc, char** argv);

namespace {

constexpr int kFrames = 300;  // consecutive frames of vtest.avi used (30 s at 10 fps)

}  // namespace

/// $GF_MODELS_DIR, else GF_SOURCE_DIR/third_party_models: the absolute source directory given by
/// CMake (__FILE__ is relative under ccache's base_dir, so it cannot be used to find the models).
std::string benchModelsRoot() {
  const char* env = std::getenv("GF_MODELS_DIR");
  if (env != nullptr && *env != '\0') return env;
  return std::string(GF_SOURCE_DIR) + "/third_party_models";
}

namespace {

std::string modelsRoot() { return benchModelsRoot(); }

const std::vector<cv::Mat>& frames() {
  static const std::vector<cv::Mat> f = [] {
    std::vector<cv::Mat> out;
    cv::VideoCapture cap("/usr/share/doc/opencv-doc/examples/data/vtest.avi");
    cv::Mat frame, small;
    while (static_cast<int>(out.size()) < kFrames && cap.read(frame)) {
      cv::resize(frame, small, cv::Size(640, 480), 0, 0, cv::INTER_AREA);
      out.push_back(small.clone());
    }
    return out;
  }();
  return f;
}

double ms(int64_t t0) { return static_cast<double>(cv::getTickCount() - t0) * 1000.0 / cv::getTickFrequency(); }

void report(benchmark::State& state, std::vector<double> v) {
  if (v.empty()) return;
  std::sort(v.begin(), v.end());
  state.counters["median_ms"] = v[v.size() / 2];
  state.counters["p90_ms"] = v[std::min(v.size() - 1, v.size() * 9 / 10)];
}

bool setup(benchmark::State& state) {
  cv::setNumThreads(2);
  if (frames().size() < 50) {
    state.SkipWithError("vtest.avi missing (Debian opencv-doc; run tools/setup.sh)");
    return false;
  }
  return true;
}

/// The worker box of frame 0 (the best multipose detection), for the per-stage benchmarks.
cv::Rect2f workerBox() {
  static const cv::Rect2f box = [] {
    auto det = gp::MoveNetMultiposeDetector::create({}, modelsRoot());
    if (!det) return cv::Rect2f(216, 176, 35, 83);
    auto d = (*det)->detect(frames()[2]);
    return d && !d->empty() ? (*d)[0].box_px : cv::Rect2f(216, 176, 35, 83);
  }();
  return box;
}

void BM_DetectMultiposeFullFrame(benchmark::State& state) {
  if (!setup(state)) return;
  auto det = gp::MoveNetMultiposeDetector::create({}, modelsRoot());
  if (!det) return state.SkipWithError(det.reason().c_str());
  std::vector<double> t;
  std::size_t i = 0;
  for (auto _ : state) {
    const int64_t t0 = cv::getTickCount();
    auto r = (*det)->detect(frames()[i++ % frames().size()]);
    t.push_back(ms(t0));
    benchmark::DoNotOptimize(r);
  }
  report(state, t);
}
BENCHMARK(BM_DetectMultiposeFullFrame)->Iterations(60)->Unit(benchmark::kMillisecond);

void BM_DetectMultiposeWindow256(benchmark::State& state) {
  if (!setup(state)) return;
  auto det = gp::MoveNetMultiposeDetector::create({}, modelsRoot());
  if (!det) return state.SkipWithError(det.reason().c_str());
  const cv::Rect2f b = workerBox();
  const cv::Rect window(std::clamp(static_cast<int>(b.x + b.width / 2) - 128, 0, 640 - 256),
                        std::clamp(static_cast<int>(b.y + b.height / 2) - 128, 0, 480 - 256), 256, 256);
  std::vector<double> t;
  std::size_t i = 0;
  for (auto _ : state) {
    const int64_t t0 = cv::getTickCount();
    auto r = (*det)->detect(frames()[i++ % frames().size()](window));
    t.push_back(ms(t0));
    benchmark::DoNotOptimize(r);
  }
  report(state, t);
}
BENCHMARK(BM_DetectMultiposeWindow256)->Iterations(60)->Unit(benchmark::kMillisecond);

void BM_DetectBlazePose(benchmark::State& state) {
  if (!setup(state)) return;
  auto det = gp::BlazePoseDetector::create({}, modelsRoot());
  if (!det) return state.SkipWithError(det.reason().c_str());
  std::vector<double> t;
  std::size_t i = 0;
  for (auto _ : state) {
    const int64_t t0 = cv::getTickCount();
    auto r = (*det)->detect(frames()[i++ % frames().size()]);
    t.push_back(ms(t0));
    benchmark::DoNotOptimize(r);
  }
  report(state, t);
}
BENCHMARK(BM_DetectBlazePose)->Iterations(60)->Unit(benchmark::kMillisecond);

/// Tracker update on consecutive frames from the worker box of frame 2 (re-init every 40).
template <class T>
void trackerBench(benchmark::State& state) {
  if (!setup(state)) return;
  const cv::Rect2f b = workerBox();
  const cv::Rect r0(cvRound(b.x), cvRound(b.y), cvRound(b.width), cvRound(b.height));
  std::vector<double> t;
  cv::Ptr<cv::Tracker> tracker;
  std::size_t i = 0;
  for (auto _ : state) {
    if (i % 40 == 0) {
      state.PauseTiming();
      tracker = T::create();
      tracker->init(frames()[2], r0);
      state.ResumeTiming();
    }
    cv::Rect r;
    const int64_t t0 = cv::getTickCount();
    const bool ok = tracker->update(frames()[3 + i % 40], r);
    t.push_back(ms(t0));
    benchmark::DoNotOptimize(ok);
    ++i;
  }
  report(state, t);
}
void BM_TrackerKcfUpdate(benchmark::State& state) { trackerBench<cv::TrackerKCF>(state); }
void BM_TrackerCsrtUpdate(benchmark::State& state) { trackerBench<cv::TrackerCSRT>(state); }
BENCHMARK(BM_TrackerKcfUpdate)->Iterations(120)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TrackerCsrtUpdate)->Iterations(120)->Unit(benchmark::kMillisecond);

template <class E, class C>
void skeletonBench(benchmark::State& state) {
  if (!setup(state)) return;
  auto ext = E::create(C{}, modelsRoot());
  if (!ext) return state.SkipWithError(ext.reason().c_str());
  const cv::Rect2f b = workerBox();
  std::vector<double> t;
  std::size_t i = 0;
  for (auto _ : state) {
    const int64_t t0 = cv::getTickCount();
    auto s = (*ext)->extract(frames()[2 + i++ % 10], b);
    t.push_back(ms(t0));
    benchmark::DoNotOptimize(s);
  }
  report(state, t);
}
void BM_SkeletonMoveNetLightning(benchmark::State& state) {
  skeletonBench<gp::MoveNetLightningExtractor, gp::MoveNetLightningConfig>(state);
}
void BM_SkeletonBlazePoseLandmark(benchmark::State& state) {
  skeletonBench<gp::BlazePoseLandmarkExtractor, gp::BlazePoseLandmarkConfig>(state);
}
BENCHMARK(BM_SkeletonMoveNetLightning)->Iterations(60)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SkeletonBlazePoseLandmark)->Iterations(60)->Unit(benchmark::kMillisecond);

/// The whole pipeline (detect every k + track + skeleton + FIFO) over consecutive frames.
/// Args: tracker (0 KCF, 1 CSRT), k, skeleton (0 lightning, 1 BlazePose landmark).
void BM_Pipeline(benchmark::State& state) {
  if (!setup(state)) return;
  gp::PerceptionConfig cfg;
  cfg.models_root = modelsRoot();
  cfg.tracker.tracker = state.range(0) == 0 ? gp::TrackerKind::kKcf : gp::TrackerKind::kCsrt;
  cfg.tracker.detect_every_k = static_cast<int>(state.range(1));
  cfg.skeleton = state.range(2) == 0 ? gp::SkeletonKind::kMoveNetLightning : gp::SkeletonKind::kBlazePoseLandmark;
  auto p = gp::PerceptionPipeline::create(cfg);
  if (!p) return state.SkipWithError(p.reason().c_str());
  std::vector<double> t;
  std::size_t i = 0, found = 0, detections = 0;
  for (auto _ : state) {
    const std::size_t f = i++ % frames().size();
    if (f == 0) (*p)->reset();
    const int64_t t0 = cv::getTickCount();
    auto r = (*p)->step(frames()[f]);
    t.push_back(ms(t0));
    if (r && r->track.found) ++found;
    if (r && r->track.detector_ran) ++detections;
  }
  report(state, t);
  double sum = 0;
  for (double v : t) sum += v;
  state.counters["mean_ms"] = sum / static_cast<double>(t.size());
  state.counters["found_pct"] = 100.0 * static_cast<double>(found) / static_cast<double>(t.size());
  state.counters["detect_pct"] = 100.0 * static_cast<double>(detections) / static_cast<double>(t.size());
}
BENCHMARK(BM_Pipeline)
    ->ArgNames({"csrt", "k", "blazelm"})
    ->Args({0, 5, 0})
    ->Args({1, 5, 0})
    ->Args({1, 10, 0})
    ->Args({1, 5, 1})
    ->Iterations(kFrames)
    ->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) { return benchPerceptionMain(argc, argv); }

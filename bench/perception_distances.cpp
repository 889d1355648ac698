// Part of gf_bench_perception (bench/bench_perception.cpp): the whole perception pipeline on a
// worker at 5, 10 and 15 m, on real and on rendered frames, the old path beside the new one in the
// same process (issue 38, docs/perception.md "Tracker cost").
//
// Size of a worker at distance d: a 1.75 m person in the default camera (D435 colour 640×480,
// fy = 615 px) is fy · 1.75 / d px tall: 215 px at 5 m, 108 px at 10 m, 72 px at 15 m.
// - Real frames: vtest.avi (Debian opencv-doc) frames 580–700, the woman whose box is labelled by hand
//   at frames 580, 610, 640, 670, 700 (test/data/perception/labels; boxes linearly interpolated in
//   between). Each frame is scaled (INTER_AREA shrinking, INTER_LINEAR enlarging) so that her box is
//   as tall as a worker at d, and a 640×480 window is cut centred on her (a camera that follows the
//   worker; beyond the video's border its edge pixels are repeated): at 5 m an enlargement ×1.4–2.0
//   of the real video, at 10 m ×0.7–1.0, at 15 m ×0.5–0.7.
// - Rendered frames: the project's renderer (src/render), the mannequin worker 5/10/15 m from a static
//   camera 8° above and 15° to the side, walking 2.4 m across the view (60 frames at 15 fps), then
//   raising an arm (60 frames); truth box = the worker's visible pixels.
// Per frame: wall time of PerceptionPipeline::step (detector every k = 5 frames, tracker, skeleton,
// FIFO), 2 threads. Old path: the visual tracker at full resolution (tracker.track_max_side_px = 0,
// the code before); new: the tracker on the frame shrunk to a box of at most 96 px (the default).
// The networks are loaded once per path and reused for every sequence.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "gesture_formation/gesture/skeleton_synth.hpp"
#include "gesture_formation/gesture/view_triangulation.hpp"
#include "gesture_formation/perception/perception_pipeline.hpp"
#include "gesture_formation/render/renderer.hpp"

namespace gp = gesture_formation::perception;
namespace gg = gesture_formation::gesture;
namespace gr = gesture_formation::render;

std::string benchModelsRoot();
int benchPerceptionMain(int argc, char** argv);

namespace {

constexpr double kWorkerHeightM = 1.75;
constexpr double kDistancesM[] = {5.0, 10.0, 15.0};
constexpr const char* kVtest = "/usr/share/doc/opencv-doc/examples/data/vtest.avi";

/// One sequence of frames with the worker's true box in each.
struct Sequence {
  std::string source;  ///< "real" or "rendered"
  double distance_m = 0.0;
  std::vector<cv::Mat> frames;
  std::vector<cv::Rect2f> truth;
  std::vector<char> judged;  ///< frames whose truth is exact (real: the hand-labelled ones; rendered: the worker visible)
};

// ---- real frames --------------------------------------------------------------------------

/// The hand-labelled boxes of vtest.avi's blonde woman (test/data/perception/labels/person_boxes.csv).
struct Label {
  int frame;
  cv::Rect2f box;
};
const Label kLabels[] = {{580, {189, 430, 67, 144}},
                         {610, {349, 427, 49, 149}},
                         {640, {337, 385, 50, 141}},
                         {670, {225, 345, 60, 123}},
                         {700, {103, 287, 39, 108}}};

cv::Rect2f labelAt(int frame) {
  for (std::size_t i = 0; i + 1 < std::size(kLabels); ++i) {
    const Label &a = kLabels[i], &b = kLabels[i + 1];
    if (frame < a.frame || frame > b.frame) continue;
    const float t = static_cast<float>(frame - a.frame) / static_cast<float>(b.frame - a.frame);
    const auto mix = [t](float x, float y) { return x + t * (y - x); };
    return {mix(a.box.x, b.box.x), mix(a.box.y, b.box.y), mix(a.box.width, b.box.width), mix(a.box.height, b.box.height)};
  }
  return kLabels[std::size(kLabels) - 1].box;
}

/// `frame` scaled by s and cut 640×480 around `centre` (frame px); `offset` = the window's corner in
/// the scaled frame.
cv::Mat cutAround(const cv::Mat& frame, double s, const cv::Point2f& centre, cv::Point& offset) {
  cv::Mat scaled;
  cv::resize(frame, scaled, cv::Size(), s, s, s < 1.0 ? cv::INTER_AREA : cv::INTER_LINEAR);
  offset = cv::Point(static_cast<int>(std::lround(centre.x * s)) - 320, static_cast<int>(std::lround(centre.y * s)) - 240);
  const int pad = 1280;
  cv::Mat padded;
  cv::copyMakeBorder(scaled, padded, pad, pad, pad, pad, cv::BORDER_REPLICATE);
  return padded(cv::Rect(offset.x + pad, offset.y + pad, 640, 480)).clone();
}

/// Frames 580–700 of vtest.avi with the woman as tall as a worker at `distance_m`; empty with a
/// reason when the video is missing.
Sequence realSequence(double distance_m, double fy_px, std::string& why_not) {
  Sequence seq;
  seq.source = "real";
  seq.distance_m = distance_m;
  cv::VideoCapture cap(kVtest);
  cv::Mat frame;
  for (int i = 0; i < kLabels[0].frame; ++i) {
    if (!cap.read(frame)) {
      why_not = std::string(kVtest) + " missing or short (Debian opencv-doc; tools/setup.sh)";
      return seq;
    }
  }
  const double height_px = fy_px * kWorkerHeightM / distance_m;
  for (int f = kLabels[0].frame; f <= kLabels[std::size(kLabels) - 1].frame && cap.read(frame); ++f) {
    const cv::Rect2f b = labelAt(f);
    const double s = height_px / b.height;
    cv::Point offset;
    seq.frames.push_back(cutAround(frame, s, {b.x + b.width / 2, b.y + b.height / 2}, offset));
    seq.truth.emplace_back(static_cast<float>(b.x * s - offset.x), static_cast<float>(b.y * s - offset.y),
                           static_cast<float>(b.width * s), static_cast<float>(b.height * s));
    seq.judged.push_back(std::any_of(std::begin(kLabels), std::end(kLabels), [f](const Label& l) { return l.frame == f; }) ? 1 : 0);
  }
  return seq;
}

// ---- rendered frames ----------------------------------------------------------------------

/// The worker 5/10/15 m from a static camera: walks 2.4 m across the view (60 frames at 15 fps), then
/// raises an arm (60 frames). Empty with a reason when the renderer cannot start (no EGL).
std::vector<Sequence> renderedSequences(const std::string& models, std::string& why_not) {
  gr::RendererConfig rc;
  rc.worker_asset_path = models + "/mannequin/wooden_mannequin.glb";
  auto renderer = gr::Renderer::create(rc);
  if (!renderer) {
    why_not = "renderer: " + renderer.reason();
    return {};
  }
  if (auto r = (*renderer)->setWorldMesh(gr::TriangleMesh{}, 0.0, Eigen::Vector3d::Zero()); !r) {
    why_not = "renderer: " + r.reason();
    return {};
  }
  (*renderer)->setUavs({});
  gg::SynthConfig synth_cfg;
  synth_cfg.camera.distortion.fill(0.0);
  gg::SkeletonSynthesizer synth(synth_cfg, 7);
  const gg::SynthSequence walk = synth.generate(gg::Motion::kWalking);
  const gg::SynthSequence raise = synth.generate(gg::Motion::kRaiseArmUp);
  const gr::Appearance look = gr::Appearance::fromSeed(7);
  constexpr double kAzimuthDeg = 15.0, kElevationDeg = 8.0, kFps = 15.0, kSpeedMps = 0.6;
  constexpr int kWalkFrames = 60, kGestureFrames = 60;
  const double a = kAzimuthDeg * M_PI / 180.0;
  const Eigen::Vector3d across(-std::sin(a), std::cos(a), 0.0);  // perpendicular to the line of sight
  std::vector<Sequence> out;
  for (const double d : kDistancesM) {
    const gg::CalibratedSkeleton pose = gg::cameraAround(d, kElevationDeg, kAzimuthDeg, 0.55 * walk.height_m, synth_cfg.camera);
    gr::CameraView cam;
    cam.intrinsics = synth_cfg.camera;
    cam.T_world_camera.linear() = pose.R_world_camera;
    cam.T_world_camera.translation() = pose.p_world_camera;
    Sequence seq;
    seq.source = "rendered";
    seq.distance_m = d;
    for (int k = 0; k < kWalkFrames + kGestureFrames; ++k) {
      const bool walking = k < kWalkFrames;
      const double along = -0.5 * kSpeedMps * kWalkFrames / kFps + kSpeedMps * std::min(k, kWalkFrames) / kFps;
      const gg::SynthSequence& motion = walking ? walk : raise;
      const auto& body = motion.bodies[static_cast<std::size_t>(walking ? k : k - kWalkFrames) % motion.bodies.size()];
      const double heading = walking ? std::atan2(across.y(), across.x()) : a;  // walking across, then facing the camera
      if (auto r = (*renderer)->setWorker(gr::WorkerJoints::fromBody(body, along * across, heading), motion.height_m, look); !r) {
        why_not = "renderer: " + r.reason();
        return {};
      }
      auto frame = (*renderer)->render(cam);
      if (!frame) {
        why_not = "renderer: " + frame.reason();
        return {};
      }
      cv::Mat bgr;
      cv::cvtColor(frame->rgb, bgr, cv::COLOR_RGB2BGR);
      seq.frames.push_back(bgr);
      seq.truth.emplace_back(frame->worker.visible_box_px);
      seq.judged.push_back(frame->worker.visible_pixels > 0 ? 1 : 0);
    }
    out.push_back(std::move(seq));
  }
  return out;
}

// ---- running the pipeline ---------------------------------------------------------------

/// Per-frame figures of one path on one sequence (all repetitions pooled).
struct PathStats {
  std::vector<double> frame_ms, tracker_ms, detection_frame_ms, skeleton_ms;
  std::vector<double> frame_cpu_ms;  ///< CPU time of the whole process per frame (both OpenCV threads)
  std::vector<double> kcf_alone_ms;  ///< ScaledTracker::update alone, from the true box (re-initialised every 10 frames)
  int frames = 0, found = 0, detections = 0;
  int judged = 0, on_worker = 0;  ///< frames with an exact truth box; of those, the worker's box overlapping it (IoU ≥ 0.5)
};

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

/// CPU time of the process [ms] (all threads): less sensitive than wall time to other programs' load.
double processCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

/// Resident set size of the process [MB] (/proc/self/status VmRSS), NaN if unreadable.
double rssMb() {
  std::ifstream f("/proc/self/status");
  std::string key;
  double kb = 0;
  while (f >> key) {
    if (key == "VmRSS:" && (f >> kb)) return kb / 1024.0;
  }
  return std::nan("");
}

double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

/// One pass over `seq` from a fresh track; the worker is designated by its true box in the first
/// frame (as the operator's choice would; vtest has other pedestrians who score higher).
void runOnce(gp::PerceptionPipeline& pipeline, const Sequence& seq, PathStats& st) {
  pipeline.reset();
  pipeline.tracker().setWorkerHint(seq.truth.front());
  for (std::size_t i = 0; i < seq.frames.size(); ++i) {
    const double cpu0 = processCpuMs();
    const auto t0 = std::chrono::steady_clock::now();
    auto r = pipeline.step(seq.frames[i]);
    const double ms = msSince(t0);
    const double cpu_ms = processCpuMs() - cpu0;
    if (!r) {
      std::cerr << "gf_bench_perception: " << seq.source << " " << seq.distance_m << " m, frame " << i << ": " << r.reason() << "\n";
      continue;
    }
    ++st.frames;
    st.frame_ms.push_back(ms);
    st.frame_cpu_ms.push_back(cpu_ms);
    if (r->has_skeleton) st.skeleton_ms.push_back(r->skeleton_ms);
    if (r->track.detector_ran) {
      ++st.detections;
      st.detection_frame_ms.push_back(ms);
    } else if (r->track.found) {
      st.tracker_ms.push_back(r->track.track_ms);
    }
    st.found += r->track.found ? 1 : 0;
    if (seq.judged[i]) {
      ++st.judged;
      if (r->track.found && gp::iou(r->track.box_px, seq.truth[i]) >= 0.5f) ++st.on_worker;
    }
  }
}

/// The visual tracker alone (KCF, as the pipeline's default) over `seq`: update times [ms].
void trackerAlone(const Sequence& seq, float max_side_px, PathStats& st) {
  gp::ScaledTracker tracker(gp::TrackerKind::kKcf, max_side_px);
  for (std::size_t i = 0; i < seq.frames.size(); ++i) {
    const cv::Rect2f& t = seq.truth[i];
    if (i % 10 == 0) {
      tracker.init(seq.frames[i], cv::Rect(cvRound(t.x), cvRound(t.y), cvRound(t.width), cvRound(t.height)));
      continue;
    }
    cv::Rect2f box;
    const auto t0 = std::chrono::steady_clock::now();
    tracker.update(seq.frames[i], box);
    st.kcf_alone_ms.push_back(msSince(t0));
  }
}

std::string fmt(double v, int digits = 1) {
  if (!std::isfinite(v)) return "–";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

std::string loadAverage() {
  std::ifstream f("/proc/loadavg");
  double one = 0, five = 0;
  f >> one >> five;
  return fmt(one, 2) + " (1 min), " + fmt(five, 2) + " (5 min)";
}

std::string cpuModel() {
  std::ifstream f("/proc/cpuinfo");
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  }
  return "unknown CPU";
}

struct Options {
  std::string results_path;  ///< --gf_results=FILE: also write the tables there
  int repeats = 3;           ///< --gf_repeats=N: passes over each sequence per path
  bool distances = true;     ///< --gf_distances=0: Google Benchmark's stages only
};

/// Takes our own --gf_* options out of argv (Google Benchmark refuses unknown ones).
Options takeOptions(int& argc, char** argv) {
  Options o;
  int out = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--gf_results=", 0) == 0) {
      o.results_path = a.substr(13);
    } else if (a.rfind("--gf_repeats=", 0) == 0) {
      o.repeats = std::clamp(std::atoi(a.c_str() + 13), 1, 20);
    } else if (a.rfind("--gf_distances=", 0) == 0) {
      o.distances = a.substr(15) != "0";
    } else {
      argv[out++] = argv[i];
    }
  }
  argc = out;
  return o;
}

struct Row {
  const Sequence* seq;
  std::string path;
  PathStats st;
};

std::string table(const std::vector<Row>& rows, const std::string& source) {
  std::ostringstream t;
  t << "| distance | worker box h [px] | path | frame median ms | p90 ms | worst ms | mean ms | frames/s (median) | "
       "frames/s (mean) | CPU ms per frame (median, both threads) | KCF update alone ms (median) | tracker ms in the pipeline (median) | detection frames median ms | skeleton ms (median) | detector ran | found | "
       "on the worker (IoU ≥ 0.5 with the truth) |\n"
    << "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n";
  for (const Row& r : rows) {
    if (r.seq->source != source) continue;
    std::vector<double> h;
    for (const auto& b : r.seq->truth) h.push_back(b.height);
    double sum = 0;
    for (double v : r.st.frame_ms) sum += v;
    const double mean = r.st.frame_ms.empty() ? std::nan("") : sum / static_cast<double>(r.st.frame_ms.size());
    const double med = quantile(r.st.frame_ms, 0.5);
    const double n = std::max(1, r.st.frames);
    t << "| " << fmt(r.seq->distance_m, 0) << " m | " << fmt(quantile(h, 0.5), 0) << " | " << r.path << " | " << fmt(med) << " | "
      << fmt(quantile(r.st.frame_ms, 0.9)) << " | " << fmt(quantile(r.st.frame_ms, 1.0)) << " | " << fmt(mean) << " | "
      << fmt(1000.0 / med, 0) << " | " << fmt(1000.0 / mean, 0) << " | " << fmt(quantile(r.st.frame_cpu_ms, 0.5)) << " | "
      << fmt(quantile(r.st.kcf_alone_ms, 0.5)) << " | "
      << fmt(quantile(r.st.tracker_ms, 0.5)) << " | "
      << fmt(quantile(r.st.detection_frame_ms, 0.5)) << " | " << fmt(quantile(r.st.skeleton_ms, 0.5)) << " | "
      << fmt(100.0 * r.st.detections / n, 0) << " % | " << fmt(100.0 * r.st.found / n, 0) << " % | "
      << r.st.on_worker << " / " << r.st.judged << " |\n";
  }
  return t.str();
}

/// Builds both paths' pipelines once, runs every sequence `repeats` times per path (old and new
/// alternating, so both see the same machine load) and returns the rows.
/// Memory of one pipeline's networks (MoveNet multipose + lightning) [MB of RSS].
struct PipelineMemory {
  double loaded_mb = std::nan(""), after_first_frame_mb = std::nan("");
};

std::vector<Row> runAll(const std::vector<Sequence>& seqs, int repeats, PipelineMemory& memory, std::string& error) {
  std::vector<Row> rows;
  const std::pair<const char*, float> paths[] = {{"old: tracker at full resolution", 0.0f},
                                                 {"**new: tracker on the frame shrunk to a box ≤ 96 px**", 96.0f}};
  std::vector<std::unique_ptr<gp::PerceptionPipeline>> pipelines;
  for (const auto& [name, side] : paths) {
    gp::PerceptionConfig cfg;
    cfg.models_root = benchModelsRoot();
    cfg.tracker.track_max_side_px = side;
    const double rss0 = rssMb();
    auto p = gp::PerceptionPipeline::create(cfg);
    if (!p) {
      error = p.reason();
      return {};
    }
    if (pipelines.empty() && !seqs.empty()) {
      memory.loaded_mb = rssMb() - rss0;
      (void)(*p)->step(seqs.front().frames.front());
      memory.after_first_frame_mb = rssMb() - rss0;
    }
    pipelines.push_back(std::move(*p));
  }
  for (const Sequence& seq : seqs) {
    for (const auto& [name, side] : paths) rows.push_back({&seq, name, {}});
    const std::size_t first = rows.size() - std::size(paths);
    PathStats warmup;  // the networks' first forward passes are 2–4× slower: not counted
    for (auto& p : pipelines) runOnce(*p, Sequence{seq.source, seq.distance_m, {seq.frames.front()}, {seq.truth.front()}, {0}}, warmup);
    for (int rep = 0; rep < repeats; ++rep) {
      for (std::size_t k = 0; k < pipelines.size(); ++k) {
        runOnce(*pipelines[k], seq, rows[first + k].st);
        trackerAlone(seq, paths[k].second, rows[first + k].st);
      }
    }
  }
  return rows;
}

int runDistances(const Options& o) {
  cv::setNumThreads(2);
  const std::string load_before = loadAverage();
  std::vector<Sequence> seqs;
  std::string real_why, rendered_why;
  const double fy = gg::SynthConfig{}.camera.fy;
  for (const double d : kDistancesM) {
    Sequence s = realSequence(d, fy, real_why);
    if (!s.frames.empty()) seqs.push_back(std::move(s));
  }
  for (auto& s : renderedSequences(benchModelsRoot(), rendered_why)) seqs.push_back(std::move(s));
  std::string error;
  PipelineMemory memory;
  const std::vector<Row> rows = runAll(seqs, o.repeats, memory, error);
  if (!error.empty()) {
    std::cerr << "gf_bench_perception: distances: " << error << "\n";
    return 1;
  }
  std::time_t now = std::time(nullptr);
  char date[32];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  std::ostringstream md;
  md << "# Perception on workers at 5, 10 and 15 m\n\n"
     << "Written by `gf_bench_perception --gf_results=...` (bench/perception_distances.cpp) on " << date << ": " << cpuModel()
     << ", OpenCV " << CV_VERSION << " DNN on the CPU, `cv::setNumThreads(2)`; load average " << load_before
     << " before the runs, " << loadAverage() << " after. Each sequence " << o.repeats
     << " passes per path (alternating), from a fresh track each time; figures over every frame of every pass. "
     << "Whole pipeline per frame: MoveNet multipose every k = 5 frames (and on tracker failure) in the window around the "
     << "worker, KCF in between, MoveNet lightning on the worker's crop, the FIFO. *Old*: KCF at full resolution (the code "
     << "before `tracker.track_max_side_px`); *new*: KCF on the frame shrunk by an integer factor so that the worker's box is at most 96 px "
     << "(the default). Worker box height: fy · 1.75 m / d with fy = 615 px (640×480 D435 colour). How the frames are made: "
     << "bench/perception_distances.cpp, first comment.\n\n"
     << "Columns: *frame* figures are whole `PerceptionPipeline::step` calls, every frame; *KCF update alone*: "
     << "`ScaledTracker::update` from the true box (re-initialised every 10 frames), the frame's shrink included; *tracker "
     << "ms in the pipeline*: on frames without a detection, the update plus the appearance check of its box; *detection "
     << "frames*: the frames in which the detector ran (detector, tracker re-initialisation, skeleton); *on the worker*: "
     << "frames with an exact truth box (real: the 5 hand-labelled frames of each pass; rendered: every frame in which the "
     << "worker is visible) in which the reported box overlaps it with IoU ≥ 0.5.\n\n"
     << "Memory: one pipeline's networks (MoveNet multipose + MoveNet lightning, each loaded once when the pipeline is "
     << "built and reused for every frame) add " << fmt(memory.loaded_mb) << " MB of resident memory when loaded, "
     << fmt(memory.after_first_frame_mb) << " MB after the first frame (OpenCV DNN's buffers).\n\n";
  md << "## Real frames (vtest.avi, the labelled woman scaled to the worker's size, 121 frames)\n\n";
  md << (real_why.empty() ? table(rows, "real") : "Not run: " + real_why + "\n") << "\n";
  md << "## Rendered frames (the mannequin walking across, then raising an arm, 120 frames)\n\n";
  md << (rendered_why.empty() ? table(rows, "rendered") : "Not run: " + rendered_why + "\n");
  std::cout << "\n" << md.str() << std::flush;
  if (!o.results_path.empty()) {
    std::ofstream f(o.results_path);
    if (!(f << md.str())) {
      std::cerr << "gf_bench_perception: cannot write " << o.results_path << "\n";
      return 1;
    }
    std::cout << "gf_bench_perception: wrote " << o.results_path << "\n";
  }
  return 0;
}

}  // namespace

int benchPerceptionMain(int argc, char** argv) {
  const Options o = takeOptions(argc, argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return o.distances ? runDistances(o) : 0;
}

// gfctl render-gestures --seed S --count N --out DIR [--config FILE] [--views D1,D2,…]
//                       [--motions M1,M2,…] [--models DIR] [--skeleton movenet_lightning|blazepose_landmark]
//                       [--frames-every N] [--window-only]
// The gesture generator's performances (gesture::SkeletonSynthesizer, the same 3-D bodies and
// timing as `gfctl synth-gestures`) RENDERED — the skinned mannequin posed every frame from the
// generator's 3-D body, dressed per sequence (render::Appearance) — from one camera per view, and
// each view's pixels put through the real perception pipeline (MoveNet multipose detector ⇄ KCF
// tracker → MoveNet lightning, or the --skeleton network; docs/perception.md), as onboard. Writes
// per view (suffix "" for the leader, "_view1", … for the further views, as synth-gestures):
//   skeletons*.csv  the pipeline's skeletons (design.md §8.7 + label, sequence, segment): one row
//                   per frame in which the pipeline found the worker; `segment` changes whenever the
//                   pipeline lost the worker or started another identity (its FIFO restarts there;
//                   `gfctl classify` restarts its window the same way);
//   sequences*.csv  what produced each sequence, the view's camera pose (cam_* columns: the pose the
//                   image was rendered from, in the body frame) — the columns of synth-gestures —
//                   plus outfit, skin_tone, frames_found;
//   truth*.csv      every rendered frame: found, segment, the truth's visible box and the 17 truth
//                   keypoints (u, v, visible) of the posed mesh (render::WorkerTruth);
//   frames/         with --frames-every N: every N-th frame of every view, the worker's region
//                   enlarged 3×, the truth's stick figure in green and the pipeline's in red (left
//                   side solid, right side thin): the networks' errors to look at.
// --window-only: training-data mode (docs/gestures.md §9). Each view renders only a square window
// of the same camera (side 1.6 × the worker's projected height, its intrinsics' principal point
// shifted: the same pixels as the full frame there) and no detector or tracker runs: the skeleton
// network reads the worker's visible box with the KCF/detector box's error as measured on the
// rendered tuning sets (kTrackerBoxError). The worker is "found" in every frame (one segment per
// performance); the files are the same, in full-image coordinates. About 5× faster here.
// Viewpoints: the leader's distance, elevation and azimuth drawn in the config's ranges; each
// further view at its azimuth offset from the leader with its OWN distance and elevation drawn in
// the same ranges (formation-like: the followers fly their own heights). Motions: cycled through
// --motions (default: all of gesture::Motion), so every gesture and work motion is present.
// The world: open ground (z = 0), sky, no obstacles. Exit 0; 2 bad input; 1 no EGL / OpenGL here.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <random>
#include <utility>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "commands.hpp"
#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/gesture/skeleton_synth.hpp"
#include "gesture_formation/gesture/view_triangulation.hpp"
#include "gesture_formation/perception/perception_pipeline.hpp"
#include "gesture_formation/render/renderer.hpp"

namespace gesture_formation::gfctl {
namespace {

int cmdRenderGestures(const Args& args);
const Registrar kRegistrar{
    "render-gestures",
    "--seed S --count N --out DIR [--config FILE] [--views D1,D2] [--motions M1,M2] [--models DIR] [--skeleton KIND] [--frames-every N] [--window-only]   "
    "generator performances rendered per view and put through the real detector + tracker + MoveNet, or with --window-only "
    "the skeleton network alone on the worker's window (docs/gestures.md §9)",
    cmdRenderGestures};

constexpr int kExitNoRenderer = 1;  ///< no EGL display or OpenGL 3.3 context here

std::optional<gesture::Motion> parseMotion(const std::string& name) {
  for (int m = 0; m < static_cast<int>(gesture::Motion::kCount); ++m) {
    if (name == gesture::toString(static_cast<gesture::Motion>(m))) return static_cast<gesture::Motion>(m);
  }
  return std::nullopt;
}

/// The parsed command line.
struct Options {
  std::uint64_t seed = 0;
  int count = 0;
  std::string dir, models;
  std::vector<double> offsets_deg;
  std::vector<gesture::Motion> motions;
  gesture::SynthConfig synth;
  perception::SkeletonKind skeleton = perception::SkeletonKind::kMoveNetLightning;
  int frames_every = 0;  ///< 0: no annotated frames
  bool window_only = false;  ///< render the skeleton network's window only, box from the truth
};

std::string parseOptions(const Args& args, Options& o) {
  const auto seed = common::parseDouble(args.get("seed"));
  const auto count = common::parseDouble(args.get("count"));
  if (!seed || *seed < 0 || *seed > 1e15 || *seed != std::floor(*seed)) {
    return "--seed: expected a non-negative integer, got '" + args.get("seed") + "'";
  }
  if (!count || *count < 1 || *count > 1e5 || *count != std::floor(*count)) {
    return "--count: expected an integer in [1, 100000], got '" + args.get("count") + "'";
  }
  o.seed = static_cast<std::uint64_t>(*seed);
  o.count = static_cast<int>(*count);
  const auto items = [&](const char* key) { return args.has(key) ? common::splitCsvLine(args.get(key)) : std::vector<std::string>{}; };
  for (const std::string& item : items("views")) {
    const auto v = common::parseDouble(item);
    if (!v || !std::isfinite(*v) || *v < -360.0 || *v > 360.0) {
      return "--views: expected comma-separated azimuth offsets in [-360, 360] deg, got '" + item + "'";
    }
    o.offsets_deg.push_back(*v);
  }
  if (o.offsets_deg.size() > 8) return "--views: at most 8 further views, got " + std::to_string(o.offsets_deg.size());
  for (const std::string& item : items("motions")) {
    const auto m = parseMotion(item);
    if (!m) return "--motions: unknown motion '" + item + "'";
    o.motions.push_back(*m);
  }
  if (o.motions.empty()) {
    for (int m = 0; m < static_cast<int>(gesture::Motion::kCount); ++m) o.motions.push_back(static_cast<gesture::Motion>(m));
  }
  if (args.has("config")) {
    using common::ConfigReader;
    ConfigReader r = ConfigReader::fromFile(args.get("config"), ConfigReader::MissingKeys::kUseDefaults);
    gesture::synthConfigFields().readFields(r, "", o.synth);
    common::addProblems(r, "", gesture::synthConfigProblems(o.synth));
    if (!r.ok()) return "invalid configuration " + args.get("config") + ":\n" + r.errorReport();
  }
  if (args.has("frames-every")) {
    const auto n = common::parseDouble(args.get("frames-every"));
    if (!n || *n < 1 || *n > 1e6 || *n != std::floor(*n)) {
      return "--frames-every: expected an integer in [1, 1000000], got '" + args.get("frames-every") + "'";
    }
    o.frames_every = static_cast<int>(*n);
  }
  if (args.has("window-only")) {
    if (args.get("window-only") != "1") return "--window-only: a flag without a value, got '" + args.get("window-only") + "'";
    o.window_only = true;
  }
  if (args.has("skeleton")) {
    const auto k = perception::parseSkeletonKind(args.get("skeleton"));
    if (!k) return "--skeleton: " + k.reason();
    o.skeleton = *k;
  }
  o.synth.camera.distortion.fill(0.0);  // the rendered image is the rectified one
  o.dir = args.get("out");
  o.models = modelsRoot(args);
  std::error_code ec;
  std::filesystem::create_directories(o.dir, ec);
  if (ec || !std::filesystem::is_directory(o.dir)) return o.dir + ": cannot create directory";
  return "";
}

/// One view's output files and its perception pipeline.
struct ViewOut {
  std::unique_ptr<perception::PerceptionPipeline> pipeline;
  std::ofstream skeletons, sequences, truth;
  long frames = 0, found = 0;
  int index = 0;           ///< 0 leader, 1… further views
  int frames_every = 0;    ///< --frames-every (0: none)
  std::string frames_dir;  ///< where the annotated frames go
  float crop_scale = 1.25f;  ///< the skeleton network's crop around the box (drawn)
  std::unique_ptr<perception::SkeletonExtractor> extractor;  ///< --window-only: the network alone
  std::mt19937_64 box_rng;   ///< --window-only: the box error's draws
};

/// COCO-17 limbs: (a, b, left side).
constexpr std::array<std::array<int, 3>, 12> kLimbs{{{5, 7, 1}, {7, 9, 1}, {6, 8, 0}, {8, 10, 0}, {11, 13, 1}, {13, 15, 1},
                                                     {12, 14, 0}, {14, 16, 0}, {5, 6, 1}, {11, 12, 1}, {5, 11, 1}, {6, 12, 0}}};

/// The worker's region of one rendered frame enlarged, truth (green) and pipeline (red) stick figures.
void writeAnnotatedFrame(const ViewOut& v, const cv::Mat& bgr, const render::WorkerTruth& truth,
                         const perception::Skeleton* net, const cv::Rect2f* box_px, int sequence, std::size_t k) {
  cv::Rect2d box(1e9, 1e9, 0, 0);
  double u1 = -1e9, v1 = -1e9;
  for (const render::KeypointTruth& kt : truth.keypoints) {
    if (!kt.in_image) continue;
    box.x = std::min(box.x, kt.uv_px.x()), box.y = std::min(box.y, kt.uv_px.y());
    u1 = std::max(u1, kt.uv_px.x()), v1 = std::max(v1, kt.uv_px.y());
  }
  if (u1 < box.x) return;  // the worker is not in the image
  // The skeleton network's square crop around the tracker's box (centre, side max(w, h) · crop_scale).
  cv::Rect2d square;
  if (box_px != nullptr) {
    const double side = v.crop_scale * std::max(box_px->width, box_px->height);
    square = cv::Rect2d(box_px->x + 0.5 * (box_px->width - side), box_px->y + 0.5 * (box_px->height - side), side, side);
    box.x = std::min(box.x, square.x), box.y = std::min(box.y, square.y);
    u1 = std::max(u1, square.x + side), v1 = std::max(v1, square.y + side);
  }
  const double side = std::max({u1 - box.x, v1 - box.y, 20.0}) * 1.2;
  const double cu = 0.5 * (box.x + u1), cv_ = 0.5 * (box.y + v1);
  const cv::Rect roi = cv::Rect(static_cast<int>(cu - side / 2), static_cast<int>(cv_ - side / 2), static_cast<int>(side),
                                static_cast<int>(side)) &
                       cv::Rect(0, 0, bgr.cols, bgr.rows);
  if (roi.area() == 0) return;
  constexpr double kScale = 3.0;
  cv::Mat crop;
  cv::resize(bgr(roi), crop, cv::Size(), kScale, kScale, cv::INTER_NEAREST);
  const auto at = [&](double u, double w) { return cv::Point2d((u - roi.x + 0.5) * kScale, (w - roi.y + 0.5) * kScale); };
  if (box_px != nullptr) {  // the tracker's box (yellow) and the skeleton network's square crop around it (cyan)
    const cv::Rect2f& b = *box_px;
    cv::rectangle(crop, at(b.x, b.y), at(b.x + b.width, b.y + b.height), {0, 220, 255}, 1);
    cv::rectangle(crop, at(square.x, square.y), at(square.x + square.width, square.y + square.height), {255, 255, 0}, 1);
  }
  for (const auto& l : kLimbs) {
    const render::KeypointTruth &a = truth.keypoints[static_cast<std::size_t>(l[0])], &b = truth.keypoints[static_cast<std::size_t>(l[1])];
    if (a.in_image && b.in_image) {
      cv::line(crop, at(a.uv_px.x(), a.uv_px.y()), at(b.uv_px.x(), b.uv_px.y()), {0, 200, 0}, l[2] ? 2 : 1, cv::LINE_AA);
    }
    if (net == nullptr) continue;
    const perception::Keypoint &p = (*net)[static_cast<std::size_t>(l[0])], &q = (*net)[static_cast<std::size_t>(l[1])];
    if (p.c >= 0.3f && q.c >= 0.3f) cv::line(crop, at(p.x, p.y), at(q.x, q.y), {0, 0, 255}, l[2] ? 2 : 1, cv::LINE_AA);
  }
  const std::string name = v.frames_dir + "/seq" + std::to_string(sequence) + "_view" + std::to_string(v.index) + "_f" +
                           std::to_string(k) + ".png";
  cv::imwrite(name, crop);
}

void writeHeaders(ViewOut& v) {
  v.skeletons << "t,u,v,w,h";
  for (int k = 0; k < gesture::kNumKeypoints; ++k) v.skeletons << ",x" << k << ",y" << k << ",c" << k;
  v.skeletons << ",label,sequence,segment\n";
  v.sequences << "sequence,motion,gesture_id,left_arm,height_m,distance_m,elevation_deg,azimuth_deg,frames,motion_start_s,"
                 "motion_end_s,cam_x,cam_y,cam_z,cam_qw,cam_qx,cam_qy,cam_qz,cam_fx,cam_fy,cam_cx,cam_cy,cam_width,cam_height,"
                 "outfit,skin_tone,frames_found\n";
  v.truth << "sequence,t,label,found,segment,box_u,box_v,box_w,box_h";
  for (int k = 0; k < gesture::kNumKeypoints; ++k) v.truth << ",tu" << k << ",tv" << k << ",tvis" << k;
  v.truth << '\n';
}

/// The leader's viewpoint and each further view's (own distance and elevation), from `rng`.
std::vector<gesture::SkeletonSynthesizer::View> drawViews(const Options& o, std::mt19937_64& rng) {
  const gesture::SynthConfig& c = o.synth;
  std::uniform_real_distribution<double> ud(c.distance_min_m, c.distance_max_m), ue(c.elevation_min_deg, c.elevation_max_deg),
      ua(c.azimuth_min_deg, c.azimuth_max_deg);
  std::vector<gesture::SkeletonSynthesizer::View> views{{ud(rng), ue(rng), ua(rng)}};
  for (const double off : o.offsets_deg) {
    const double d = ud(rng), e = ue(rng);
    views.push_back({d, e, std::remainder(views[0].azimuth_deg + off, 360.0)});
  }
  return views;
}

/// One frame of one view: the pipeline on the rendered pixels, a skeleton row when the worker was
/// found, a truth row always.
struct FrameState {
  int segment = 0;
  bool in_segment = false;
  int last_id = -1;
};

std::string processFrame(ViewOut& v, const render::RenderedFrame& frame, const gesture::SynthSequence& seq, std::size_t k,
                         FrameState& st) {
  cv::Mat bgr;
  cv::cvtColor(frame.rgb, bgr, cv::COLOR_RGB2BGR);
  auto pf = v.pipeline->step(bgr);
  if (!pf) return pf.reason();
  const bool found = pf->track.found && pf->has_skeleton;
  if (!found || pf->track.identity_changed || pf->track.id != st.last_id) {
    if (st.in_segment) ++st.segment;  // the FIFO restarts: a new window segment
    st.in_segment = false;
  }
  const auto f = [](double x) { return common::formatDouble(x); };
  const gesture::SynthFrame& sf = seq.frames[k];
  ++v.frames;
  if (v.frames_every > 0 && k % static_cast<std::size_t>(v.frames_every) == 0) {
    writeAnnotatedFrame(v, bgr, frame.worker, found ? &pf->skeleton : nullptr, found ? &pf->track.box_px : nullptr, seq.id, k);
  }
  if (found) {
    st.in_segment = true;
    st.last_id = pf->track.id;
    ++v.found;
    const cv::Rect2f& b = pf->track.box_px;
    v.skeletons << f(sf.t_s) << ',' << f(b.x) << ',' << f(b.y) << ',' << f(b.width) << ',' << f(b.height);
    for (const perception::Keypoint& p : pf->skeleton) v.skeletons << ',' << f(p.x) << ',' << f(p.y) << ',' << f(p.c);
    v.skeletons << ',' << sf.label << ',' << seq.id << ',' << st.segment << '\n';
  } else {
    st.last_id = -1;
  }
  const render::WorkerTruth& t = frame.worker;
  v.truth << seq.id << ',' << f(sf.t_s) << ',' << sf.label << ',' << (found ? 1 : 0) << ',' << st.segment << ','
          << t.visible_box_px.x << ',' << t.visible_box_px.y << ',' << t.visible_box_px.width << ',' << t.visible_box_px.height;
  for (const render::KeypointTruth& kt : t.keypoints) {
    v.truth << ',' << f(kt.uv_px.x()) << ',' << f(kt.uv_px.y()) << ',' << (kt.visible ? 1 : 0);
  }
  v.truth << '\n';
  return "";
}

/// \brief The tracker's box error, measured on the rendered tuning sets (seeds 3701 and 3702, every
/// view, 13 548 frames in which the pipeline found the worker; KCF ⇄ multipose box against the
/// worker's visible box, in units of its height): a bias per view and performance plus an AR(1)
/// per frame (lag-1 autocorrelation 0.6–0.75). log w is skewed (p95 0.20), drawn Gaussian here.
struct BoxErrorModel {
  double ar = 0.7;                                   ///< lag-1 autocorrelation of the per-frame part
  double cx_bias_sd = 0.006, cx_sd = 0.011;          ///< centre u / height
  double cy_bias_sd = 0.005, cy_sd = 0.006;          ///< centre v / height
  double log_h_mean = 0.013, log_h_bias_sd = 0.008, log_h_sd = 0.010;  ///< log(box h / visible h)
  double log_w_mean = 0.024, log_w_bias_sd = 0.044, log_w_sd = 0.070;  ///< log(box w / visible w)
};
constexpr BoxErrorModel kTrackerBoxError{};

/// One view's box error state across a performance.
struct BoxError {
  std::array<double, 4> bias{}, state{};  ///< cx, cy, log h, log w
  void start(std::mt19937_64& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    const BoxErrorModel& m = kTrackerBoxError;
    bias = {m.cx_bias_sd * n(rng), m.cy_bias_sd * n(rng), m.log_h_mean + m.log_h_bias_sd * n(rng),
            m.log_w_mean + m.log_w_bias_sd * n(rng)};
    state = {m.cx_sd * n(rng), m.cy_sd * n(rng), m.log_h_sd * n(rng), m.log_w_sd * n(rng)};
  }
  /// The next frame's box around the visible box `vis`.
  cv::Rect2f next(const cv::Rect& vis, std::mt19937_64& rng) {
    std::normal_distribution<double> n(0.0, 1.0);
    const BoxErrorModel& m = kTrackerBoxError;
    const double innov = std::sqrt(1.0 - m.ar * m.ar);
    const std::array<double, 4> sd{m.cx_sd, m.cy_sd, m.log_h_sd, m.log_w_sd};
    for (std::size_t i = 0; i < 4; ++i) state[i] = m.ar * state[i] + innov * sd[i] * n(rng);
    const double h = vis.height, cu = vis.x + 0.5 * vis.width + (bias[0] + state[0]) * h,
                 cv_ = vis.y + 0.5 * vis.height + (bias[1] + state[1]) * h;
    const double bh = h * std::exp(bias[2] + state[2]), bw = std::max(1.0, vis.width * std::exp(bias[3] + state[3]));
    return {static_cast<float>(cu - 0.5 * bw), static_cast<float>(cv_ - 0.5 * bh), static_cast<float>(bw), static_cast<float>(bh)};
  }
};

/// The camera's square window around `centre` (side `side` px), clipped to the image: the same
/// camera with its principal point shifted, so that its pixels are the full frame's there.
std::pair<render::CameraView, cv::Point> windowOf(const render::CameraView& cam, const Eigen::Vector2d& centre, double side) {
  const estimation::CameraIntrinsics& k = cam.intrinsics;
  const int s = static_cast<int>(std::ceil(side));
  const int x0 = std::clamp(static_cast<int>(std::floor(centre.x() - 0.5 * s)), 0, k.width_px - 1);
  const int y0 = std::clamp(static_cast<int>(std::floor(centre.y() - 0.5 * s)), 0, k.height_px - 1);
  const int x1 = std::clamp(static_cast<int>(std::floor(centre.x() - 0.5 * s)) + s, x0 + 1, k.width_px);
  const int y1 = std::clamp(static_cast<int>(std::floor(centre.y() - 0.5 * s)) + s, y0 + 1, k.height_px);
  render::CameraView w = cam;
  w.intrinsics.cx = k.cx - x0, w.intrinsics.cy = k.cy - y0;
  w.intrinsics.width_px = x1 - x0, w.intrinsics.height_px = y1 - y0;
  return {w, cv::Point(x0, y0)};
}

/// Whether the square crop the skeleton network takes around `box` lies inside the window, or
/// beyond it only where the window ends at the image's edge (the full frame has nothing there either).
bool cropInside(const cv::Rect2f& box, float crop_scale, const render::CameraView& window, const cv::Point& offset,
                const estimation::CameraIntrinsics& full) {
  const double side = crop_scale * std::max(box.width, box.height);
  const double u0 = box.x + 0.5 * (box.width - side), v0 = box.y + 0.5 * (box.height - side);
  const int W = window.intrinsics.width_px, H = window.intrinsics.height_px;
  const bool left = u0 >= 0 || offset.x == 0, top = v0 >= 0 || offset.y == 0;
  const bool right = u0 + side <= W || offset.x + W == full.width_px, bottom = v0 + side <= H || offset.y + H == full.height_px;
  return left && top && right && bottom;
}

/// --window-only: one frame of one view — the skeleton network on the rendered window around the
/// worker, the box his visible box with the tracker's error. Coordinates written are the full image's.
std::string processWindowFrame(ViewOut& v, render::Renderer& renderer, const render::CameraView& cam,
                               const gesture::SynthSequence& seq, std::size_t k, BoxError& err) {
  // The worker's extent from his posed keypoints (the visible box adds ~6 % of his height above the
  // eyes and below the ankles; the window leaves room for the crop of 1.25 × the box around it).
  const render::PosedKeypoints* kp = renderer.workerKeypoints();
  if (kp == nullptr) return "no worker posed";
  const Eigen::Isometry3d T_camera_world = cam.T_world_camera.inverse();
  const estimation::CameraIntrinsics& in = cam.intrinsics;
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  for (const Eigen::Vector3d& p : kp->p_world) {
    const Eigen::Vector3d c = T_camera_world * p;
    if (c.z() <= 0.05) return "a keypoint behind the camera";
    const Eigen::Vector2d uv(in.fx * c.x() / c.z() + in.cx, in.fy * c.y() / c.z() + in.cy);
    lo = lo.cwiseMin(uv), hi = hi.cwiseMax(uv);
  }
  const double extent = std::max((hi.y() - lo.y()) / 0.88, (hi.x() - lo.x()) * 1.15);
  double side = 1.7 * extent + 8.0;
  for (int attempt = 0; attempt < 3; ++attempt, side *= 1.5) {
    const auto [window, offset] = windowOf(cam, 0.5 * (lo + hi), side);
    auto frame = renderer.render(window);
    if (!frame) return frame.reason();
    const cv::Rect vis = frame->worker.visible_box_px;
    if (vis.area() == 0) return "the worker is not seen in the window";
    const cv::Rect2f box = err.next(vis, v.box_rng);
    if (!cropInside(box, v.crop_scale, window, offset, in) && attempt < 2) continue;  // a larger window
    cv::Mat bgr;
    cv::cvtColor(frame->rgb, bgr, cv::COLOR_RGB2BGR);
    auto skel = v.extractor->extract(bgr, box);
    if (!skel) return skel.reason();
    ++v.frames, ++v.found;
    if (v.frames_every > 0 && k % static_cast<std::size_t>(v.frames_every) == 0) {
      writeAnnotatedFrame(v, bgr, frame->worker, &*skel, &box, seq.id, k);
    }
    const auto f = [](double x) { return common::formatDouble(x); };
    const gesture::SynthFrame& sf = seq.frames[k];
    v.skeletons << f(sf.t_s) << ',' << f(box.x + offset.x) << ',' << f(box.y + offset.y) << ',' << f(box.width) << ','
                << f(box.height);
    for (const perception::Keypoint& p : *skel) v.skeletons << ',' << f(p.x + offset.x) << ',' << f(p.y + offset.y) << ',' << f(p.c);
    v.skeletons << ',' << sf.label << ',' << seq.id << ",0\n";
    const render::WorkerTruth& t = frame->worker;
    v.truth << seq.id << ',' << f(sf.t_s) << ',' << sf.label << ",1,0," << vis.x + offset.x << ',' << vis.y + offset.y << ','
            << vis.width << ',' << vis.height;
    for (const render::KeypointTruth& kt : t.keypoints) {
      v.truth << ',' << f(kt.uv_px.x() + offset.x) << ',' << f(kt.uv_px.y() + offset.y) << ',' << (kt.visible ? 1 : 0);
    }
    v.truth << '\n';
    return "";
  }
  return "";  // not reached
}

void writeSequenceRow(ViewOut& v, const gesture::SynthSequence& s, const gesture::CalibratedSkeleton& cam,
                      const render::Appearance& look, long found) {
  const auto f = [](double x) { return common::formatDouble(x); };
  const Eigen::Quaterniond q(cam.R_world_camera);
  const estimation::CameraIntrinsics& in = cam.intrinsics;
  v.sequences << s.id << ',' << gesture::toString(s.motion) << ',' << gesture::gestureIdOf(s.motion) << ',' << (s.left_arm ? 1 : 0)
              << ',' << f(s.height_m) << ',' << f(s.distance_m) << ',' << f(s.elevation_deg) << ',' << f(s.azimuth_deg) << ','
              << s.frames.size() << ',' << f(s.motion_start_s) << ',' << f(s.motion_end_s) << ',' << f(cam.p_world_camera.x())
              << ',' << f(cam.p_world_camera.y()) << ',' << f(cam.p_world_camera.z()) << ',' << f(q.w()) << ',' << f(q.x()) << ','
              << f(q.y()) << ',' << f(q.z()) << ',' << f(in.fx) << ',' << f(in.fy) << ',' << f(in.cx) << ',' << f(in.cy) << ','
              << in.width_px << ',' << in.height_px << ',' << render::toString(look.outfit) << ',' << look.skin_tone << ','
              << found << '\n';
}

/// Renders every frame of one performance from every view and runs each view's pipeline.
std::string renderSequence(render::Renderer& renderer, std::vector<ViewOut>& out, const std::vector<gesture::SynthSequence>& seqs,
                           const estimation::CameraIntrinsics& intrinsics, const render::Appearance& look) {
  const gesture::SynthSequence& s0 = seqs.front();
  std::vector<render::CameraView> cams;
  std::vector<gesture::CalibratedSkeleton> poses;
  for (const gesture::SynthSequence& s : seqs) {
    poses.push_back(gesture::cameraAround(s.distance_m, s.elevation_deg, s.azimuth_deg, 0.55 * s.height_m, intrinsics));
    render::CameraView cam;
    cam.intrinsics = intrinsics;
    cam.T_world_camera.linear() = poses.back().R_world_camera;
    cam.T_world_camera.translation() = poses.back().p_world_camera;
    cams.push_back(cam);
  }
  std::vector<FrameState> states(seqs.size());
  std::vector<BoxError> box_errors(seqs.size());
  for (std::size_t v = 0; v < out.size(); ++v) {
    if (out[v].pipeline) out[v].pipeline->reset();  // every performance starts with no track
    if (out[v].extractor) box_errors[v].start(out[v].box_rng);
  }
  std::vector<long> found_before;
  for (const ViewOut& v : out) found_before.push_back(v.found);
  for (std::size_t k = 0; k < s0.frames.size() && k < s0.bodies.size(); ++k) {
    auto r = renderer.setWorker(render::WorkerJoints::fromBody(s0.bodies[k], Eigen::Vector3d::Zero(), 0.0), s0.height_m, look);
    if (!r) return "sequence " + std::to_string(s0.id) + " frame " + std::to_string(k) + ": " + r.reason();
    for (std::size_t v = 0; v < seqs.size(); ++v) {
      if (out[v].extractor) {  // --window-only
        const std::string e = processWindowFrame(out[v], renderer, cams[v], seqs[v], k, box_errors[v]);
        if (!e.empty()) return "sequence " + std::to_string(s0.id) + " view " + std::to_string(v) + " frame " + std::to_string(k) + ": " + e;
        continue;
      }
      auto frame = renderer.render(cams[v]);
      if (!frame) return "sequence " + std::to_string(s0.id) + " view " + std::to_string(v) + ": " + frame.reason();
      const std::string e = processFrame(out[v], *frame, seqs[v], k, states[v]);
      if (!e.empty()) return "sequence " + std::to_string(s0.id) + " view " + std::to_string(v) + ": " + e;
    }
  }
  for (std::size_t v = 0; v < seqs.size(); ++v) {
    writeSequenceRow(out[v], seqs[v], poses[v], look, out[v].found - found_before[v]);
    for (std::ofstream* f : {&out[v].skeletons, &out[v].sequences, &out[v].truth}) f->flush();
  }
  return "";
}

int cmdRenderGestures(const Args& args) {
  if (!checkOptions(args, {"seed", "count", "out"}, {"config", "views", "motions", "models", "skeleton", "frames-every", "window-only"})) return kExitBadInput;
  Options o;
  if (const std::string e = parseOptions(args, o); !e.empty()) return badInput(args, e);
  render::RendererConfig rc;
  rc.worker_asset_path = o.models + "/mannequin/wooden_mannequin.glb";
  auto renderer = render::Renderer::create(rc);
  if (!renderer && renderer.reason().rfind("worker asset", 0) == 0) return badInput(args, renderer.reason());
  if (!renderer) {  // no EGL display / OpenGL context: not the input's fault
    std::cerr << "gfctl render-gestures: " << renderer.reason() << "\n";
    return kExitNoRenderer;
  }
  if (auto r = (*renderer)->setWorldMesh(render::TriangleMesh{}, 0.0, Eigen::Vector3d::Zero()); !r) return badInput(args, r.reason());
  (*renderer)->setUavs({});
  perception::PerceptionConfig pc;
  pc.models_root = o.models;
  pc.skeleton = o.skeleton;
  const std::size_t n_views = 1 + o.offsets_deg.size();
  std::vector<ViewOut> out(n_views);
  for (std::size_t v = 0; v < n_views; ++v) {
    if (o.window_only) {
      auto x = perception::makeSkeletonExtractor(pc);
      if (!x) return badInput(args, x.reason() + " (models root: " + o.models + ")");
      out[v].extractor = std::move(*x);
      std::seed_seq box_seed{o.seed, std::uint64_t{0xb0c5e7u}, static_cast<std::uint64_t>(v)};
      out[v].box_rng.seed(box_seed);
    } else {
      auto p = perception::PerceptionPipeline::create(pc);
      if (!p) return badInput(args, p.reason() + " (models root: " + o.models + ")");
      out[v].pipeline = std::move(*p);
    }
    out[v].index = static_cast<int>(v);
    out[v].crop_scale =
        o.skeleton == perception::SkeletonKind::kBlazePoseLandmark ? pc.blazepose_landmark.crop_scale : pc.lightning.crop_scale;
    if (o.frames_every > 0) {
      out[v].frames_every = o.frames_every;
      out[v].frames_dir = o.dir + "/frames";
      std::error_code ec;
      std::filesystem::create_directories(out[v].frames_dir, ec);
      if (ec) return badInput(args, out[v].frames_dir + ": cannot create directory");
    }
    const std::string suffix = v == 0 ? "" : "_view" + std::to_string(v);
    out[v].skeletons.open(o.dir + "/skeletons" + suffix + ".csv");
    out[v].sequences.open(o.dir + "/sequences" + suffix + ".csv");
    out[v].truth.open(o.dir + "/truth" + suffix + ".csv");
    if (!out[v].skeletons || !out[v].sequences || !out[v].truth) return badInput(args, o.dir + ": cannot write the view's files");
    writeHeaders(out[v]);
  }
  gesture::SkeletonSynthesizer synth(o.synth, o.seed);
  std::seed_seq ss{o.seed, std::uint64_t{0x7e4d3e5du}};
  std::mt19937_64 view_rng(ss);
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < o.count; ++i) {
    const gesture::Motion motion = o.motions[static_cast<std::size_t>(i) % o.motions.size()];
    const std::vector<gesture::SynthSequence> seqs = synth.generateViewsFrom(motion, drawViews(o, view_rng));
    const render::Appearance look = render::Appearance::fromSeed(o.seed * 1000003ULL + static_cast<std::uint64_t>(seqs[0].id));
    if (const std::string e = renderSequence(**renderer, out, seqs, o.synth.camera, look); !e.empty()) return badInput(args, e);
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::cout << "render-gestures: sequence " << i + 1 << "/" << o.count << " " << gesture::toString(motion) << ", "
              << seqs[0].frames.size() << " frames x " << n_views << " views, " << common::formatDouble(wall_s) << " s\n"
              << std::flush;
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  long frames = 0, found = 0;
  for (const ViewOut& v : out) frames += v.frames, found += v.found;
  std::cout << "gfctl render-gestures: " << o.count << " sequences, " << frames << " view-frames (worker found in " << found
            << ") in " << common::formatDouble(wall_s) << " s = " << common::formatDouble(frames / std::max(wall_s, 1e-9))
            << " view-frames/s; " << (*renderer)->glRenderer() << " -> " << o.dir << "\n";
  return kExitOk;
}

}  // namespace
}  // namespace gesture_formation::gfctl

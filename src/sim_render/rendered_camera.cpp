#include "gesture_formation/sim/rendered_camera.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <thread>

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/render/renderer.hpp"
#include "gesture_formation/sim/leader_camera.hpp"
#include "gesture_formation/sim/random.hpp"

namespace gesture_formation::sim {

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

/// The names under which the streams are written (docs/simulation.md §8).
std::string videoPath(const std::string& dir, std::size_t i, const MissionConfig& m) {
  std::string name = i < m.uavs.size() ? m.uavs[i].name : std::to_string(i);
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  }
  return dir + "/uav" + std::to_string(i) + "_" + name + ".avi";
}

}  // namespace

/// One UAV's camera: its own pipeline (detector ⇄ tracker, skeleton, FIFO), the classifier's
/// window made from its FIFO, and its video.
struct RenderedCamera::Camera {
  std::unique_ptr<perception::PerceptionPipeline> pipeline;
  gesture::SkeletonWindow window;
  double last_frame_s = -1e9;    ///< last frame this camera processed
  double last_visible_s = -1e9;  ///< last frame it found the worker
  cv::VideoWriter video;
};

/// What one camera made of one frame.
struct CameraResult {
  bool rendered = false;   ///< the image exists
  bool processed = false;  ///< rendered and through the pipeline
  std::string error;       ///< why not
  double render_ms = 0.0;
  bool found = false;      ///< the worker's box
  estimation::Box box;
  gesture::Skeleton2D skeleton;  ///< image pixels, on the tracker's box
  bool classify = false;         ///< found, and the FIFO holds a full window of one identity
  cv::Mat bgr, depth_m;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  perception::PerceptionFrame perception;
  render::WorkerTruth truth;
};

namespace {

gesture::Skeleton2D toSkeleton2D(const perception::Skeleton& sk, const cv::Rect2f& box) {
  gesture::Skeleton2D s;
  s.u = box.x;
  s.v = box.y;
  s.w = box.width;
  s.h = box.height;
  for (std::size_t k = 0; k < static_cast<std::size_t>(gesture::kNumKeypoints); ++k) {
    s.x[k] = sk[k].x;
    s.y[k] = sk[k].y;
    s.c[k] = sk[k].c;
  }
  return s;
}

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// The pipeline's output of one frame beside the renderer's truth.
PerceptionRecord makeRecord(double t, std::size_t uav, const Eigen::Vector3d& camera_world, const WorkerState& ws,
                            const perception::PerceptionFrame& pf, const render::WorkerTruth& truth, double render_ms) {
  PerceptionRecord r;
  r.t_s = t;
  r.uav = static_cast<int>(uav);
  const formation::ViewGeometry g = formation::viewGeometry(camera_world, ws.p_world);
  r.distance_m = g.distance_m;
  r.elevation_deg = g.elevation_deg;
  r.truth_box_height_px = truth.visible_pixels > 0 ? truth.visible_box_px.height : 0;
  r.visible_pixels = truth.visible_pixels;
  r.in_view = r.truth_box_height_px >= kMinTruthBoxHeightPx;
  r.detected = pf.track.found;
  r.detector_ran = pf.track.detector_ran;
  r.iou = (r.detected && truth.visible_pixels > 0) ? perception::iou(pf.track.box_px, cv::Rect2f(truth.visible_box_px)) : 0.0;
  std::vector<double> err;
  if (pf.has_skeleton) {
    for (std::size_t k = 0; k < static_cast<std::size_t>(gesture::kNumKeypoints); ++k) {
      const render::KeypointTruth& kt = truth.keypoints[k];
      if (!kt.visible || !(pf.skeleton[k].c > 0.0f)) continue;
      err.push_back(std::hypot(pf.skeleton[k].x - kt.uv_px.x(), pf.skeleton[k].y - kt.uv_px.y()));
    }
  }
  r.keypoints_compared = static_cast<int>(err.size());
  r.keypoint_error_px = median(err);
  r.keypoint_error_fraction =
      r.truth_box_height_px > 0 ? r.keypoint_error_px / r.truth_box_height_px : std::numeric_limits<double>::quiet_NaN();
  r.track_id = pf.track.found ? pf.track.id : -1;
  r.identity_started = pf.track.identity_changed;
  r.render_ms = render_ms;
  r.detect_ms = pf.track.detect_ms;
  r.track_ms = pf.track.track_ms;
  r.skeleton_ms = pf.skeleton_ms;
  return r;
}

std::string gestureName(int id) { return id == gesture::kNone ? "none" : gesture::toString(motionOfGesture(id)); }

/// The annotated frame: truth joints (yellow rings), the worker's box (green: the detector
/// found it this frame; orange: the tracker), the skeleton (person's left blue, right red,
/// keypoints with c >= 0.3), the classification and the performed gesture.
void annotate(cv::Mat& img, const CameraResult& r, const std::optional<gesture::Classification>& c, double t,
              const std::string& name, int performing) {
  for (const render::KeypointTruth& kt : r.truth.keypoints) {
    if (kt.visible) cv::circle(img, cv::Point2d(kt.uv_px.x(), kt.uv_px.y()), 4, cv::Scalar(0, 230, 255), 1, cv::LINE_AA);
  }
  const perception::TrackStep& tr = r.perception.track;
  if (tr.found) {
    const bool by_detector = tr.source == perception::BoxSource::kDetector;
    cv::rectangle(img, tr.box_px, by_detector ? cv::Scalar(0, 200, 0) : cv::Scalar(0, 140, 255), 2);
  }
  if (r.perception.has_skeleton) {
    const perception::Skeleton& sk = r.perception.skeleton;
    for (const auto& [a, b] : perception::cocoLimbs()) {
      const auto& pa = sk[static_cast<std::size_t>(a)];
      const auto& pb = sk[static_cast<std::size_t>(b)];
      if (pa.c < 0.3f || pb.c < 0.3f) continue;
      const bool left = (a % 2 == 1) && (b % 2 == 1), right = (a % 2 == 0 && a > 0) && (b % 2 == 0 && b > 0);
      const cv::Scalar colour = left ? cv::Scalar(255, 80, 0) : (right ? cv::Scalar(0, 0, 255) : cv::Scalar(255, 255, 255));
      cv::line(img, cv::Point2f(pa.x, pa.y), cv::Point2f(pb.x, pb.y), colour, 2, cv::LINE_AA);
    }
  }
  std::ostringstream top, bottom;
  top.setf(std::ios::fixed);
  top.precision(2);
  top << "t " << t << " s  " << name << (tr.found ? "  id " + std::to_string(tr.id) : "  worker not found");
  bottom << "classifier: " << (c ? gestureName(c->gesture_id) + " " +
                                      std::to_string(static_cast<int>(100.0f * c->probabilities[static_cast<std::size_t>(c->gesture_id)])) + "%"
                                : std::string("-"))
         << "   performing: " << gestureName(performing);
  for (const auto& [text, y] : {std::pair<std::string, int>{top.str(), 18}, {bottom.str(), img.rows - 8}}) {
    cv::putText(img, text, cv::Point(6, y), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
    cv::putText(img, text, cv::Point(6, y), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
}

}  // namespace

std::vector<std::string> RenderedCameraConfig::validate() const {
  std::vector<std::string> e;
  if (models_root.empty()) e.push_back("models_root: must not be empty");
  if (threads < 1 || threads > 16) e.push_back("threads: must be in 1..16, got " + std::to_string(threads));
  for (const auto& p : perception.validate()) e.push_back("perception." + p);
  if (!(stereo.min_depth_m >= 0.0)) e.push_back("stereo.min_depth_m: must be >= 0, got " + std::to_string(stereo.min_depth_m));
  if (!stereo_max_from_mission && !(stereo.max_depth_m > stereo.min_depth_m)) {
    e.push_back("stereo.max_depth_m: must exceed min_depth_m, got " + std::to_string(stereo.max_depth_m));
  }
  if (stereo.min_valid_pixels < 1) e.push_back("stereo.min_valid_pixels: must be >= 1, got " + std::to_string(stereo.min_valid_pixels));
  return e;
}

gesture::SkeletonWindow windowFromFifo(const std::vector<float>& tensor) {
  gesture::SkeletonWindow w;
  constexpr std::size_t per_frame = gesture::kFeaturesPerFrame;
  if (tensor.size() != per_frame * static_cast<std::size_t>(gesture::kWindowFrames)) return w;
  for (std::size_t f = 0; f < static_cast<std::size_t>(gesture::kWindowFrames); ++f) {
    gesture::Skeleton2D s;
    s.u = 0.0;
    s.v = 0.0;
    s.w = 1.0;
    s.h = 1.0;
    for (std::size_t k = 0; k < static_cast<std::size_t>(gesture::kNumKeypoints); ++k) {
      const float* p = tensor.data() + f * per_frame + 3 * k;
      s.x[k] = p[0];
      s.y[k] = p[1];
      s.c[k] = p[2];
    }
    w.push(s);
  }
  return w;
}

RenderedCamera::RenderedCamera(const MissionConfig& mission, const planning::OccupancyMap* map, std::uint64_t seed)
    : cfg_(mission),
      intrinsics_(renderedIntrinsics(mission)),
      uwb_(mission.camera, mission.stereo, mission.uwb, map, makeRng(seed, Stream::kCamera), makeRng(seed, Stream::kStereo),
           makeRng(seed, Stream::kUwb)),
      fault_rng_(makeRng(seed, Stream::kFault)),
      seed_(seed) {}

RenderedCamera::~RenderedCamera() = default;

common::Result<std::unique_ptr<RenderedCamera>> RenderedCamera::create(const RenderedCameraConfig& config,
                                                                       const MissionConfig& mission,
                                                                       const planning::Scenario& scenario,
                                                                       const planning::OccupancyMap* map,
                                                                       std::uint64_t seed,
                                                                       const std::vector<UnmappedObstacle>& unmapped) {
  using R = common::Result<std::unique_ptr<RenderedCamera>>;
  const auto problems = config.validate();
  if (!problems.empty()) {
    std::string all = "rendered camera: ";
    for (std::size_t i = 0; i < problems.size(); ++i) all += (i ? "; " : "") + problems[i];
    return R::fail(all);
  }
  std::unique_ptr<RenderedCamera> cam(new RenderedCamera(mission, map, seed));
  cam->config_ = config;
  cam->config_.perception.models_root = config.models_root;
  if (config.stereo_max_from_mission) cam->config_.stereo.max_depth_m = mission.stereo.max_range_m;
  auto scene = SceneRenderer::create(config.models_root, scenario, seed);
  if (!scene) return R::fail("rendered camera: " + scene.reason());
  cam->scene_ = std::move(*scene);
  if (auto set = cam->scene_->setUnmappedObstacles(unmapped); !set) return R::fail("rendered camera: " + set.reason());
  const std::size_t n = mission.uavs.size();
  for (std::size_t i = 0; i < n; ++i) {
    auto c = std::make_unique<Camera>();
    auto pipeline = perception::PerceptionPipeline::create(cam->config_.perception);
    if (!pipeline) {
      return R::fail("rendered camera: perception networks under " + config.models_root + ": " + pipeline.reason() +
                     " (the networks are committed in third_party_models/; see third_party_models/MODELS.md)");
    }
    c->pipeline = std::move(*pipeline);
    if (!config.video_dir.empty()) {
      const std::string path = videoPath(config.video_dir, i, mission);
      const double fps = std::max(1.0, mission.camera.rate_hz);
      c->video.open(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps,
                    cv::Size(cam->intrinsics_.width_px, cam->intrinsics_.height_px));
      if (!c->video.isOpened()) return R::fail("rendered camera: --camera-video: cannot open a video writer for " + path);
    }
    cam->cameras_.push_back(std::move(c));
  }
  return R::ok(std::move(cam));
}

CameraResult RenderedCamera::renderCamera(std::size_t i, double t, const Eigen::Isometry3d& T_world_camera,
                                          double extra_render_ms) {
  Camera& c = *cameras_[i];
  CameraResult r;
  r.T_world_camera = T_world_camera;
  // A camera that delivered no frame for longer than the synthetic camera's gap starts over
  // (new track, empty FIFO): a window never spans a gap.
  if (c.last_frame_s > -1e8 && t - c.last_frame_s > LeaderCamera::kSkeletonGapS + 1e-9) c.pipeline->reset();
  c.last_frame_s = t;
  const auto t0 = Clock::now();
  auto rendered = scene_->render(i, intrinsics_);
  if (!rendered) {
    r.error = "t " + std::to_string(t) + " s, uav " + std::to_string(i) + ": render: " + rendered.reason();
    return r;
  }
  cv::cvtColor(rendered->rgb, r.bgr, cv::COLOR_RGB2BGR);
  r.render_ms = msSince(t0) + extra_render_ms;
  r.truth = rendered->worker;
  r.depth_m = rendered->depth_m;
  r.rendered = true;
  return r;
}

void RenderedCamera::runPipeline(std::size_t i, double t, CameraResult& r) {
  if (!r.rendered) return;
  Camera& c = *cameras_[i];
  auto pf = c.pipeline->step(r.bgr);
  if (!pf) {
    r.error = "t " + std::to_string(t) + " s, uav " + std::to_string(i) + ": perception: " + pf.reason();
    return;
  }
  r.processed = true;
  r.perception = std::move(*pf);
  const perception::TrackStep& tr = r.perception.track;
  r.found = tr.found;
  if (r.found) {
    c.last_visible_s = t;
    r.box = estimation::Box{tr.box_px.x, tr.box_px.y, tr.box_px.width, tr.box_px.height};
    r.skeleton = toSkeleton2D(r.perception.skeleton, tr.box_px);
    r.classify = r.perception.has_skeleton && r.perception.fifo_full;
  }
}

void RenderedCamera::processCameras(double t, const WorkerState& ws, std::vector<CameraResult>& results,
                                    const std::vector<bool>& wanted, const CameraPoses& cameras, double pose_ms) {
  // Rendering is serial (one GL context); the UAVs' pipelines are independent (each UAV runs its
  // own) and run on up to config_.threads threads: the results do not depend on it.
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < results.size(); ++i) {
    if (!wanted[i]) continue;
    results[i] = renderCamera(i, t, cameras[i], i == 0 ? pose_ms : 0.0);
    todo.push_back(i);
  }
  const std::size_t lanes = std::max<std::size_t>(1, std::min<std::size_t>(todo.size(), static_cast<std::size_t>(config_.threads)));
  const auto lane = [&](std::size_t l) {
    for (std::size_t k = l; k < todo.size(); k += lanes) runPipeline(todo[k], t, results[todo[k]]);
  };
  std::vector<std::thread> helpers;
  for (std::size_t l = 1; l < lanes; ++l) helpers.emplace_back(lane, l);
  lane(0);
  for (auto& h : helpers) h.join();
  for (const std::size_t i : todo) {  // in camera order: the records and the first error do not depend on the threads
    const CameraResult& r = results[i];
    if (!r.error.empty() && error_.empty()) error_ = r.error;
    if (r.processed) {
      records_.push_back(makeRecord(t, i, r.T_world_camera.translation(), ws, r.perception, r.truth, r.render_ms));
    }
  }
}

SensorFrame RenderedCamera::leaderSensors(double t, const CameraResult& leader, bool blackout, const MultirotorState& state,
                                          const WorkerState& ws, int& range_outliers) {
  // UWB: the synthetic radio range (its box and stereo outputs are discarded).
  const estimation::CameraPose pose = cameraPose(state.p_world, state.heading_rad, state.pitch_rad);
  const SensorFrame radio = uwb_.observe(pose, ws.feet_world, ws.p_world, cfg_.worker.height_m, false);
  SensorFrame f;
  f.true_range_m = radio.true_range_m;
  f.d_uwb_m = radio.d_uwb_m;
  f.visibility = blackout ? Visibility::kBlackout : Visibility::kDropout;  // kDropout: the pipeline did not find the worker
  if (!blackout && leader.found) {
    f.visibility = Visibility::kVisible;
    f.box = leader.box;
    const auto range = estimation::stereoDistance(leader.depth_m, leader.box, estimation::CameraModel(intrinsics_), config_.stereo);
    if (range) f.d_stereo_m = *range;
  }
  range_outliers = applyRangeFaults(cfg_.faults, t, f, fault_rng_);
  return f;
}

LeaderCameraFrame RenderedCamera::frame(double t, const MultirotorState& leader, const std::vector<MultirotorState>& followers,
                                        const std::vector<bool>& online, const WorkerState& ws, WorkerModel& worker,
                                        MissionClassifier* classifier) {
  LeaderCameraFrame out;
  out.intrinsics = intrinsics_;  // the rendered (rectified) image's
  // Every UAV's body and camera pose; the worker's performance advances exactly as with the
  // synthetic camera (the same motions and gesture episodes) — its synthetic skeletons are not used.
  std::vector<MultirotorState> states{leader};
  states.insert(states.end(), followers.begin(), followers.end());
  std::vector<Eigen::Vector3d> camera_world;
  for (const MultirotorState& s : states) camera_world.push_back(s.p_world);
  out.skeleton.t_s = t;
  out.skeleton.label = worker.skeletonsAt(t, camera_world).front().label;  // the truth label only
  const auto t0 = Clock::now();
  const auto posed = scene_->setScene(worker.bodyAt(t), ws.feet_world, ws.heading_rad, cfg_.worker.height_m, states, t);
  if (!posed && error_.empty()) error_ = "t " + std::to_string(t) + " s: " + posed.reason();
  CameraPoses cameras;
  for (std::size_t i = 0; i < states.size(); ++i) cameras.push_back(scene_->cameraPose(i));
  const double pose_ms = msSince(t0);  // skinning + upload, charged to the leader's render time

  bool blackout = false;
  for (const auto& [a, b] : cfg_.faults.camera_blackouts) blackout = blackout || (t >= a && t < b);
  std::vector<CameraResult> results(states.size());
  std::vector<bool> wanted(states.size(), true);
  wanted[0] = !blackout;  // a blackout: the leader gets no frame
  for (std::size_t i = 0; i < followers.size(); ++i) wanted[i + 1] = i >= online.size() || online[i];  // offline: none
  processCameras(t, ws, results, wanted, cameras, pose_ms);
  out.sensors = leaderSensors(t, results[0], blackout, leader, ws, out.range_outliers);
  for (std::size_t i = 0; i < results.size(); ++i) {
    if (results[i].rendered && !results[i].depth_m.empty()) out.depth.push_back(CameraDepth{i, t, results[i].T_world_camera, intrinsics_, results[i].depth_m});
  }
  out.followers.resize(followers.size());
  for (std::size_t i = 0; i < followers.size(); ++i) out.followers[i].visible = results[i + 1].found;
  // Every full window of the frame, classified together (MissionClassifier::classifyAll).
  std::vector<const gesture::SkeletonWindow*> windows;
  std::vector<std::optional<gesture::Classification>*> slots;
  for (std::size_t i = 0; i < results.size(); ++i) {
    if (classifier == nullptr || !results[i].classify) continue;
    cameras_[i]->window = windowFromFifo(cameras_[i]->pipeline->classifierInput());
    windows.push_back(&cameras_[i]->window);
    slots.push_back(i == 0 ? &out.classification : &out.followers[i - 1].classification);
  }
  if (!windows.empty()) {
    auto classified = classifier->classifyAll(windows);
    for (std::size_t k = 0; k < slots.size() && k < classified.size(); ++k) *slots[k] = std::move(classified[k]);
  }
  // The 3-D confirmation's skeletons: the pipeline's, with the pose of the camera that rendered it.
  for (std::size_t i = 0; cfg_.view_fusion.usesCalibratedViews() && i < results.size(); ++i) {
    if (!results[i].found) continue;
    gesture::CalibratedSkeleton& cal = i == 0 ? out.calibrated : out.followers[i - 1].calibrated;
    cal.skeleton = results[i].skeleton;
    cal.R_world_camera = results[i].T_world_camera.linear();
    cal.p_world_camera = results[i].T_world_camera.translation();
    cal.intrinsics = intrinsics_;
  }
  const int performing = worker.performingAt(t);
  for (std::size_t i = 0; i < results.size(); ++i) {
    if (!results[i].processed || !cameras_[i]->video.isOpened()) continue;
    const auto& c = i == 0 ? out.classification : out.followers[i - 1].classification;
    annotate(results[i].bgr, results[i], c, t, i < cfg_.uavs.size() ? cfg_.uavs[i].name : std::to_string(i), performing);
    cameras_[i]->video.write(results[i].bgr);
  }
  return out;
}

double RenderedCamera::lastVisibleS() const { return cameras_.empty() ? -1e9 : cameras_.front()->last_visible_s; }

std::string RenderedCamera::glRenderer() const { return scene_->glRenderer(); }

}  // namespace gesture_formation::sim

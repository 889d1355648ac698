#include "gesture_formation/perception/perception_pipeline.hpp"

#include "gesture_formation/perception/dnn_model.hpp"

namespace gesture_formation::perception {

common::Result<DetectorKind> parseDetectorKind(const std::string& text) {
  if (text == "movenet_multipose") return common::Result<DetectorKind>::ok(DetectorKind::kMoveNetMultipose);
  if (text == "blazepose") return common::Result<DetectorKind>::ok(DetectorKind::kBlazePose);
  return common::Result<DetectorKind>::fail("detector must be movenet_multipose or blazepose, got '" + text + "'");
}

std::string toString(DetectorKind kind) {
  return kind == DetectorKind::kMoveNetMultipose ? "movenet_multipose" : "blazepose";
}

std::vector<std::string> PerceptionConfig::validate() const {
  std::vector<std::string> e;
  const auto add = [&e](const std::vector<std::string>& more) { e.insert(e.end(), more.begin(), more.end()); };
  add(blazepose_detector.validate());
  add(multipose.validate());
  add(lightning.validate());
  add(blazepose_landmark.validate());
  add(tracker.validate());
  if (fifo_frames < 1) e.push_back("fifo_frames must be >= 1, got " + std::to_string(fifo_frames));
  if (const std::string d = dnnDeviceProblem(dnn_device); !d.empty()) e.push_back(d);
  return e;
}

namespace {

/// A network's config on the pipeline's DNN device.
template <class Config>
Config onDevice(Config config, DnnDevice device) {
  config.device = device;
  return config;
}

}  // namespace

common::Result<std::unique_ptr<PersonDetector>> makePersonDetector(const PerceptionConfig& c) {
  using R = common::Result<std::unique_ptr<PersonDetector>>;
  if (c.detector == DetectorKind::kBlazePose) {
    auto d = BlazePoseDetector::create(onDevice(c.blazepose_detector, c.dnn_device), c.models_root);
    if (!d) return R::fail(d.reason());
    return R::ok(std::move(d.value()));
  }
  auto d = MoveNetMultiposeDetector::create(onDevice(c.multipose, c.dnn_device), c.models_root);
  if (!d) return R::fail(d.reason());
  return R::ok(std::move(d.value()));
}

common::Result<std::unique_ptr<SkeletonExtractor>> makeSkeletonExtractor(const PerceptionConfig& c) {
  using R = common::Result<std::unique_ptr<SkeletonExtractor>>;
  if (c.skeleton == SkeletonKind::kBlazePoseLandmark) {
    auto s = BlazePoseLandmarkExtractor::create(onDevice(c.blazepose_landmark, c.dnn_device), c.models_root);
    if (!s) return R::fail(s.reason());
    return R::ok(std::move(s.value()));
  }
  auto s = MoveNetLightningExtractor::create(onDevice(c.lightning, c.dnn_device), c.models_root);
  if (!s) return R::fail(s.reason());
  return R::ok(std::move(s.value()));
}

common::Result<std::unique_ptr<PerceptionPipeline>> PerceptionPipeline::create(const PerceptionConfig& config) {
  using R = common::Result<std::unique_ptr<PerceptionPipeline>>;
  const auto problems = config.validate();
  if (!problems.empty()) {
    std::string all;
    for (const auto& p : problems) all += (all.empty() ? "" : "; ") + p;
    return R::fail(all);
  }
  auto detector = makePersonDetector(config);
  if (!detector) return R::fail(detector.reason());
  auto skeleton = makeSkeletonExtractor(config);
  if (!skeleton) return R::fail(skeleton.reason());
  auto tracker = WorkerTracker::create(config.tracker, std::move(detector.value()));
  if (!tracker) return R::fail(tracker.reason());
  return R::ok(std::unique_ptr<PerceptionPipeline>(
      new PerceptionPipeline(std::move(tracker.value()), std::move(skeleton.value()), config.fifo_frames)));
}

PerceptionPipeline::PerceptionPipeline(std::unique_ptr<WorkerTracker> tracker, std::unique_ptr<SkeletonExtractor> skeleton,
                                       int n)
    : tracker_(std::move(tracker)), skeleton_(std::move(skeleton)), fifo_(n) {}

void PerceptionPipeline::reset() {
  tracker_->reset();
  fifo_.clear();
}

common::Result<PerceptionFrame> PerceptionPipeline::step(const cv::Mat& frame_bgr) {
  using R = common::Result<PerceptionFrame>;
  const int64_t t0 = cv::getTickCount();
  const std::string bad = checkBgrImage(frame_bgr, "frame");
  if (!bad.empty()) return R::fail("perception: " + bad);
  auto track = tracker_->step(frame_bgr);
  if (!track) return R::fail(track.reason());
  PerceptionFrame out;
  out.track = std::move(track.value());
  if (!out.track.found || out.track.identity_changed || out.track.stream_reset) fifo_.clear();
  if (out.track.found) {
    const int64_t t1 = cv::getTickCount();
    auto skel = skeleton_->extract(frame_bgr, out.track.box_px);
    out.skeleton_ms = static_cast<double>(cv::getTickCount() - t1) * 1000.0 / cv::getTickFrequency();
    if (!skel) return R::fail(skel.reason());
    out.skeleton = *skel;
    out.has_skeleton = true;
    fifo_.push(out.skeleton, out.track.box_px);
  }
  out.fifo_full = fifo_.full();
  out.total_ms = static_cast<double>(cv::getTickCount() - t0) * 1000.0 / cv::getTickFrequency();
  return R::ok(std::move(out));
}

}  // namespace gesture_formation::perception

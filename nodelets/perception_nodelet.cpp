// Perception nodelet (issue 8 item 2): one camera's RGB image (+ aligned depth, CameraInfo) →
// the worker's box (perception::PerceptionPipeline: person detector ⇄ visual tracker), its
// skeleton into the FIFO of N frames, the gesture LSTM (gesture::GestureClassifier) on a full
// window, and the stereo range (estimation::stereoDistance: median depth in the box, along the
// box-centre ray). A thin adapter: the core decides, this converts and publishes.
//
// Topics: image_in (sensor_msgs/Image: bgr8, rgb8 or mono8), depth_in (sensor_msgs/Image aligned
//   to the colour image: 16UC1 in depth_scale_m units or 32FC1 in metres; optional),
//   camera_info_in (sensor_msgs/CameraInfo of the colour camera; without it: no stereo range)
//   → detection_out (WorkerDetection, one per image; frame_id = the image's),
//   gesture_out (Gesture, one per image with a full skeleton window: this UAV's classifier output,
//   the ViewObserver's input; with the image's skeleton and camera info once camera_info_in has
//   delivered, for the formation's 3-D confirmation).
//   candidates_out (WorkerCandidates, each detection round: the people the operator can choose from).
// Service ~select_worker (SelectWorker): the operator chooses the worker by an image point or a
//   candidate index (a point inside two people's boxes is refused); the tracker then keeps that
//   person (appearance + geometry) and does not start another identity by itself until
//   ~select_worker unlock — re-acquisition after a loss is by position or colour alone
//   (docs/perception.md "Choosing the worker", Known limits).
// Parameters (required): ~models_root (third_party_models), ~gesture_model (the LSTM's .onnx),
//   ~detector (movenet_multipose | blazepose), ~skeleton (movenet_lightning | blazepose_landmark),
//   ~detect_every_k, ~appearance (true: identity kept by the worker's colours too), ~min_depth_m, ~max_depth_m, ~depth_scale_m, ~max_depth_dt_s
//   (a depth image further than this from the colour image's stamp is not used; the nodelet keeps the
//   last DepthBuffer::kSize depth images and uses the one nearest the colour image's stamp — the two
//   topics are not delivered in order, and a colour image processed late must still find its depth).
// Optional: ~dnn_device (cpu): where the networks run — cpu, opencl, opencl_fp16, cuda, cuda_fp16
//   (refused at start, naming what this OpenCV can use, when it cannot run there).
//   ~track_max_side_px (96): the visual tracker works on the image shrunk so the worker's box is at
//   most this [px] (0: full resolution; its cost then grows with a close worker's box).
//   ~image_transport (raw): how image_in arrives, through image_transport (image_in/<transport>);
//   `compressed` (sensor_msgs/CompressedImage, JPEG / PNG) is decoded here with OpenCV when the
//   compressed_image_transport plugin is not installed (Debian ships the raw transport only).
//   ~depth_transport (raw): the same for depth_in, through image_transport only (a transport whose
//   plugin is not installed is refused at start, naming the ones that are).
// /diagnostics: `Perception`: images per second, found, gestures, images refused, colour frames whose
//   depth image was not aligned to them (another size or frame_id: no stereo range), the last image's age.
#include <algorithm>
#include <cmath>
#include <mutex>
#include <optional>

#include <image_transport/image_transport.h>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/CompressedImage.h>

#include "conversions.hpp"
#include "diagnostics.hpp"
#include "gesture_formation/Gesture.h"
#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/estimation/stereo_distance.hpp"
#include "gesture_formation/gesture/gesture_classifier.hpp"
#include "gesture_formation/perception/perception_pipeline.hpp"
#include "gesture_formation/perception/worker_tracker.hpp"
#include "depth_buffer.hpp"
#include "gesture_formation/onboard/frame_check.hpp"
#include "param_loader.hpp"
#include "worker_choice.hpp"

namespace gesture_formation::nodelets {

class PerceptionNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ParamLoader params(getPrivateNodeHandle());
    perception::PerceptionConfig cfg;
    std::string detector, skeleton, gesture_model;
    params.load("models_root", cfg.models_root);
    params.load("gesture_model", gesture_model);
    params.load("detector", detector);
    params.load("skeleton", skeleton);
    // One range per setting: the core's tables.
    params.load("detect_every_k", cfg.tracker.detect_every_k,
                *perception::workerTrackerFields().rangeOf("tracker.detect_every_k"));
    if (getPrivateNodeHandle().hasParam("track_max_side_px")) {
      double side = cfg.tracker.track_max_side_px;
      params.load("track_max_side_px", side, *perception::workerTrackerFields().rangeOf("tracker.track_max_side_px"));
      cfg.tracker.track_max_side_px = static_cast<float>(side);
    }
    bool appearance = true;
    params.load("appearance", appearance);
    cfg.tracker.appearance.enabled = appearance ? 1 : 0;
    const auto& stereo = estimation::stereoDistanceFields();
    params.load("min_depth_m", stereo_.min_depth_m, *stereo.rangeOf("min_depth_m"));
    params.load("max_depth_m", stereo_.max_depth_m, *stereo.rangeOf("max_depth_m"));
    params.load("depth_scale_m", stereo_.depth_scale_m, *stereo.rangeOf("depth_scale_m"));
    params.load("max_depth_dt_s", depths_.max_dt_s, 0.0, 1.0);
    std::string dnn_device;
    params.loadOptional("dnn_device", dnn_device, "cpu");
    if (const auto d = perception::parseDnnDevice(dnn_device)) cfg.dnn_device = *d;
    else params.addError("dnn_device: " + d.reason());
    if (!detector.empty()) {
      const auto k = perception::parseDetectorKind(detector);
      if (k) cfg.detector = *k;
      else params.addError("detector: " + k.reason());
    }
    if (!skeleton.empty()) {
      const auto k = perception::parseSkeletonKind(skeleton);
      if (k) cfg.skeleton = *k;
      else params.addError("skeleton: " + k.reason());
    }
    for (const auto& p : estimation::stereoDistanceProblems(stereo_)) params.addError(p.key + ": " + p.message);
    for (const auto& e : cfg.validate()) params.addError(e);
    loadTransports(params);
    if (params.ok()) {
      auto p = perception::PerceptionPipeline::create(cfg);
      if (p) pipeline_ = std::move(*p);
      else params.addError("models_root: " + p.reason());
      auto c = gesture::GestureClassifier::load(gesture_model);
      if (c) classifier_.emplace(std::move(*c));
      else params.addError("gesture_model: " + c.reason());
    }
    if (!params.ok()) {
      NODELET_ERROR_STREAM("Perception refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("Perception loaded:\n" << params.loaded());
    detection_pub_ = nh.advertise<gesture_formation::WorkerDetection>("detection_out", 10);
    gesture_pub_ = nh.advertise<gesture_formation::Gesture>("gesture_out", 10);
    candidates_pub_ = nh.advertise<gesture_formation::WorkerCandidates>("candidates_out", 2);
    select_srv_ = getPrivateNodeHandle().advertiseService("select_worker", &PerceptionNodelet::onSelectWorker, this);
    info_sub_ = nh.subscribe<sensor_msgs::CameraInfo>("camera_info_in", 2, [this](const sensor_msgs::CameraInfo::ConstPtr& m) {
      auto k = toIntrinsics(*m);
      std::lock_guard<std::mutex> lock(mutex_);
      if (k) {
        camera_.emplace(*k);
        camera_info_ = *m;
      } else {
        NODELET_WARN_STREAM_THROTTLE(5.0, "Perception: " << k.reason());
      }
    });
    // On the multi-threaded handle with its own lock: a depth image is stored at once, also while a
    // colour image is being processed (on the single-threaded handle it would queue behind it and
    // the depth stream would fall behind the colour stream on a busy computer).
    depth_sub_ = depth_it_->subscribe("depth_in", 2, &PerceptionNodelet::onDepth, this,
                                      image_transport::TransportHints(depth_transport_, ros::TransportHints(),
                                                                      getPrivateNodeHandle(), "depth_transport"));
    if (decode_compressed_) {
      compressed_sub_ = nh.subscribe(nh.resolveName("image_in") + "/compressed", 2,
                                     &PerceptionNodelet::onImage<sensor_msgs::CompressedImage>, this);
    } else {
      image_sub_ = image_it_->subscribe("image_in", 2, &PerceptionNodelet::onImage<sensor_msgs::Image>, this,
                                        image_transport::TransportHints(image_transport_, ros::TransportHints(),
                                                                        getPrivateNodeHandle(), "image_transport"));
    }
    diagnostics_.start(nh, 1.0, [this](double since_s) { return health(since_s); });
  }

  /// image_in's and depth_in's transports: each through image_transport when its plugin is
  /// installed; image_in's `compressed` without the plugin decoded here (decode_compressed_).
  void loadTransports(ParamLoader& params) {
    params.loadOptional("image_transport", image_transport_, "raw");
    params.loadOptional("depth_transport", depth_transport_, "raw");
    image_it_.emplace(getNodeHandle());
    depth_it_.emplace(getMTNodeHandle());
    const std::vector<std::string> loadable = image_it_->getLoadableTransports();
    const auto installed = [&](const std::string& t) {
      return std::find(loadable.begin(), loadable.end(), "image_transport/" + t) != loadable.end();
    };
    std::string names;
    for (const auto& l : loadable) names += (names.empty() ? "" : ", ") + l.substr(l.find('/') + 1);
    decode_compressed_ = image_transport_ == "compressed" && !installed("compressed");
    if (!installed(image_transport_) && !decode_compressed_) {
      params.addError("image_transport '" + image_transport_ + "': no such image_transport plugin installed (installed: " +
                      names + "; compressed is decoded here without one)");
    }
    if (!installed(depth_transport_)) {
      params.addError("depth_transport '" + depth_transport_ + "': no such image_transport plugin installed (installed: " + names + ")");
    }
  }

  void onDepth(const sensor_msgs::Image::ConstPtr& m) {
    depths_.add(m);
  }

  /// A colour image, raw (sensor_msgs/Image) or compressed (sensor_msgs/CompressedImage).
  template <class ImageMsg>
  void onImage(const boost::shared_ptr<const ImageMsg>& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto bgr = toBgr(*msg);
    if (!bgr) {
      ++refused_since_report_;
      NODELET_WARN_STREAM_THROTTLE(5.0, "Perception: image refused: " << bgr.reason());
      return;
    }
    process(msg->header, *bgr);
  }

  /// Perception on /diagnostics: WARN when no image arrived or images were refused since the last report.
  std::vector<diagnostic_msgs::DiagnosticStatus> health(double since_s) {
    std::lock_guard<std::mutex> lock(mutex_);
    Health h("Perception", image_transport_);
    h.warn(images_since_report_ == 0 && refused_since_report_ == 0, "no image on image_in")
        .warn(refused_since_report_ > 0, std::to_string(refused_since_report_) + " image(s) refused")
        .value("images_per_s", images_since_report_ / since_s)
        .value("found_per_s", found_since_report_ / since_s)
        .value("gestures_per_s", gestures_since_report_ / since_s)
        .value("refused", refused_since_report_)
        .warn(depth_refused_since_report_ > 0, std::to_string(depth_refused_since_report_) +
                                                   " frame(s) whose depth image was not aligned to the colour image (no stereo range)")
        .value("depth_refused", depth_refused_since_report_)
        .value("last_image_age_s", last_image_.isZero() ? -1.0 : (ros::Time::now() - last_image_).toSec())
        .value("image_transport", image_transport_ + (decode_compressed_ ? " (decoded here)" : ""));
    images_since_report_ = found_since_report_ = gestures_since_report_ = refused_since_report_ = depth_refused_since_report_ = 0;
    return {h.status()};
  }

  /// One colour image (caller holds mutex_): the pipeline, the stereo range, the classifier.
  void process(const std_msgs::Header& header, const cv::Mat& bgr) {
    ++images_since_report_;
    last_image_ = header.stamp;
    auto frame = pipeline_->step(bgr);
    if (!frame) {
      NODELET_WARN_STREAM_THROTTLE(5.0, "Perception: " << frame.reason());
      return;
    }
    if (frame->track.detector_ran) {
      candidates_pub_.publish(toCandidates(header, ++candidate_round_, frame->track, pipeline_->tracker().locked()));
    }
    gesture_formation::WorkerDetection d;
    d.header = header;
    d.detected = frame->track.found;
    d.stereo_distance_m = std::nan("");
    if (frame->track.found) {
      const cv::Rect2f& b = frame->track.box_px;
      d.u = b.x;
      d.v = b.y;
      d.w = b.width;
      d.h = b.height;
      // The detector's score of the worker's last detection (the tracker reports none).
      const auto& t = frame->track;
      if (t.identity_changed) last_score_ = 0.0f;
      if (t.worker_detection >= 0) last_score_ = t.detections[static_cast<std::size_t>(t.worker_detection)].score;
      d.confidence = last_score_;
      sensor_msgs::Image::ConstPtr depth_msg = depths_.nearest(header.stamp);
      // The depth must be aligned to this colour image: its size and frame (an unaligned or wrongly
      // remapped depth topic gave a range from the wrong pixels, clipped in silence).
      if (depth_msg) {
        if (const auto why = onboard::depthAlignmentProblem(static_cast<int>(depth_msg->width), static_cast<int>(depth_msg->height),
                                                           depth_msg->header.frame_id, bgr.cols, bgr.rows, header.frame_id)) {
          ++depth_refused_since_report_;
          NODELET_WARN_STREAM_THROTTLE(5.0, "Perception: depth image not used: " << *why);
          depth_msg.reset();
        }
      }
      if (depth_msg && camera_) {
        auto depth = toDepth(*depth_msg);
        const estimation::Box box{d.u, d.v, d.w, d.h};
        auto range = depth ? estimation::stereoDistance(*depth, box, *camera_, stereo_)
                           : common::Result<double>::fail(depth.reason());
        if (range) d.stereo_distance_m = *range;
        else NODELET_DEBUG_STREAM_THROTTLE(5.0, "Perception: no stereo range: " << range.reason());
      }
    }
    if (d.detected) ++found_since_report_;
    detection_pub_.publish(d);
    if (!frame->fifo_full) return;
    const std::vector<float> window = pipeline_->classifierInput();
    auto c = classifier_->classify(window.data());
    if (!c) {
      NODELET_WARN_STREAM_THROTTLE(5.0, "Perception: classifier: " << c.reason());
      return;
    }
    gesture_formation::Gesture g;
    g.header = header;
    g.gesture_id = c->gesture_id;
    g.probabilities.assign(c->probabilities.begin(), c->probabilities.end());
    if (frame->has_skeleton && camera_info_) {  // the window's newest skeleton, in this image's pixels
      g.keypoints.reserve(3 * frame->skeleton.size());
      for (const perception::Keypoint& k : frame->skeleton) g.keypoints.insert(g.keypoints.end(), {k.x, k.y, k.c});
      g.camera = *camera_info_;
    }
    gesture_pub_.publish(g);
    ++gestures_since_report_;
  }

  bool onSelectWorker(gesture_formation::SelectWorker::Request& req, gesture_formation::SelectWorker::Response& res) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (pipeline_) res = selectWorker(pipeline_->tracker(), req, candidate_round_);
    else res.message = "perception is not running";
    if (res.accepted) NODELET_INFO_STREAM("Perception: " << res.message);
    return true;
  }

  std::mutex mutex_;
  std::unique_ptr<perception::PerceptionPipeline> pipeline_;
  std::optional<gesture::GestureClassifier> classifier_;
  estimation::StereoDistanceConfig stereo_;
  DepthBuffer depths_;  ///< the last depth images (depth_in)
  float last_score_ = 0.0f;
  std::optional<estimation::CameraModel> camera_;
  std::optional<sensor_msgs::CameraInfo> camera_info_;  ///< the last usable one (its intrinsics are camera_'s)
  std::string image_transport_, depth_transport_;
  bool decode_compressed_ = false;  ///< image_transport compressed without its plugin: decoded here
  int images_since_report_ = 0, found_since_report_ = 0, gestures_since_report_ = 0, refused_since_report_ = 0;
  int depth_refused_since_report_ = 0;  ///< depth images of another size or frame than the colour image
  ros::Time last_image_;
  DiagnosticsPublisher diagnostics_;
  std::optional<image_transport::ImageTransport> image_it_, depth_it_;
  std::uint32_t candidate_round_ = 0;  ///< detection rounds published on candidates_out
  ros::ServiceServer select_srv_;
  ros::Publisher detection_pub_, gesture_pub_, candidates_pub_;
  ros::Subscriber info_sub_, compressed_sub_;
  image_transport::Subscriber depth_sub_, image_sub_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::PerceptionNodelet, nodelet::Nodelet)

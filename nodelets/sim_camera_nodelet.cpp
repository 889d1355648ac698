// SimCamera nodelet: one simulated UAV's RGB-D camera, rendered (simulation.launch camera:=rendered;
// docs/ros.md "Rendered cameras"). At its camera rate in sim time it renders, with the core of
// `gfctl simulate --camera rendered` (sim::SceneRenderer: the mission's world, the worker mesh posed
// from the worker model's 3-D body, the other UAVs), the colour image and the aligned depth at the
// UAV's true camera pose, and publishes them with the CameraInfo on the RealSense driver's topics,
// which the onboard Perception nodelet reads. It runs in the UAV's nodelet manager beside that
// Perception nodelet (the images are passed without a copy) and renders in parallel with the other
// UAVs' cameras (each manager process has its own GL context).
//
// Topics: worker_body_in (WorkerBody from SimWorld at each of its camera frames: the frame's time
//   and the worker's body), uav<j>/ground_truth for every UAV j of the mission (nav_msgs/Odometry,
//   SimUav's true states: this UAV's camera pose, the other UAVs' bodies)
//   → color_out (sensor_msgs/Image rgb8), depth_out (sensor_msgs/Image 32FC1, metres along the
//   optical axis, NaN where nothing is seen, REP 118), camera_info_out (sensor_msgs/CameraInfo:
//   the mission's intrinsics, distortion 0 — the rectified image), all stamped with the
//   WorkerBody's time, frame_id ~camera_frame.
// A frame is rendered for the first WorkerBody at (within half of SimWorld's frame period) or
// after each multiple of 1/camera_rate_hz; a WorkerBody that arrives while the previous frame is
// rendering replaces the waiting one (a slow renderer drops frames, it does not fall behind).
// Rendering runs on the nodelet's own thread, which owns the GL context (created, made current
// and used there only) and holds none of the manager's workers. The UAV states are the ground
// truths nearest the frame's time. No frame in the mission's camera blackouts (the leader) or
// while this follower is offline (follower_dropouts), as gfctl simulate.
// Parameters (required): ~mission_file (+ optional ~faults_file), ~seed (the worker's outfit, as
//   gfctl simulate --seed), ~uav_index, ~camera_rate_hz (0.5 .. the mission's
//   sensors.camera.rate_hz), ~models_root (the mannequin asset), ~camera_frame.
#include <cmath>
#include <condition_variable>
#include <deque>
#include <future>
#include <mutex>
#include <thread>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>

#include "sim_config_sources.hpp"
#include "sim_conversions.hpp"
#include "gesture_formation/comm/payloads.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/sim/scene_renderer.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class SimCameraNodelet : public nodelet::Nodelet {
 public:
  ~SimCameraNodelet() override {
    {
      std::lock_guard<std::mutex> lock(mail_mutex_);
      stop_ = true;
    }
    mail_cv_.notify_all();
    if (render_thread_.joinable()) render_thread_.join();
  }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ParamLoader params(getPrivateNodeHandle());
    std::string mission_file, models_root;
    int seed = 0;
    params.load("mission_file", mission_file);
    params.load("seed", seed, 0, 1 << 30);
    params.load("uav_index", index_, 0, comm::kMaxUavIndex);
    params.load("camera_rate_hz", rate_hz_, 0.5, 60.0);
    params.load("models_root", models_root);
    params.load("camera_frame", camera_frame_);
    if (!mission_file.empty() && loadMission(mission_file, params, cfg_)) checkMission(params);
    if (params.ok()) startRenderer(mission_file, models_root, static_cast<std::uint64_t>(seed), params);
    if (!params.ok()) {
      NODELET_ERROR_STREAM("SimCamera refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("SimCamera loaded:\n" << params.loaded() << "rendering with " << scene_->glRenderer());
    intrinsics_ = sim::renderedIntrinsics(cfg_);
    info_ = toCameraInfo(intrinsics_);
    info_.header.frame_id = camera_frame_;
    color_pub_ = nh.advertise<sensor_msgs::Image>("color_out", 2);
    depth_pub_ = nh.advertise<sensor_msgs::Image>("depth_out", 2);
    info_pub_ = nh.advertise<sensor_msgs::CameraInfo>("camera_info_out", 2);
    const std::size_t n = cfg_.uavs.size();
    truths_.resize(n);
    for (std::size_t j = 0; j < n; ++j) {
      truth_subs_.push_back(nh.subscribe<nav_msgs::Odometry>(
          "uav" + std::to_string(j) + "/ground_truth", 20, [this, j](const nav_msgs::Odometry::ConstPtr& m) {
            std::lock_guard<std::mutex> lock(truth_mutex_);
            auto& h = truths_[j];
            h.push_back(Stamped{m->header.stamp.toSec(), toMultirotorState(*m)});
            while (h.size() > kTruthHistory) h.pop_front();
          }));
    }
    body_sub_ = nh.subscribe("worker_body_in", 5, &SimCameraNodelet::onBody, this);
  }

  void checkMission(ParamLoader& params) const {
    if (index_ >= static_cast<int>(cfg_.uavs.size())) {
      params.addError("uav_index: " + std::to_string(index_) + " but the mission has " + std::to_string(cfg_.uavs.size()) +
                      " UAVs");
    }
    if (rate_hz_ > cfg_.camera.rate_hz) {
      params.addError("camera_rate_hz: " + std::to_string(rate_hz_) + " exceeds the mission's sensors.camera.rate_hz " +
                      std::to_string(cfg_.camera.rate_hz) + " (SimWorld's frames)");
    }
  }

  /// Starts the render thread, which opens the renderer (its GL context lives on that thread);
  /// a failure to open it is a parameter error.
  void startRenderer(const std::string& mission_file, const std::string& models_root, std::uint64_t seed,
                     ParamLoader& params) {
    auto scenario = planning::loadScenario(mission_file);
    if (!scenario) {
      params.addError("mission_file: " + scenario.reason());
      return;
    }
    std::promise<std::string> opened;
    std::future<std::string> error = opened.get_future();
    render_thread_ = std::thread([this, sc = std::move(*scenario), mission_file, models_root, seed, &opened]() {
      auto scene = sim::SceneRenderer::create(models_root, sc, seed);
      if (!scene) {
        opened.set_value(scene.reason());
        return;
      }
      // The scenario's unmapped obstacles, drawn where they are at each frame's time.
      auto unmapped = sim::loadUnmappedObstacles(mission_file);
      if (!unmapped) {
        opened.set_value("mission_file: " + unmapped.reason());
        return;
      }
      if (auto set = (*scene)->setUnmappedObstacles(std::move(*unmapped)); !set) {
        opened.set_value(set.reason());
        return;
      }
      scene_ = std::move(*scene);
      opened.set_value("");
      renderLoop();
    });
    const std::string e = error.get();
    if (!e.empty()) {
      params.addError("rendering (models_root " + models_root + "): " + e);
      render_thread_.join();
    }
  }

  void onBody(const gesture_formation::WorkerBody::ConstPtr& m) {
    {
      std::lock_guard<std::mutex> lock(mail_mutex_);
      pending_ = m;  // replaces a body not yet taken
    }
    mail_cv_.notify_all();
  }

  void renderLoop() {
    for (;;) {
      gesture_formation::WorkerBody::ConstPtr m;
      {
        std::unique_lock<std::mutex> lock(mail_mutex_);
        mail_cv_.wait(lock, [this]() { return stop_ || pending_; });
        if (stop_) return;
        m.swap(pending_);
      }
      renderFrame(*m);
    }
  }

  /// Whether this UAV's camera delivers a frame at `t_s` (the mission's faults, as gfctl simulate).
  bool cameraOn(double t_s) const {
    if (index_ > 0) return !cfg_.faults.followerOffline(index_, t_s);
    for (const auto& [from, to] : cfg_.faults.camera_blackouts) {
      if (t_s >= from && t_s < to) return false;
    }
    return true;
  }

  void renderFrame(const gesture_formation::WorkerBody& m) {
    const double t = m.header.stamp.toSec();
    // SimWorld's frames fall on its clock steps: a body within half its frame period of a grid
    // point of this camera's rate is that grid point's.
    const double half_s = 0.5 / cfg_.camera.rate_hz;
    if (t + half_s < next_frame_s_ || !cameraOn(t)) return;
    const auto body = fromWorkerBodyMsg(m);
    if (!body) {
      NODELET_WARN_STREAM_THROTTLE(5.0, "SimCamera: " << body.reason());
      return;
    }
    std::vector<sim::MultirotorState> uavs;
    if (!statesAt(t, uavs)) return;  // not every UAV is up yet
    next_frame_s_ = (std::floor((t + half_s) * rate_hz_) + 1.0) / rate_hz_;
    const auto wall0 = ros::WallTime::now();
    const auto set = scene_->setScene(*body, toEigen(m.feet_world), m.heading_rad, cfg_.worker.height_m, uavs, t);
    if (!set) NODELET_WARN_STREAM_THROTTLE(5.0, "SimCamera: t " << t << " s: " << set.reason());
    auto frame = scene_->render(static_cast<std::size_t>(index_), intrinsics_);
    if (!frame) {
      NODELET_ERROR_STREAM_THROTTLE(5.0, "SimCamera: t " << t << " s: render: " << frame.reason());
      return;
    }
    publish(*frame, m.header.stamp);
    const double ms = (ros::WallTime::now() - wall0).toSec() * 1e3;
    render_ms_sum_ += ms;
    if (++frames_ % 50 == 0) {
      NODELET_INFO_STREAM("SimCamera uav" << index_ << ": " << frames_ << " frames, mean " << render_ms_sum_ / frames_
                                          << " ms wall per frame (render + read-back + messages)");
    }
  }

  /// Every UAV's true state nearest `t_s` (false while one has none).
  bool statesAt(double t_s, std::vector<sim::MultirotorState>& out) {
    std::lock_guard<std::mutex> lock(truth_mutex_);
    for (const auto& h : truths_) {
      if (h.empty()) return false;
      const Stamped* best = &h.front();
      for (const Stamped& s : h) {
        if (std::abs(s.t_s - t_s) < std::abs(best->t_s - t_s)) best = &s;
      }
      out.push_back(best->state);
    }
    return true;
  }

  /// CameraInfo, then depth, then colour: the Perception nodelet finds a colour image's depth
  /// already stored.
  void publish(const render::RenderedFrame& f, const ros::Time& stamp) {
    auto colour = toImage(f.rgb, "rgb8");
    auto depth = toImage(f.depth_m, "32FC1");
    if (!colour || !depth) {
      NODELET_ERROR_STREAM_THROTTLE(5.0, "SimCamera: " << (colour ? depth.reason() : colour.reason()));
      return;
    }
    info_.header.stamp = stamp;
    info_pub_.publish(info_);
    for (auto* img : {&*depth, &*colour}) {
      img->header.stamp = stamp;
      img->header.frame_id = camera_frame_;
    }
    depth_pub_.publish(boost::make_shared<sensor_msgs::Image>(std::move(*depth)));
    color_pub_.publish(boost::make_shared<sensor_msgs::Image>(std::move(*colour)));
  }

  struct Stamped {
    double t_s;
    sim::MultirotorState state;
  };
  static constexpr std::size_t kTruthHistory = 100;  ///< 2 s of SimUav's 50 Hz ground truth

  sim::MissionConfig cfg_;
  std::unique_ptr<sim::SceneRenderer> scene_;  ///< used on render_thread_ only
  std::thread render_thread_;
  std::mutex mail_mutex_;  ///< guards pending_, stop_
  std::condition_variable mail_cv_;
  gesture_formation::WorkerBody::ConstPtr pending_;  ///< the newest body not yet taken
  bool stop_ = false;
  estimation::CameraIntrinsics intrinsics_;
  sensor_msgs::CameraInfo info_;
  std::string camera_frame_;
  int index_ = 0;
  double rate_hz_ = 5.0, next_frame_s_ = 0.0, render_ms_sum_ = 0.0;
  long frames_ = 0;
  std::mutex truth_mutex_;
  std::vector<std::deque<Stamped>> truths_;
  ros::Publisher color_pub_, depth_pub_, info_pub_;
  std::vector<ros::Subscriber> truth_subs_;
  ros::Subscriber body_sub_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::SimCameraNodelet, nodelet::Nodelet)

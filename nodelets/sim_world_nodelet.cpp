// SimWorld nodelet: the simulated mission's world on the sim core of `gfctl simulate` (docs/ros.md
// "SimWorld"): sim time (/clock, from when every UAV's planner is up), the worker (sim::WorkerModel),
// the cameras (sim::LeaderCamera: box, stereo and UWB with the sensor faults; each UAV's classification
// as its Perception nodelet would publish it), the operator's scheduled requests and faults.abort
// (through the ground's OperatorInterface, as an operator), the record (sim::WorldRecord: metrics,
// plans, modes, outcomes, abort states, files). ~camera rendered: SimCamera renders the worker's body
// (worker_body_out) for the Perception nodelets; the leader's detections (detection_in) feed the metrics.
#include <algorithm>
#include <mutex>
#include <optional>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <std_msgs/Bool.h>
#include <tf2_ros/transform_broadcaster.h>

#include "sim_config_sources.hpp"
#include "sim_conversions.hpp"
#include "sim_start_gate.hpp"
#include "gesture_formation/GestureStatus.h"
#include "gesture_formation/SendAbort.h"
#include "gesture_formation/formation/worker_heading.hpp"
#include "gesture_formation/sim/leader_camera.hpp"
#include "gesture_formation/sim/random.hpp"
#include "gesture_formation/sim/world_record.hpp"
#include "gesture_formation/sim/worker_model.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class SimWorldNodelet : public nodelet::Nodelet {
 public:
  ~SimWorldNodelet() override { clock_timer_.stop(); }

 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ParamLoader params(getPrivateNodeHandle());
    loadSimWorldSettings(params, set_);
    const std::string& mission_file = set_.mission_file;
    if (!mission_file.empty() && loadMission(mission_file, params, cfg_)) loadWorldMap(mission_file, params, world_);
    if (params.ok() && !cfg_.gesture_model.empty()) {
      auto c = sim::loadOnnxClassifier(cfg_.gesture_model);
      if (!c) params.addError("mission_file: gesture_model " + cfg_.gesture_model + ": " + c.reason());
      else classifier_ = std::move(*c);
    }
    if (!params.ok()) {
      NODELET_ERROR_STREAM("SimWorld refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("SimWorld loaded:\n" << params.loaded());
    for (const auto& w : sim::gestureReadabilityWarnings(cfg_)) NODELET_WARN_STREAM("SimWorld: " << w);
    if (set_.duration_s <= 0.0) set_.duration_s = cfg_.duration_s;
    const auto s = static_cast<std::uint64_t>(set_.seed);
    worker_.emplace(cfg_.worker, sim::mixSeed(s ^ static_cast<std::uint64_t>(sim::Stream::kWorker)));
    camera_.emplace(cfg_, world_.map.get(), s);
    camera_frames_.emplace(1.0 / cfg_.camera.rate_hz, set_.clock_step_s);
    timeline_samples_.emplace(1.0 / cfg_.timeline_rate_hz, set_.clock_step_s);
    record_.emplace(cfg_, sim::ObstacleDistance{world_.field.get(), world_.solids.get(), world_.ground_height_m}, s);
    heading_.emplace(cfg_.formation.worker_heading);
    n_ = cfg_.formation.params.uavCount();
    truth_.resize(static_cast<std::size_t>(n_));

    clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
    worker_pub_ = nh.advertise<nav_msgs::Odometry>("worker_truth_out", 10);
    uwb_pub_ = nh.advertise<sensor_msgs::Range>("uwb_out", 10);
    follower_views_ = cfg_.view_fusion.min_agreeing_views > 1;  // as sim::runMission
    if (set_.rendered) {
      // The cameras are rendered (SimCamera) and seen by the Perception nodelets: no detection and
      // no classification from here, only the body they render.
      body_pub_ = nh.advertise<gesture_formation::WorkerBody>("worker_body_out", 10);
      detection_sub_ = nh.subscribe("detection_in", 20, &SimWorldNodelet::onLeaderDetection, this);
    } else {
      detection_pub_ = nh.advertise<gesture_formation::WorkerDetection>("detection_out", 10);
      info_pub_ = nh.advertise<sensor_msgs::CameraInfo>("camera_info_out", 2);  // the leader camera's, every frame
      info_ = toCameraInfo(cfg_.camera.camera);
      info_.header.frame_id = set_.camera_frame;
      for (int i = 0; i < (follower_views_ ? n_ : 1); ++i) gesture_pubs_.push_back(nh.advertise<gesture_formation::Gesture>("uav" + std::to_string(i) + "/gesture_out", 10));
    }
    command_pub_ = nh.advertise<gesture_formation::FormationCommand>("operator_command_out", 20);
    done_pub_ = nh.advertise<std_msgs::Bool>("done_out", 1, true);
    for (int i = 0; i < n_; ++i) {  // each UAV's truth, plans and abort state, recorded until the end
      truth_subs_.push_back(perUav<nav_msgs::Odometry>(nh, i, "ground_truth", [this](int k, const nav_msgs::Odometry& m) {
        truth_[static_cast<std::size_t>(k)] = toMultirotorState(m);
      }));
      plan_subs_.push_back(perUav<gesture_formation::PlannedTrajectory>(nh, i, "plan", [this](int k, const gesture_formation::PlannedTrajectory& m) {
        const auto status = planStatusFromName(m.status);
        if (status) record_->plan(toPlanReport(k, m, *status));
        else NODELET_WARN_STREAM_THROTTLE(5.0, "SimWorld: plan not counted: " << status.reason());
      }));
      abort_subs_.push_back(perUav<gesture_formation::AbortState>(
          nh, i, "abort_state", [this](int k, const gesture_formation::AbortState& m) { record_->abortState(toAbortReport(k, m)); }));
    }
    // faults.abort: asked of the ground station's OperatorInterface as an operator does.
    abort_client_ = nh.serviceClient<gesture_formation::SendAbort>("send_abort");
    params_sub_ = nh.subscribe("leader_params_in", 20, &SimWorldNodelet::onParams, this);
    estimate_sub_ = nh.subscribe<gesture_formation::WorkerState>(
        "worker_estimate_in", 10, [this](const gesture_formation::WorkerState::ConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          estimate_ = *m;
          if (!m->lost) heading_->update(toEigen(m->velocity));  // the leader's ^Hφ follows its estimate
        });
    status_sub_ = nh.subscribe("gesture_status_in", 50, &SimWorldNodelet::onGestureStatus, this);
    gate_.arm();
    publishClock();
    clock_timer_ = nh.createWallTimer(ros::WallDuration(set_.clock_step_s / set_.real_time_factor), &SimWorldNodelet::onClock, this);
  }

  /// uav<i>/<topic>, handed to `f(i, msg)` under the lock until the mission finished.
  template <class Msg, class F>
  ros::Subscriber perUav(ros::NodeHandle& nh, int i, const std::string& topic, F f) {
    return nh.subscribe<Msg>("uav" + std::to_string(i) + "/" + topic, 10, [this, i, f](const typename Msg::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!finished_) f(i, *m);
    });
  }

  void onParams(const gesture_formation::FormationParams::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!finished_) record_->params(toParamsReport(*m));
  }

  /// Rendered cameras: `visible` holds this long after the leader's Perception last found the worker.
  static constexpr double kRenderedVisibleS = 1.0;

  /// Rendered cameras: the leader's Perception output per processed frame (visibility, estimate error).
  void onLeaderDetection(const gesture_formation::WorkerDetection::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_ || !gate_.started()) return;
    const double t = m->header.stamp.toSec();
    if (m->detected) last_detected_s_ = t;
    const std::optional<Eigen::Vector3d> est = estimateAt(t);
    record_->metrics().cameraFrame(m->detected, est ? &*est : nullptr, worker_->stateAt(t).p_world);
  }

  void onGestureStatus(const gesture_formation::GestureStatus::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    last_class_ = m->gesture_id;
    last_ratio_ = m->dominant_ratio;
    if (finished_ || !m->fired) return;
    record_->gestureFired(m->header.stamp.toSec(), m->dominant_id, cfg_.gesture_mapping);
  }

  void publishClock() {
    rosgraph_msgs::Clock c;
    c.clock = ros::Time(std::max(t_, 1e-6));
    clock_pub_.publish(c);
  }

  void onClock(const ros::WallTimerEvent&) {
    // faults.abort at its time: the operator's abort through the OperatorInterface's send_abort (it
    // numbers the command and has the ground station's LcmBridge send its copies to every UAV);
    // outside the lock: the service call waits for the OperatorInterface.
    if (!tick()) return;
    gesture_formation::SendAbort srv;
    const bool sent = abort_client_.call(srv) && srv.response.accepted;
    if (!sent) NODELET_ERROR_STREAM("SimWorld: faults.abort: send_abort failed" << (abort_client_.exists() ? ": " : " (no service)") << srv.response.message);
    else NODELET_WARN_STREAM("SimWorld: faults.abort: the operator's abort #" << srv.response.sequence << " sent (" << srv.response.copies << " copies)");
  }

  /// One clock step; true when faults.abort falls due in it.
  bool tick() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return false;
    if (!gate_.open(plan_subs_)) {  // sim time starts once every UAV's planner is up
      publishClock();
      return false;
    }
    ++k_;
    t_ = static_cast<double>(k_) * set_.clock_step_s;
    publishClock();
    record_->divertWorker(t_, *worker_, truth_);  // faults.worker_approach, at its time
    const sim::WorkerState ws = worker_->stateAt(t_);
    // Operator requests (the OperatorInterface numbers them and sends them over LCM).
    for (const auto& c : record_->dueRequests(t_)) {
      auto m = toMsg(c);
      m.header.stamp = ros::Time(t_);
      command_pub_.publish(m);
    }
    const bool all = record_->sampleSafety(t_, truth_, ws);  // false until every UAV's truth came
    // With the followers' cameras a frame needs every UAV's truth (the same number of followers every call).
    if (camera_frames_->due(k_) && (follower_views_ ? all : truth_[0].has_value())) cameraFrame(ws);
    if (timeline_samples_->due(k_)) sample(ws, all);
    const bool abort_due = record_->abortDue(t_);
    if (t_ >= set_.duration_s - 1e-9) finish();
    return abort_due;
  }

  /// The leader's estimate predicted to t_s (nullopt before the first one).
  std::optional<Eigen::Vector3d> estimateAt(double t_s) const {
    if (!estimate_) return std::nullopt;
    return toWorkerKnowledge(*estimate_).positionAt(t_s);
  }

  /// UAV `uav`'s classification as its Perception nodelet would publish it (with the 3-D
  /// confirmation: the skeleton and its camera on tf, toGestureMsg).
  void publishGesture(int uav, const gesture::Classification& c, const ros::Time& stamp,
                      const gesture::CalibratedSkeleton* skeleton) {
    const auto& truth = truth_[static_cast<std::size_t>(uav)];
    geometry_msgs::TransformStamped T;
    const auto g = toGestureMsg(uav, c, stamp, skeleton, truth ? &*truth : nullptr, &T);
    if (!T.child_frame_id.empty()) tf_.sendTransform(T);
    gesture_pubs_[static_cast<std::size_t>(uav)].publish(g);
  }

  void cameraFrame(const sim::WorkerState& ws) {
    std::vector<sim::MultirotorState> followers;
    std::vector<bool> online;
    for (int i = 1; follower_views_ && i < n_; ++i) {
      followers.push_back(*truth_[static_cast<std::size_t>(i)]);
      online.push_back(!cfg_.faults.followerOffline(i, t_));
    }
    // The worker's performance advances in both modes; rendered cameras: only its body leaves.
    const sim::LeaderCameraFrame cf =
        camera_->frame(t_, *truth_[0], followers, online, ws, *worker_, set_.rendered ? nullptr : classifier_.get());
    record_->metrics().counters().range_outliers += cf.range_outliers;
    const ros::Time stamp(t_);
    if (set_.rendered) {
      body_pub_.publish(toWorkerBodyMsg(worker_->bodyAt(t_), ws.feet_world, ws.heading_rad, stamp, set_.world_frame));
    } else {
      const std::optional<Eigen::Vector3d> est = estimateAt(t_);
      record_->metrics().cameraFrame(cf.sensors.visible(), est ? &*est : nullptr, ws.p_world);
    }
    if (std::isfinite(cf.sensors.d_uwb_m)) uwb_pub_.publish(toUwbRange(cf.sensors.d_uwb_m, cfg_.uwb.max_range_m, stamp, set_.camera_frame));
    if (set_.rendered) return;  // the Perception nodelets see the rendered images
    info_.header.stamp = stamp;
    info_pub_.publish(info_);
    // Each UAV's classifier output, the followers' first (the leader's closes the frame at the GestureCommander).
    for (std::size_t i = 0; i < cf.followers.size(); ++i) {
      const auto& f = cf.followers[i];
      if (f.classification) publishGesture(static_cast<int>(i) + 1, *f.classification, stamp,
                                           cfg_.view_fusion.usesCalibratedViews() && f.visible ? &f.calibrated : nullptr);
    }
    if (!cf.sensors.visible()) return;
    detection_pub_.publish(toDetectionMsg(cf.sensors, stamp, set_.camera_frame));
    if (cf.classification) publishGesture(0, *cf.classification, stamp, cfg_.view_fusion.usesCalibratedViews() ? &cf.calibrated : nullptr);
  }

  void sample(const sim::WorkerState& ws, bool all_truths) {
    worker_pub_.publish(toWorkerTruthMsg(ws, ros::Time(t_), set_.world_frame));
    if (!all_truths) return;  // not every UAV is up yet
    sim::TimelineInput in;
    in.t_s = t_;
    in.worker = ws;
    if (const auto est = estimateAt(t_)) in.estimate_world = *est;
    // Rendered cameras: the leader's Perception found the worker within kRenderedVisibleS.
    in.visible = (set_.rendered ? last_detected_s_ > t_ - kRenderedVisibleS : camera_->lastVisibleS() > t_ - 0.2) ? 1 : 0;
    in.gesture_true = worker_->performingAt(t_);
    in.gesture_class = last_class_;
    in.dominant_ratio = last_ratio_;
    in.params = record_->currentParams();
    in.human_heading_rad = heading_->heading();
    for (const auto& s : truth_) in.uavs.push_back(*s);
    record_->metrics().sampleTimeline(in);
  }

  void finish() {
    finished_ = true;
    const double wall = gate_.wallSinceStart();
    // metrics.json last: its appearance tells tools/run_ros_mission.sh that the files are complete.
    std::string err, warning;
    if (!record_->finish(worker_->episodes(), t_, wall, set_.output_dir, &err, &warning)) NODELET_ERROR_STREAM("SimWorld: " << err);
    if (!warning.empty()) NODELET_WARN_STREAM("SimWorld: " << warning);
    NODELET_INFO_STREAM("SimWorld: mission done at t = " << t_ << " s (" << wall << " s wall); wrote " << set_.output_dir
                                                         << "/metrics.json");
    done_pub_.publish([] { std_msgs::Bool b; b.data = true; return b; }());
  }

  std::mutex mutex_;
  sim::MissionConfig cfg_;
  WorldMap world_;
  std::unique_ptr<sim::MissionClassifier> classifier_;
  std::optional<sim::WorkerModel> worker_;
  std::optional<sim::LeaderCamera> camera_;
  std::optional<sim::StepSchedule> camera_frames_, timeline_samples_;
  std::optional<sim::WorldRecord> record_;  ///< metrics, plans and modes, command outcomes, the files
  std::optional<formation::WorkerHeading> heading_;
  SimWorldSettings set_;  ///< the nodelet's parameters (duration: the mission's if not given)
  double t_ = 0.0, last_ratio_ = 0.0, last_detected_s_ = -1e9;  ///< last detected: the leader's Perception (rendered)
  long k_ = 0;
  int n_ = 0, last_class_ = -1;
  bool finished_ = false, follower_views_ = false;
  SimStartGate gate_;  ///< sim time starts once every UAV's planner is up
  std::vector<std::optional<sim::MultirotorState>> truth_;
  std::optional<gesture_formation::WorkerState> estimate_;
  ros::Publisher clock_pub_, worker_pub_, detection_pub_, uwb_pub_, command_pub_, done_pub_, body_pub_, info_pub_;
  sensor_msgs::CameraInfo info_;  ///< synthetic camera: the leader camera's intrinsics (the estimator's camera model)
  tf2_ros::TransformBroadcaster tf_;  ///< the gesture cameras (3-D confirmation)
  std::vector<ros::Publisher> gesture_pubs_;  ///< per UAV (only the leader's without follower views)
  std::vector<ros::Subscriber> truth_subs_, plan_subs_, abort_subs_;
  ros::ServiceClient abort_client_;
  ros::Subscriber params_sub_, estimate_sub_, status_sub_, detection_sub_;
  ros::WallTimer clock_timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::SimWorldNodelet, nodelet::Nodelet)

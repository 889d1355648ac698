// SimWorld nodelet: the simulated mission's world on the sim core of `gfctl simulate` (docs/ros.md
// "SimWorld"): sim time (/clock, from when every UAV's planner is up), the worker (sim::WorkerModel),
// the cameras (sim::LeaderCamera: box, stereo and UWB with the sensor faults; each UAV's classification
// as its Perception nodelet would publish it), the operator's scheduled requests, faults.abort and
// faults.leader_silence (sim_world_calls.hpp), the record (sim::WorldRecord: metrics,
// plans, modes, outcomes, abort states, files). ~camera rendered: SimCamera renders the worker's body
// (worker_body_out) for the Perception nodelets; the leader's detections (detection_in) feed the metrics.
// ~leadership (optional, default false; docs/safety.md §1.2): the leader camera is the acting leader's
// (every UAV's leadership_state; UAV 0 until another acts), and the leader's estimate, parameters and
// gesture status are the acting UAV's (uav<k>/worker_state, every uav<k>/formation_params and
// gesture_status) — the synthetic camera only (rendered: the detections of detection_in, UAV 0's).
#include <algorithm>
#include <mutex>
#include <optional>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <std_msgs/Bool.h>

#include "sim_camera_topics.hpp"
#include "sim_config_sources.hpp"
#include "sim_start_gate.hpp"
#include "sim_world_calls.hpp"
#include "gesture_formation/GestureStatus.h"
#include "gesture_formation/LeadershipState.h"
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
    loadSimWorld(params, set_, cfg_, world_, site_);
    if (params.ok() && !cfg_.gesture_model.empty()) {
      auto c = sim::loadOnnxClassifier(cfg_.gesture_model);
      if (!c) params.addError("mission_file: gesture_model " + cfg_.gesture_model + ": " + c.reason());
      else classifier_ = std::move(*c);
    }
    if (const auto why = SimWorldCalls::checkSilence(cfg_.faults.leader_silence, set_.leadership); !why.empty()) params.addError(why);
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
    record_.emplace(cfg_, site_.distance(world_, &t_), s);  // the unmapped obstacles where they are at t_
    heading_.emplace(cfg_.formation.worker_heading);
    n_ = cfg_.formation.params.uavCount();
    truth_.resize(static_cast<std::size_t>(n_));

    clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
    worker_pub_ = nh.advertise<nav_msgs::Odometry>("worker_truth_out", 10);
    follower_views_ = cfg_.view_fusion.min_agreeing_views > 1;  // as sim::runMission
    camera_topics_.advertise(nh, n_, set_.rendered, toCameraInfo(cfg_.camera.camera), set_.camera_frame, cfg_.uwb.max_range_m,
                             cfg_.view_fusion.usesCalibratedViews());
    if (set_.rendered) {
      // The cameras are rendered (SimCamera) and seen by the Perception nodelets: no detection and
      // no classification from here, only the body they render.
      body_pub_ = nh.advertise<gesture_formation::WorkerBody>("worker_body_out", 10);
      detection_sub_ = nh.subscribe("detection_in", 20, &SimWorldNodelet::onLeaderDetection, this);
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
      if (set_.leadership) subscribeLeader(nh, i);
    }
    // faults.abort: asked of the ground station's OperatorInterface as an operator does.
    calls_.init(nh);
    if (!set_.leadership) {  // UAV 0 does the leader's work
      leader_subs_.push_back(nh.subscribe<gesture_formation::FormationParams>(
          "leader_params_in", 20, [this](const gesture_formation::FormationParams::ConstPtr& m) { locked([&] { onParams(*m); }); }));
      leader_subs_.push_back(nh.subscribe<gesture_formation::WorkerState>(
          "worker_estimate_in", 10, [this](const gesture_formation::WorkerState::ConstPtr& m) { locked([&] { onEstimate(*m); }); }));
      leader_subs_.push_back(nh.subscribe<gesture_formation::GestureStatus>(
          "gesture_status_in", 50, [this](const gesture_formation::GestureStatus::ConstPtr& m) { locked([&] { onGestureStatus(*m); }); }));
    }
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

  template <class F>
  void locked(F f) {
    std::lock_guard<std::mutex> lock(mutex_);
    f();
  }
  /// ~leadership: UAV i's leadership state (its acting makes its camera the leader's) and its
  /// planner's parameters, gesture status (published only while it acts) and estimate (the owner's).
  void subscribeLeader(ros::NodeHandle& nh, int i) {
    leader_subs_.push_back(perUav<gesture_formation::LeadershipState>(nh, i, "leadership_state", [this](int k, const auto& m) {
      calls_.log(k, m);
      if (m.acting && k != owner_) NODELET_WARN_STREAM("SimWorld: the leader camera is UAV " << k << "'s from t = " << t_ << " s");
      if (m.acting) owner_ = k;
    }));
    leader_subs_.push_back(perUav<gesture_formation::FormationParams>(nh, i, "formation_params", [this](int, const auto& m) { onParams(m); }));
    leader_subs_.push_back(perUav<gesture_formation::GestureStatus>(nh, i, "gesture_status", [this](int, const auto& m) { onGestureStatus(m); }));
    leader_subs_.push_back(perUav<gesture_formation::WorkerState>(nh, i, "worker_state", [this](int k, const auto& m) {
      if (k == owner_) onEstimate(m);
    }));
  }
  // Mutex held. The leader's parameters, estimate (its ^Hφ follows it) and gesture status.
  void onParams(const gesture_formation::FormationParams& m) {
    if (!finished_) record_->params(toParamsReport(m));
  }
  void onEstimate(const gesture_formation::WorkerState& m) {
    estimate_ = m;
    if (!m.lost) heading_->update(toEigen(m.velocity));
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

  void onGestureStatus(const gesture_formation::GestureStatus& m) {
    last_class_ = m.gesture_id;
    last_ratio_ = m.dominant_ratio;
    if (finished_ || !m.fired) return;
    record_->gestureFired(m.header.stamp.toSec(), m.dominant_id, cfg_.gesture_mapping);
  }

  void publishClock() {
    rosgraph_msgs::Clock c;
    c.clock = ros::Time(std::max(t_, 1e-6));
    clock_pub_.publish(c);
  }

  void onClock(const ros::WallTimerEvent&) {
    // faults.abort and faults.leader_silence at their time, outside the lock (sim_world_calls.hpp).
    const SimWorldDue due = tick();
    if (due.abort) calls_.abort();
    if (due.silence >= 0) SimWorldCalls::silence(due.silence, due.t_s);
  }

  /// One clock step; what falls due in it.
  SimWorldDue tick() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return {};
    if (!gate_.open(plan_subs_)) {  // sim time starts once every UAV's planner is up
      publishClock();
      return {};
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
    if (camera_frames_->due(k_) && (follower_views_ ? all : truth_[static_cast<std::size_t>(owner_)].has_value())) cameraFrame(ws);
    if (timeline_samples_->due(k_)) sample(ws, all);
    SimWorldDue due{record_->abortDue(t_), -1, t_};
    const auto& silence = cfg_.faults.leader_silence;  // for good (checked at start): once, the acting UAV
    if (silence && !silenced_ && t_ >= silence->t_s) due.silence = owner_;
    silenced_ = silenced_ || due.silence >= 0;
    if (t_ >= set_.duration_s - 1e-9) finish();
    return due;
  }

  /// The leader's estimate predicted to t_s (nullopt before the first one).
  std::optional<Eigen::Vector3d> estimateAt(double t_s) const {
    if (!estimate_) return std::nullopt;
    return toWorkerKnowledge(*estimate_).positionAt(t_s);
  }

  void cameraFrame(const sim::WorkerState& ws) {
    std::vector<sim::MultirotorState> followers;
    std::vector<bool> online;
    for (int i = 0; follower_views_ && i < n_; ++i) {  // the other UAVs' cameras, in index order
      if (i == owner_) continue;
      followers.push_back(*truth_[static_cast<std::size_t>(i)]);
      online.push_back(!cfg_.faults.followerOffline(i, t_));
    }
    // The worker's performance advances in both modes; rendered cameras: only its body leaves.
    const sim::LeaderCameraFrame cf =
        camera_->frame(t_, *truth_[static_cast<std::size_t>(owner_)], followers, online, ws, *worker_, set_.rendered ? nullptr : classifier_.get());
    record_->metrics().counters().range_outliers += cf.range_outliers;
    const ros::Time stamp(t_);
    if (set_.rendered) {
      body_pub_.publish(toWorkerBodyMsg(worker_->bodyAt(t_), ws.feet_world, ws.heading_rad, stamp, set_.world_frame));
    } else {
      const std::optional<Eigen::Vector3d> est = estimateAt(t_);
      record_->metrics().cameraFrame(cf.sensors.visible(), est ? &*est : nullptr, ws.p_world);
    }
    camera_topics_.publish(cf, owner_, truth_, stamp);
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
    if (!calls_.write(set_.output_dir)) NODELET_ERROR_STREAM("SimWorld: " << set_.output_dir << "/leadership.csv not written");
    if (!record_->finish(worker_->episodes(), t_, wall, set_.output_dir, &err, &warning)) NODELET_ERROR_STREAM("SimWorld: " << err);
    if (!warning.empty()) NODELET_WARN_STREAM("SimWorld: " << warning);
    NODELET_INFO_STREAM("SimWorld: mission done at t = " << t_ << " s (" << wall << " s wall); wrote " << set_.output_dir
                                                         << "/metrics.json");
    done_pub_.publish([] { std_msgs::Bool b; b.data = true; return b; }());
  }

  std::mutex mutex_;
  sim::MissionConfig cfg_;
  WorldMap world_;
  SiteObstacles site_;  ///< the unmapped obstacles (counted by record_'s obstacle distance)
  std::unique_ptr<sim::MissionClassifier> classifier_;
  std::optional<sim::WorkerModel> worker_;
  std::optional<sim::LeaderCamera> camera_;
  std::optional<sim::StepSchedule> camera_frames_, timeline_samples_;
  std::optional<sim::WorldRecord> record_;  ///< metrics, plans and modes, command outcomes, the files
  std::optional<formation::WorkerHeading> heading_;
  SimWorldSettings set_;  ///< the nodelet's parameters (duration: the mission's if not given)
  double t_ = 0.0, last_ratio_ = 0.0, last_detected_s_ = -1e9;  ///< last detected: the leader's Perception (rendered)
  long k_ = 0;
  int n_ = 0, last_class_ = -1, owner_ = 0;  ///< owner_: whose camera is the leader's (~leadership: the acting UAV)
  bool finished_ = false, follower_views_ = false, silenced_ = false;
  SimStartGate gate_;  ///< sim time starts once every UAV's planner is up
  std::vector<std::optional<sim::MultirotorState>> truth_;
  std::optional<gesture_formation::WorkerState> estimate_;
  ros::Publisher clock_pub_, worker_pub_, command_pub_, done_pub_, body_pub_;
  SimCameraTopics camera_topics_;  ///< the leader camera's detection, CameraInfo, UWB; every UAV's classification
  std::vector<ros::Subscriber> truth_subs_, plan_subs_, abort_subs_, leader_subs_;
  SimWorldCalls calls_;  ///< faults.abort, faults.leader_silence; the leadership log
  ros::Subscriber detection_sub_;
  ros::WallTimer clock_timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::SimWorldNodelet, nodelet::Nodelet)

// SimWorld nodelet: the world of the simulated mission, on the sim core of `gfctl simulate`:
// sim time (/clock), the worker (sim::WorkerModel), the leader's camera (sim::LeaderCamera: box,
// stereo and UWB from the leader's true pose with the mission's sensor faults, the skeleton from
// the actual viewpoint through the gesture LSTM — the classifier output a Perception nodelet
// would publish; with mission.gestures.view_fusion.min_agreeing_views > 1 also the followers'
// cameras, each UAV's classification on its own topic, as `gfctl simulate` renders them),
// the mission's scheduled operator requests, and the mission's metrics
// (sim::MetricsAccumulator: the definitions of docs/simulation.md §4, fed from the UAVs' true
// states, the worker's truth, the leader's parameters, the plans and the command outcomes).
//
// Publishes: /clock; worker_truth_out (nav_msgs/Odometry); detection_out (WorkerDetection in
//   <leader>/camera_optical); uwb_out (sensor_msgs/Range); uav<i>/gesture_out (Gesture: UAV i's
//   classifier output; followers only while online, i.e. not in a mission follower dropout; with
//   view_fusion.confirm_3d or require_3d the skeleton too, in uav<i>/gesture_camera, and tf uav<i>/camera_axis →
//   uav<i>/gesture_camera);
//   operator_command_out (FormationCommand, sender/sequence assigned by the OperatorInterface);
//   done_out (latched, at the end).
// Subscribes: uav<i>/ground_truth (true states), uav<i>/plan, leader_params_in (FormationParams
//   of the leader: parameters and what became of each command), worker_estimate_in
//   (WorkerState of the leader), gesture_status_in (the leader's gesture filter).
// Sim time starts when every UAV's FormationPlanner is up. At the end (~duration_s, ≤ 0: the
// mission's) writes ~output_dir/{metrics.json, timeline.csv, events.csv, modes.csv (the planners'
// mode changes, from the plans' mode field), plans.csv (every plan's status and reason)} and stops
// the clock.
// Parameters (required): ~mission_file, ~seed, ~real_time_factor, ~clock_step_s,
//   ~duration_s, ~output_dir, ~world_frame, ~leader_camera_frame; optional ~faults_file (a fault
//   profile merged into the mission: camera blackouts, sensor dropouts, range outliers, wind),
//   ~camera (synthetic | rendered; default synthetic).
// ~camera rendered (simulation.launch camera:=rendered): every UAV's camera is rendered by its
//   SimCamera nodelet and goes through its Perception nodelet; SimWorld then publishes no
//   detection and no classification (no ground truth reaches the estimator or the classifier),
//   but worker_body_out (WorkerBody: the worker's posed 3-D body at each camera frame, which the
//   SimCamera nodelets render) and, for its metrics, reads the leader's Perception output on
//   detection_in (visibility). UWB stays synthetic (a radio sensor), as in gfctl simulate.
#include <algorithm>
#include <mutex>
#include <optional>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/Range.h>
#include <std_msgs/Bool.h>
#include <tf2_ros/transform_broadcaster.h>

#include "sim_config_sources.hpp"
#include "sim_conversions.hpp"
#include "gesture_formation/Gesture.h"
#include "gesture_formation/GestureStatus.h"
#include "gesture_formation/formation/worker_heading.hpp"
#include "gesture_formation/sim/leader_camera.hpp"
#include "gesture_formation/sim/mission_metrics.hpp"
#include "gesture_formation/sim/random.hpp"
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
    std::string mission_file;
    int seed = 0;
    params.load("mission_file", mission_file);
    params.load("seed", seed, 0, 1 << 30);
    params.load("real_time_factor", rtf_, 0.05, 100.0);
    params.load("clock_step_s", clock_step_s_, 0.001, 0.1);
    params.load("duration_s", duration_s_, -1.0, 1e5);
    params.load("output_dir", output_dir_);
    params.load("world_frame", world_frame_);
    params.load("leader_camera_frame", camera_frame_);
    std::string camera_mode;
    params.loadOptional("camera", camera_mode, "synthetic");
    if (camera_mode != "synthetic" && camera_mode != "rendered") {
      params.addError("camera: must be synthetic or rendered, got '" + camera_mode + "'");
    }
    rendered_ = camera_mode == "rendered";
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
    if (duration_s_ <= 0.0) duration_s_ = cfg_.duration_s;
    const auto s = static_cast<std::uint64_t>(seed);
    worker_.emplace(cfg_.worker, sim::mixSeed(s ^ static_cast<std::uint64_t>(sim::Stream::kWorker)));
    camera_.emplace(cfg_, world_.map.get(), s);
    camera_frames_.emplace(1.0 / cfg_.camera.rate_hz, clock_step_s_);
    timeline_samples_.emplace(1.0 / cfg_.timeline_rate_hz, clock_step_s_);
    schedule_.emplace(cfg_.requests, "mission");
    metrics_.emplace(cfg_, sim::ObstacleDistance{world_.field.get(), world_.solids.get(), world_.ground_height_m}, s);
    heading_.emplace(cfg_.formation.worker_heading);
    n_ = cfg_.formation.params.uavCount();
    params_ = cfg_.formation.params;
    versions_.emplace(params_);
    truth_.resize(static_cast<std::size_t>(n_));

    clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
    worker_pub_ = nh.advertise<nav_msgs::Odometry>("worker_truth_out", 10);
    uwb_pub_ = nh.advertise<sensor_msgs::Range>("uwb_out", 10);
    follower_views_ = cfg_.view_fusion.min_agreeing_views > 1;  // as sim::runMission
    if (rendered_) {
      // The cameras are rendered (SimCamera) and seen by the Perception nodelets: no detection and
      // no classification from here, only the body they render.
      body_pub_ = nh.advertise<gesture_formation::WorkerBody>("worker_body_out", 10);
      detection_sub_ = nh.subscribe("detection_in", 20, &SimWorldNodelet::onLeaderDetection, this);
    } else {
      detection_pub_ = nh.advertise<gesture_formation::WorkerDetection>("detection_out", 10);
      for (int i = 0; i < (follower_views_ ? n_ : 1); ++i) {
        gesture_pubs_.push_back(nh.advertise<gesture_formation::Gesture>("uav" + std::to_string(i) + "/gesture_out", 10));
      }
    }
    command_pub_ = nh.advertise<gesture_formation::FormationCommand>("operator_command_out", 20);
    done_pub_ = nh.advertise<std_msgs::Bool>("done_out", 1, true);
    plan_mode_.assign(static_cast<std::size_t>(n_), "");
    for (int i = 0; i < n_; ++i) {
      truth_subs_.push_back(nh.subscribe<nav_msgs::Odometry>(
          "uav" + std::to_string(i) + "/ground_truth", 10, [this, i](const nav_msgs::Odometry::ConstPtr& m) {
            std::lock_guard<std::mutex> lock(mutex_);
            truth_[static_cast<std::size_t>(i)] = toMultirotorState(*m);
          }));
      plan_subs_.push_back(nh.subscribe<gesture_formation::PlannedTrajectory>(
          "uav" + std::to_string(i) + "/plan", 10, [this, i](const gesture_formation::PlannedTrajectory::ConstPtr& m) {
            const auto status = planStatusFromName(m->status);
            std::lock_guard<std::mutex> lock(mutex_);
            if (finished_) return;
            if (!status) {
              NODELET_WARN_STREAM_THROTTLE(5.0, "SimWorld: plan not counted: " << status.reason());
              return;
            }
            metrics_->plan(i, m->planned_at.toSec(), planVersion(*m), *status, m->planning_ms, m->reason);
            // The planners' modes (docs/safety.md §1): hold replannings and every change → modes.csv.
            if (m->mode == "hold" || m->mode == "search") ++metrics_->counters().plans_hold;
            auto& last = plan_mode_[static_cast<std::size_t>(i)];
            if (!m->mode.empty() && m->mode != last) {
              last = m->mode;
              modes_.push_back(sim::ModeChange{m->planned_at.toSec(), i, m->mode,
                                               m->mode_reason.empty() ? "fresh data" : m->mode_reason});
            }
          }));
    }
    params_sub_ = nh.subscribe("leader_params_in", 20, &SimWorldNodelet::onParams, this);
    estimate_sub_ = nh.subscribe<gesture_formation::WorkerState>(
        "worker_estimate_in", 10, [this](const gesture_formation::WorkerState::ConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          estimate_ = *m;
          if (!m->lost) heading_->update(toEigen(m->velocity));  // the leader's ^Hφ follows its estimate
        });
    status_sub_ = nh.subscribe("gesture_status_in", 50, &SimWorldNodelet::onGestureStatus, this);
    wall0_ = ros::WallTime::now();
    publishClock();
    clock_timer_ = nh.createWallTimer(ros::WallDuration(clock_step_s_ / rtf_), &SimWorldNodelet::onClock, this);
  }

  void onParams(const gesture_formation::FormationParams::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto p = fromMsg(*m);
    if (p && p->uavCount() == n_) {
      params_ = *p;
      versions_->published(m->version, *p);
    }
    if (finished_ || m->last_command.empty()) return;
    // Re-published parameters repeat the last command: one outcome per (command, status).
    const std::string key = m->last_command + "|" + m->last_command_status;
    if (key == last_outcome_key_) return;
    last_outcome_key_ = key;
    if (m->last_command_status == formation::toString(formation::CommandStatus::kDuplicate)) {
      ++metrics_->counters().commands_duplicate;
    }
    metrics_->commandOutcome(sim::CommandOutcome{m->last_command_source, m->last_command_status,
                                                 m->last_command_stamp.toSec(), m->header.stamp.toSec(), m->version,
                                                 std::vector<int>(m->last_command_uavs.begin(), m->last_command_uavs.end())},
                             kStampToleranceS);
  }

  /// A command outcome goes to the earliest pending request of its source issued at the command's
  /// stamp ± this. An operator command reaches the leader stamped by the ground LcmBridge when it
  /// sent it (the envelope stamp: the world process's clock, a tick or two after the request) — by
  /// a repeated copy when the first ones were lost on the radio (LcmBridge command_repeats ×
  /// command_repeat_period_s: 0.4 s later with 5 × 0.1 s); a gesture command keeps the classifier
  /// output's stamp (the fire time).
  static constexpr double kStampToleranceS = 0.6;
  /// Rendered cameras: the timeline's `visible` holds this long after the leader's Perception last
  /// found the worker (its frames come at the SimCamera's rate, a few Hz, and late by their
  /// processing time).
  static constexpr double kRenderedVisibleS = 1.0;

  /// The parameter version a plan was made with: the leader's says it; a follower's parameters
  /// come over LCM without their version, so it is the latest version the leader published
  /// with exactly the parameters the plan lists (PlannedTrajectory.formation).
  std::uint64_t planVersion(const gesture_formation::PlannedTrajectory& m) const {
    if (m.uav_index == formation::kLeader || m.params_version > 0 || m.formation.empty()) return m.params_version;
    const auto used = fromMsg(m.formation);
    if (!used || used->uavCount() != n_) return m.params_version;
    return versions_->versionOf(*used).value_or(m.params_version);
  }

  /// Rendered cameras: the leader's Perception output, one per frame it processed (metrics:
  /// visibility and the estimate's error at that frame).
  void onLeaderDetection(const gesture_formation::WorkerDetection::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_ || !started_) return;
    const double t = m->header.stamp.toSec();
    if (m->detected) last_detected_s_ = t;
    const std::optional<Eigen::Vector3d> est = estimateAt(t);
    metrics_->cameraFrame(m->detected, est ? &*est : nullptr, worker_->stateAt(t).p_world);
  }

  void onGestureStatus(const gesture_formation::GestureStatus::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    last_class_ = m->gesture_id;
    last_ratio_ = m->dominant_ratio;
    if (finished_ || !m->fired) return;
    metrics_->addRequest(sim::firedGestureRecord(m->header.stamp.toSec(), m->dominant_id, cfg_.gesture_mapping));
    metrics_->resolveOutcomes(kStampToleranceS);
  }

  void publishClock() {
    rosgraph_msgs::Clock c;
    c.clock = ros::Time(std::max(t_, 1e-6));
    clock_pub_.publish(c);
  }

  bool allTruths() const {
    return std::all_of(truth_.begin(), truth_.end(), [](const auto& t) { return t.has_value(); });
  }

  void onClock(const ros::WallTimerEvent&) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (finished_) return;
    if (!started_) {
      // Sim time starts once every UAV's planner is up (it advertises its plan after loading the
      // map), so that no UAV misses the mission's start; after 120 s wall it starts anyway.
      bool all = true;
      for (const auto& sub : plan_subs_) all = all && sub.getNumPublishers() > 0;
      const double waited = (ros::WallTime::now() - wall0_).toSec();
      if (!all && waited < 120.0) {
        publishClock();
        return;
      }
      if (!all) NODELET_WARN("SimWorld: not every UAV planner is up after 120 s; starting anyway");
      NODELET_INFO_STREAM("SimWorld: every UAV is up after " << waited << " s wall; sim time starts");
      started_ = true;
      wall0_ = ros::WallTime::now();
    }
    ++k_;
    t_ = static_cast<double>(k_) * clock_step_s_;
    publishClock();
    const sim::WorkerState ws = worker_->stateAt(t_);
    // Operator requests (the OperatorInterface numbers them and sends them over LCM).
    for (const auto& d : schedule_->due(t_)) {
      auto m = toMsg(d.command);
      m.header.stamp = ros::Time(t_);
      command_pub_.publish(m);
      metrics_->addRequest(d.record);  // "lost" until the leader says what it did with it
    }
    metrics_->resolveOutcomes(kStampToleranceS);
    const bool all = allTruths();
    // With the followers' cameras, a frame needs every UAV's truth (LeaderCamera wants the same
    // number of followers at every call); SimWorld starts when every planner is up.
    if (camera_frames_->due(k_) && (follower_views_ ? all : truth_[0].has_value())) cameraFrame(ws);
    if (all) {
      std::vector<Eigen::Vector3d> ps;
      for (const auto& s : truth_) ps.push_back(s->p_world);
      metrics_->sampleSafety(t_, ps, ws);
    }
    if (timeline_samples_->due(k_)) sample(ws, all);
    if (t_ >= duration_s_ - 1e-9) finish();
  }

  /// The leader's estimate predicted to t_s (nullopt before the first one).
  std::optional<Eigen::Vector3d> estimateAt(double t_s) const {
    if (!estimate_) return std::nullopt;
    return toWorkerKnowledge(*estimate_).positionAt(t_s);
  }

  /// UAV `uav`'s classification, as its Perception nodelet would publish it. With the 3-D
  /// confirmation (`skeleton` given) the skeleton goes along in the frame of the generator's camera
  /// that rendered it, uav<i>/gesture_camera, sent on tf relative to the UAV's true camera axis: the
  /// pose the ViewObserver looks up through the estimated axis (SimUav) is the rendering pose moved
  /// by the odometry's error, as in `gfctl simulate`.
  void publishGesture(int uav, const gesture::Classification& c, const ros::Time& stamp,
                      const gesture::CalibratedSkeleton* skeleton) {
    const std::string prefix = "uav" + std::to_string(uav);
    gesture_formation::Gesture g;
    g.header.stamp = stamp;
    g.header.frame_id = prefix + "/camera_optical";
    g.gesture_id = c.gesture_id;
    g.probabilities.assign(c.probabilities.begin(), c.probabilities.end());
    const auto& truth = truth_[static_cast<std::size_t>(uav)];
    if (skeleton != nullptr && truth) {
      g.header.frame_id = prefix + "/gesture_camera";
      g.keypoints = toKeypoints(skeleton->skeleton);
      g.camera = toCameraInfo(skeleton->intrinsics);
      const geometry_msgs::Quaternion axis = cameraAxisOrientation(truth->heading_rad, truth->pitch_rad);
      const Eigen::Quaterniond q_axis_inv = Eigen::Quaterniond(axis.w, axis.x, axis.y, axis.z).conjugate();
      geometry_msgs::TransformStamped T;
      T.header.stamp = stamp;
      T.header.frame_id = prefix + "/camera_axis";
      T.child_frame_id = g.header.frame_id;
      T.transform = toTransform(toPose(q_axis_inv * Eigen::Quaterniond(skeleton->R_world_camera),
                                       q_axis_inv * (skeleton->p_world_camera - truth->p_world)));
      tf_.sendTransform(T);
    }
    gesture_pubs_[static_cast<std::size_t>(uav)].publish(g);
  }

  void cameraFrame(const sim::WorkerState& ws) {
    std::vector<sim::MultirotorState> followers;
    std::vector<bool> online;
    if (follower_views_) {
      for (int i = 1; i < n_; ++i) {
        followers.push_back(*truth_[static_cast<std::size_t>(i)]);
        online.push_back(!cfg_.faults.followerOffline(i, t_));
      }
    }
    // The worker's performance advances here in both modes (the same motions and gesture
    // episodes); with rendered cameras only its body leaves (no classifier is run).
    const sim::LeaderCameraFrame cf =
        camera_->frame(t_, *truth_[0], followers, online, ws, *worker_, rendered_ ? nullptr : classifier_.get());
    metrics_->counters().range_outliers += cf.range_outliers;
    const ros::Time stamp(t_);
    if (rendered_) {
      auto body = toWorkerBodyMsg(worker_->bodyAt(t_), ws.feet_world, ws.heading_rad);
      body.header.stamp = stamp;
      body.header.frame_id = world_frame_;
      body_pub_.publish(body);
    } else {
      const std::optional<Eigen::Vector3d> est = estimateAt(t_);
      metrics_->cameraFrame(cf.sensors.visible(), est ? &*est : nullptr, ws.p_world);
    }
    if (std::isfinite(cf.sensors.d_uwb_m)) {
      sensor_msgs::Range r;
      r.header.stamp = stamp;
      r.header.frame_id = camera_frame_;
      r.radiation_type = sensor_msgs::Range::INFRARED;  // UWB has no constant; documented in docs/ros.md
      r.min_range = 0.0f;
      r.max_range = static_cast<float>(cfg_.uwb.max_range_m);
      r.range = static_cast<float>(cf.sensors.d_uwb_m);
      uwb_pub_.publish(r);
    }
    if (rendered_) return;  // the Perception nodelets see the rendered images
    // Each UAV's classifier output, as its Perception nodelet would publish it (the followers'
    // first: the leader's closes the frame at the GestureCommander only when all have reported).
    for (std::size_t i = 0; i < cf.followers.size(); ++i) {
      if (cf.followers[i].classification) {
        publishGesture(static_cast<int>(i) + 1, *cf.followers[i].classification, stamp,
                       cfg_.view_fusion.usesCalibratedViews() && cf.followers[i].visible ? &cf.followers[i].calibrated : nullptr);
      }
    }
    if (!cf.sensors.visible()) return;
    gesture_formation::WorkerDetection d;
    d.header.stamp = stamp;
    d.header.frame_id = camera_frame_;
    d.detected = true;
    d.u = cf.sensors.box.u;
    d.v = cf.sensors.box.v;
    d.w = cf.sensors.box.w;
    d.h = cf.sensors.box.h;
    d.confidence = 0.9f;
    d.stereo_distance_m = cf.sensors.d_stereo_m;
    detection_pub_.publish(d);
    if (cf.classification) publishGesture(0, *cf.classification, stamp, cfg_.view_fusion.usesCalibratedViews() ? &cf.calibrated : nullptr);
  }

  void sample(const sim::WorkerState& ws, bool all_truths) {
    nav_msgs::Odometry w;
    w.header.stamp = ros::Time(t_);
    w.header.frame_id = world_frame_;
    w.child_frame_id = world_frame_;
    w.pose.pose.position = toPoint(ws.p_world);
    w.pose.pose.orientation = cameraAxisOrientation(ws.heading_rad, 0.0);
    w.twist.twist.linear = toVector3(ws.v_world);
    worker_pub_.publish(w);
    if (!all_truths) return;  // not every UAV is up yet
    sim::TimelineInput in;
    in.t_s = t_;
    in.worker = ws;
    if (const auto est = estimateAt(t_)) in.estimate_world = *est;
    // Rendered cameras: the leader's Perception found the worker within kRenderedVisibleS.
    in.visible = (rendered_ ? last_detected_s_ > t_ - kRenderedVisibleS : camera_->lastVisibleS() > t_ - 0.2) ? 1 : 0;
    in.gesture_true = worker_->performingAt(t_);
    in.gesture_class = last_class_;
    in.dominant_ratio = last_ratio_;
    in.params = params_;
    in.human_heading_rad = heading_->heading();
    for (const auto& s : truth_) in.uavs.push_back(*s);
    metrics_->sampleTimeline(in);
  }

  void finish() {
    finished_ = true;
    const double wall = (ros::WallTime::now() - wall0_).toSec();
    // What the ROS system does not report (docs/ros.md): the planners' skipped replannings,
    // command ages, the LCM links' counters, QP sparse timeouts (logged by the planner).
    metrics_->counters().not_measured = {"plans_skipped",  "commands_stale",      "messages_sent",
                                         "messages_lost", "messages_duplicated", "messages_reordered",
                                         "qp_sparse_timeouts"};
    sim::MissionOutput out = metrics_->finish(worker_->episodes(), t_, wall);
    out.modes = modes_;  // from the plans' mode fields (the planners' hold decisions)
    // metrics.json last: its appearance tells tools/run_ros_mission.sh that the files are complete.
    std::string err;
    if (!sim::writeMissionFiles(output_dir_, out, n_, true, &err)) NODELET_ERROR_STREAM("SimWorld: " << err);
    if (const auto& left = metrics_->unmatchedOutcomes(); !left.empty()) {
      NODELET_WARN_STREAM("SimWorld: " << left.size() << " command outcome(s) matched no request (e.g. "
                                       << left.front().source << " at " << left.front().issued_s << " s)");
    }
    NODELET_INFO_STREAM("SimWorld: mission done at t = " << t_ << " s (" << wall << " s wall); wrote " << output_dir_
                                                         << "/metrics.json");
    std_msgs::Bool done;
    done.data = true;
    done_pub_.publish(done);
  }

  std::mutex mutex_;
  std::vector<std::string> plan_mode_;   ///< per UAV: the mode of its last plan
  std::vector<sim::ModeChange> modes_;   ///< every planner mode change (modes.csv)
  sim::MissionConfig cfg_;
  WorldMap world_;
  std::unique_ptr<sim::MissionClassifier> classifier_;
  std::optional<sim::WorkerModel> worker_;
  std::optional<sim::LeaderCamera> camera_;
  std::optional<sim::StepSchedule> camera_frames_, timeline_samples_;
  std::optional<sim::MetricsAccumulator> metrics_;
  std::optional<formation::WorkerHeading> heading_;
  formation::FormationParams params_;
  /// Every parameter version the leader published (0: the mission's), for planVersion().
  std::optional<sim::ParamsVersions> versions_;
  std::string output_dir_, world_frame_, camera_frame_, last_outcome_key_;
  double rtf_ = 1.0, clock_step_s_ = 0.01, duration_s_ = 0.0, t_ = 0.0, last_ratio_ = 0.0;
  long k_ = 0;
  int n_ = 0, last_class_ = -1;
  bool finished_ = false, started_ = false, follower_views_ = false, rendered_ = false;
  double last_detected_s_ = -1e9;  ///< rendered cameras: the leader's Perception's last find
  std::optional<sim::OperatorSchedule> schedule_;
  std::vector<std::optional<sim::MultirotorState>> truth_;
  std::optional<gesture_formation::WorkerState> estimate_;
  ros::WallTime wall0_;
  ros::Publisher clock_pub_, worker_pub_, detection_pub_, uwb_pub_, command_pub_, done_pub_, body_pub_;
  tf2_ros::TransformBroadcaster tf_;  ///< the gesture cameras (3-D confirmation)
  std::vector<ros::Publisher> gesture_pubs_;  ///< per UAV (only the leader's without follower views)
  std::vector<ros::Subscriber> truth_subs_, plan_subs_;
  ros::Subscriber params_sub_, estimate_sub_, status_sub_, detection_sub_;
  ros::WallTimer clock_timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::SimWorldNodelet, nodelet::Nodelet)

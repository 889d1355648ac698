// SimWorld nodelet: the world of the simulated mission (the sim core of `gfctl simulate`): sim
// time (/clock), the worker (sim::WorkerModel), the leader's camera, stereo and UWB
// (sim::SyntheticSensors on the leader's true pose), the skeletons seen from the leader's
// actual viewpoint through the gesture LSTM (the classifier output a Perception nodelet would
// publish), the mission's scheduled operator requests, and the mission's metrics (DESIGN §8.4,
// docs/simulation.md §4) computed online from the UAVs' true states.
//
// Publishes: /clock; worker_truth_out (nav_msgs/Odometry); detection_out (WorkerDetection in
//   <leader>/camera_optical); uwb_out (sensor_msgs/Range); gesture_out (Gesture);
//   operator_command_out (FormationCommand, sender/sequence assigned by the OperatorInterface).
// Subscribes: uav<i>/ground_truth (true states), leader_params_in (FormationParams of the
//   leader), worker_estimate_in (WorkerState of the leader), gesture_status_in, uav<i>/plan.
// Sim time starts when every UAV's FormationPlanner is up. At the end (~duration_s, ≤ 0: the mission's) writes ~output_dir/{metrics.json,
// timeline.csv, events.csv} and stops the clock.
// Parameters (required): ~mission_file, ~seed, ~real_time_factor, ~clock_step_s,
//   ~duration_s, ~output_dir, ~world_frame, ~leader_camera_frame.
#include <algorithm>
#include <fstream>
#include <iomanip>
#include <mutex>
#include <optional>
#include <sstream>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/Range.h>
#include <std_msgs/Bool.h>

#include "config_sources.hpp"
#include "conversions.hpp"
#include "gesture_formation/Gesture.h"
#include "gesture_formation/GestureStatus.h"
#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/formation/worker_heading.hpp"
#include "gesture_formation/gesture/gesture_classifier.hpp"
#include "gesture_formation/sim/mission_runner.hpp"
#include "gesture_formation/sim/random.hpp"
#include "gesture_formation/sim/synthetic_sensors.hpp"
#include "gesture_formation/sim/worker_model.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

namespace {
double pct(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(std::max(0.0, std::ceil(q * static_cast<double>(v.size())) - 1.0));
  return v[std::min(i, v.size() - 1)];
}
std::string num(double x) {
  if (!std::isfinite(x)) return "null";
  std::ostringstream os;
  os << std::setprecision(6) << x;
  return os.str();
}
std::string label(int i) { return i == 0 ? "L" : std::to_string(i); }
}  // namespace

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
    if (!mission_file.empty() && loadMission(mission_file, params, cfg_)) loadWorldMap(mission_file, params, world_);
    if (params.ok() && !cfg_.gesture_model.empty()) {
      auto c = gesture::GestureClassifier::load(cfg_.gesture_model);
      if (!c) params.addError("mission_file: gesture_model " + cfg_.gesture_model + ": " + c.reason());
      else classifier_.emplace(std::move(*c));
    }
    if (!params.ok()) {
      NODELET_ERROR_STREAM("SimWorld refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("SimWorld loaded:\n" << params.loaded());
    if (duration_s_ <= 0.0) duration_s_ = cfg_.duration_s;
    const auto s = static_cast<std::uint64_t>(seed);
    worker_.emplace(cfg_.worker, sim::mixSeed(s ^ static_cast<std::uint64_t>(sim::Stream::kWorker)));
    sensors_.emplace(cfg_.camera, cfg_.stereo, cfg_.uwb, world_.map.get(), sim::makeRng(s, sim::Stream::kCamera),
                     sim::makeRng(s, sim::Stream::kStereo), sim::makeRng(s, sim::Stream::kUwb));
    heading_.emplace(cfg_.formation.worker_heading);
    n_ = cfg_.formation.params.uavCount();
    params_ = cfg_.formation.params;
    truth_.resize(static_cast<std::size_t>(n_));
    in_obstacle_.assign(static_cast<std::size_t>(n_), false);
    in_worker_.assign(static_cast<std::size_t>(n_), false);
    pair_collision_.assign(static_cast<std::size_t>(n_ * n_), false);

    clock_pub_ = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
    worker_pub_ = nh.advertise<nav_msgs::Odometry>("worker_truth_out", 10);
    detection_pub_ = nh.advertise<gesture_formation::WorkerDetection>("detection_out", 10);
    uwb_pub_ = nh.advertise<sensor_msgs::Range>("uwb_out", 10);
    gesture_pub_ = nh.advertise<gesture_formation::Gesture>("gesture_out", 10);
    command_pub_ = nh.advertise<gesture_formation::FormationCommand>("operator_command_out", 20);
    done_pub_ = nh.advertise<std_msgs::Bool>("done_out", 1, true);
    for (int i = 0; i < n_; ++i) {
      truth_subs_.push_back(nh.subscribe<nav_msgs::Odometry>(
          "uav" + std::to_string(i) + "/ground_truth", 10,
          [this, i](const nav_msgs::Odometry::ConstPtr& m) {
            std::lock_guard<std::mutex> lock(mutex_);
            truth_[static_cast<std::size_t>(i)] = *m;
          }));
      plan_subs_.push_back(nh.subscribe<gesture_formation::PlannedTrajectory>(
          "uav" + std::to_string(i) + "/plan", 10, [this](const gesture_formation::PlannedTrajectory::ConstPtr& m) {
            std::lock_guard<std::mutex> lock(mutex_);
            plan_ms_.push_back(m->planning_ms);
            ++plans_;
            if (m->status == "fallback_previous") ++plans_previous_;
            if (m->status == "fallback_brake") ++plans_brake_;
          }));
    }
    params_sub_ = nh.subscribe("leader_params_in", 10, &SimWorldNodelet::onParams, this);
    estimate_sub_ = nh.subscribe<gesture_formation::WorkerState>(
        "worker_estimate_in", 10, [this](const gesture_formation::WorkerState::ConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          estimate_ = *m;
        });
    status_sub_ = nh.subscribe("gesture_status_in", 50, &SimWorldNodelet::onGestureStatus, this);
    wall0_ = ros::WallTime::now();
    publishClock();
    clock_timer_ = nh.createWallTimer(ros::WallDuration(clock_step_s_ / rtf_), &SimWorldNodelet::onClock, this);
  }

  void onParams(const gesture_formation::FormationParams::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto p = fromMsg(*m);
    if (p && p->uavCount() == n_) params_ = *p;
    if (m->version > version_) {
      version_ = m->version;
      ++requests_applied_;
      const std::string source = m->last_command.rfind("gesture", 0) == 0 ? "gesture" : "operator";
      if (source == "gesture") ++gesture_applied_;
      else ++operator_applied_;
      events_.push_back({t_, source, m->last_command, m->last_outcome});
    }
  }

  void onGestureStatus(const gesture_formation::GestureStatus::ConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex_);
    last_class_ = m->gesture_id;
    last_ratio_ = m->dominant_ratio;
    if (m->fired) fired_.emplace_back(m->header.stamp.toSec(), m->dominant_id);
  }

  void publishClock() {
    rosgraph_msgs::Clock c;
    c.clock = ros::Time(std::max(t_, 1e-6));
    clock_pub_.publish(c);
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
    const double t_prev = t_;
    t_ += clock_step_s_;
    publishClock();
    const sim::WorkerState ws = worker_->stateAt(t_);
    // Operator requests (the OperatorInterface numbers and sends them over LCM).
    while (next_request_ < cfg_.requests.size() && cfg_.requests[next_request_].t_s <= t_ + 1e-9) {
      const sim::OperatorRequest& q = cfg_.requests[next_request_++];
      formation::FormationCommand c;
      c.id = {"mission", next_request_};
      c.target = q.target;
      c.parameter = q.parameter;
      c.kind = q.kind;
      c.amount = q.amount;
      auto m = toMsg(c);
      m.header.stamp = ros::Time(t_);
      command_pub_.publish(m);
    }
    const double cam_period = 1.0 / cfg_.camera.rate_hz;
    if (std::floor(t_ / cam_period) != std::floor(t_prev / cam_period) && truth_[0]) cameraFrame(ws);
    const double tl_period = 1.0 / cfg_.timeline_rate_hz;
    if (std::floor(t_ / tl_period) != std::floor(t_prev / tl_period)) sample(ws);
    if (t_ >= duration_s_) finish();
  }

  void cameraFrame(const sim::WorkerState& ws) {
    planning::UavKinematicState L = toKinematicState(*truth_[0]);
    const estimation::CameraPose true_pose = sim::cameraPose(L.p_world, L.heading_rad, L.pitch_rad);
    bool blackout = false;
    for (const auto& [a, b] : cfg_.faults.camera_blackouts) blackout = blackout || (t_ >= a && t_ < b);
    const sim::SensorFrame frame = sensors_->observe(true_pose, ws.feet_world, ws.p_world, cfg_.worker.height_m, blackout);
    const gesture::SynthFrame sk = worker_->skeletonAt(t_, true_pose.t_world_camera);
    ++frames_;
    if (estimate_ && !estimate_->lost) {
      const double age = t_ - estimate_->header.stamp.toSec();
      if (age >= 0.0 && age < 0.5) {
        const Eigen::Vector3d e = toEigen(estimate_->position) + age * toEigen(estimate_->velocity);
        est_sq_ += (e - ws.p_world).squaredNorm();
        ++est_n_;
      }
    }
    const ros::Time stamp(t_);
    if (!std::isnan(frame.d_uwb_m)) {
      sensor_msgs::Range r;
      r.header.stamp = stamp;
      r.header.frame_id = camera_frame_;
      r.radiation_type = sensor_msgs::Range::INFRARED;  // UWB has no constant; documented in docs/ros.md
      r.min_range = 0.0f;
      r.max_range = static_cast<float>(cfg_.uwb.max_range_m);
      r.range = static_cast<float>(frame.d_uwb_m);
      uwb_pub_.publish(r);
    }
    if (!frame.visible()) return;
    ++visible_frames_;
    gesture_formation::WorkerDetection d;
    d.header.stamp = stamp;
    d.header.frame_id = camera_frame_;
    d.detected = true;
    d.u = frame.box.u;
    d.v = frame.box.v;
    d.w = frame.box.w;
    d.h = frame.box.h;
    d.confidence = 0.9f;
    d.stereo_distance_m = frame.d_stereo_m;
    detection_pub_.publish(d);
    if (t_ - last_skeleton_t_ > 0.5) window_.clear();  // as gfctl simulate: a gap breaks the FIFO
    window_.push(sk.skeleton);
    last_skeleton_t_ = t_;
    if (classifier_ && window_.full()) {
      const auto c = classifier_->classify(window_);
      if (c) {
        gesture_formation::Gesture g;
        g.header.stamp = stamp;
        g.header.frame_id = camera_frame_;
        g.gesture_id = c->gesture_id;
        g.probabilities.assign(c->probabilities.begin(), c->probabilities.end());
        gesture_pub_.publish(g);
      }
    }
  }

  void sample(const sim::WorkerState& ws) {
    nav_msgs::Odometry w;
    w.header.stamp = ros::Time(t_);
    w.header.frame_id = world_frame_;
    w.child_frame_id = world_frame_;
    w.pose.pose.position = toPoint(ws.p_world);
    w.pose.pose.orientation = cameraAxisOrientation(ws.heading_rad, 0.0);
    w.twist.twist.linear = toVector3(ws.v_world);
    worker_pub_.publish(w);
    for (const auto& tr : truth_) {
      if (!tr) return;  // not every UAV is up yet
    }
    const double hphi = heading_->update(ws.v_world);
    const formation::UavReference lref = formation::leaderReference(ws.p_world, hphi, params_.leader);
    std::ostringstream row;
    row << std::setprecision(6) << t_ << "," << ws.p_world.x() << "," << ws.p_world.y() << "," << ws.p_world.z();
    std::vector<Eigen::Vector3d> ps;
    for (int i = 0; i < n_; ++i) {
      const auto s = toKinematicState(*truth_[static_cast<std::size_t>(i)]);
      const double r = cfg_.uavs[static_cast<std::size_t>(i)].plant.body_radius_m;
      ps.push_back(s.p_world);
      const formation::UavReference ref =
          i == 0 ? lref
                 : formation::followerReference(ws.p_world, lref.heading_rad, lref.pitch_rad,
                                                params_.followers[static_cast<std::size_t>(i - 1)]);
      const Eigen::Vector3d to_worker = ws.p_world - s.p_world;
      const double d_t = to_worker.norm();
      const double d_ref = params_.uav(i).distance_m;
      const double d_o = world_.field->clearance(s.p_world);
      const double phi = std::atan2(to_worker.y(), to_worker.x());
      const double elev = std::asin(std::clamp(-to_worker.z() / std::max(1e-9, d_t), -1.0, 1.0));
      const double ae = common::radToDeg(common::wrapAngle(phi - ref.heading_rad));
      dist_sq_ += (d_t - d_ref) * (d_t - d_ref);
      angle_sq_ += ae * ae;
      ++dist_n_;
      min_obstacle_ = std::min(min_obstacle_, d_o);
      min_human_ = std::min(min_human_, d_t);
      const bool in_obs = d_o < r;
      if (in_obs && !in_obstacle_[static_cast<std::size_t>(i)]) ++collisions_;
      in_obstacle_[static_cast<std::size_t>(i)] = in_obs;
      const Eigen::Vector3d feet = ws.feet_world;
      const double along = std::clamp(s.p_world.z() - feet.z(), 0.0, cfg_.worker.height_m);
      const double radial = (s.p_world - Eigen::Vector3d(feet.x(), feet.y(), feet.z() + along)).norm();
      const bool in_w = radial < 0.3 + r;
      if (in_w && !in_worker_[static_cast<std::size_t>(i)]) ++collisions_;
      in_worker_[static_cast<std::size_t>(i)] = in_w;
      row << "," << s.p_world.x() << "," << s.p_world.y() << "," << s.p_world.z() << "," << d_t << "," << d_ref << ","
          << d_o << "," << common::radToDeg(phi) << "," << common::radToDeg(ref.heading_rad) << ","
          << common::radToDeg(elev) << "," << formation::elevationDeg(params_, i) << ","
          << common::radToDeg(s.heading_rad) << "," << common::radToDeg(s.pitch_rad) << "," << s.v_world.norm();
    }
    for (int i = 0; i < n_; ++i) {
      for (int j = i + 1; j < n_; ++j) {
        const double d = (ps[static_cast<std::size_t>(i)] - ps[static_cast<std::size_t>(j)]).norm();
        min_mutual_ = std::min(min_mutual_, d);
        const double rr = cfg_.uavs[static_cast<std::size_t>(i)].plant.body_radius_m + cfg_.uavs[static_cast<std::size_t>(j)].plant.body_radius_m;
        const bool hit = d < rr;
        auto slot = pair_collision_[static_cast<std::size_t>(i * n_ + j)];
        if (hit && !slot) ++collisions_;
        pair_collision_[static_cast<std::size_t>(i * n_ + j)] = hit;
        row << "," << d;
      }
    }
    row << "," << worker_->performingAt(t_) << "," << last_class_ << "," << last_ratio_;
    timeline_.push_back(row.str());
  }

  void finish() {
    finished_ = true;
    const double wall = (ros::WallTime::now() - wall0_).toSec();
    // Gestures: a fired command matches a performed gesture of its id that it fired during
    // (success: the adaptation started while the worker still performed it; the planner
    // replans within one period after the command) or that started ≤ gesture_match_window_s before.
    const auto& eps = worker_->episodes();
    std::vector<bool> used(eps.size(), false);
    int success = 0, false_adapt = 0;
    double latency_sum = 0.0;
    for (const auto& [tf, id] : fired_) {
      int match = -1;
      for (std::size_t e = 0; e < eps.size(); ++e) {
        if (!used[e] && eps[e].gesture_id == id && tf >= eps[e].start_s && tf - eps[e].start_s <= cfg_.gesture_match_window_s) {
          match = static_cast<int>(e);
          break;
        }
      }
      if (match < 0) {
        ++false_adapt;
        continue;
      }
      used[static_cast<std::size_t>(match)] = true;
      if (tf <= eps[static_cast<std::size_t>(match)].end_s) ++success;
      latency_sum += tf - eps[static_cast<std::size_t>(match)].start_s;
    }
    const int matched = static_cast<int>(std::count(used.begin(), used.end(), true));
    std::ostringstream j;
    j << "{\n"
      << "  \"min_mutual_distance_m\": " << num(min_mutual_) << ",\n"
      << "  \"min_obstacle_distance_m\": " << num(min_obstacle_) << ",\n"
      << "  \"min_human_distance_m\": " << num(min_human_) << ",\n"
      << "  \"collisions\": " << collisions_ << ",\n"
      << "  \"distance_error_rms_m\": " << num(std::sqrt(dist_sq_ / std::max<long>(1, dist_n_))) << ",\n"
      << "  \"angle_error_rms_deg\": " << num(std::sqrt(angle_sq_ / std::max<long>(1, dist_n_))) << ",\n"
      << "  \"requests_applied\": " << requests_applied_ << ",\n"
      << "  \"gesture_success_rate\": " << num(eps.empty() ? std::nan("") : double(success) / double(eps.size())) << ",\n"
      << "  \"gesture_mean_latency_s\": " << num(matched ? latency_sum / matched : std::nan("")) << ",\n"
      << "  \"false_adaptations\": " << false_adapt << ",\n"
      << "  \"planning_ms_median\": " << num(pct(plan_ms_, 0.5)) << ",\n"
      << "  \"planning_ms_p99\": " << num(pct(plan_ms_, 0.99)) << ",\n"
      << "  \"human_estimate_error_rms_m\": " << num(std::sqrt(est_sq_ / std::max<long>(1, est_n_))) << ",\n"
      << "  \"requests_total\": " << (cfg_.requests.size() + eps.size()) << ",\n"
      << "  \"operator_requests_applied\": " << operator_applied_ << ",\n"
      << "  \"gesture_requests_applied\": " << gesture_applied_ << ",\n"
      << "  \"gestures_performed\": " << eps.size() << ",\n"
      << "  \"gestures_successful\": " << success << ",\n"
      << "  \"plans\": " << plans_ << ", \"plans_fallback_previous\": " << plans_previous_
      << ", \"plans_fallback_brake\": " << plans_brake_ << ",\n"
      << "  \"visible_fraction\": " << num(frames_ ? double(visible_frames_) / double(frames_) : 0.0) << ",\n"
      << "  \"sim_time_s\": " << num(t_) << ", \"wall_time_s\": " << num(wall) << ", \"real_time_factor\": "
      << num(t_ / std::max(1e-9, wall)) << ",\n"
      << "  \"obstacle_distance_source\": \"distance field (voxel centres)\",\n"
      << "  \"wall_clock_keys\": [\"planning_ms_median\", \"planning_ms_p99\", \"wall_time_s\", \"real_time_factor\"]\n"
      << "}\n";
    std::ofstream(output_dir_ + "/metrics.json") << j.str();
    std::ofstream tl(output_dir_ + "/timeline.csv");
    tl << "t,worker_x,worker_y,worker_z";
    for (int i = 0; i < n_; ++i) {
      for (const char* c : {"x", "y", "z", "d_t", "d_ref", "d_o", "phi_deg", "phi_ref_deg", "elev_deg", "elev_ref_deg",
                            "heading_deg", "pitch_deg", "speed"}) {
        tl << "," << label(i) << "_" << c;
      }
    }
    for (int i = 0; i < n_; ++i) {
      for (int k = i + 1; k < n_; ++k) tl << ",d_m_" << label(i) << "_" << label(k);
    }
    tl << ",gesture_true,gesture_class,dominant_ratio\n";
    for (const auto& r : timeline_) tl << r << "\n";
    std::ofstream ev(output_dir_ + "/events.csv");
    ev << "t,source,description,status,applied_t\n";
    for (const auto& e : events_) {
      std::string d = e.description;
      std::replace(d.begin(), d.end(), ',', ';');
      std::string o = e.outcome;
      std::replace(o.begin(), o.end(), ',', ';');
      ev << e.t << "," << e.source << "," << d << "," << o << "," << e.t << "\n";
    }
    NODELET_INFO_STREAM("SimWorld: mission done at t = " << t_ << " s (" << wall << " s wall); wrote " << output_dir_
                                                         << "/metrics.json");
    std_msgs::Bool done;
    done.data = true;
    done_pub_.publish(done);
  }

  struct Event {
    double t;
    std::string source, description, outcome;
  };
  std::mutex mutex_;
  sim::MissionConfig cfg_;
  WorldMap world_;
  std::optional<gesture::GestureClassifier> classifier_;
  std::optional<sim::WorkerModel> worker_;
  std::optional<sim::SyntheticSensors> sensors_;
  std::optional<formation::WorkerHeading> heading_;
  gesture::SkeletonWindow window_;
  formation::FormationParams params_;
  std::string output_dir_, world_frame_, camera_frame_;
  double rtf_ = 1.0, clock_step_s_ = 0.01, duration_s_ = 0.0, t_ = 0.0, last_skeleton_t_ = -1e9;
  int n_ = 0;
  bool finished_ = false, started_ = false;
  std::size_t next_request_ = 0;
  std::vector<std::optional<nav_msgs::Odometry>> truth_;
  std::optional<gesture_formation::WorkerState> estimate_;
  // metrics
  double min_mutual_ = INFINITY, min_obstacle_ = INFINITY, min_human_ = INFINITY;
  double dist_sq_ = 0.0, angle_sq_ = 0.0, est_sq_ = 0.0, last_ratio_ = 0.0;
  long dist_n_ = 0, est_n_ = 0, frames_ = 0, visible_frames_ = 0;
  int collisions_ = 0, requests_applied_ = 0, operator_applied_ = 0, gesture_applied_ = 0, last_class_ = -1;
  int plans_ = 0, plans_previous_ = 0, plans_brake_ = 0;
  std::vector<bool> in_obstacle_, in_worker_, pair_collision_;
  std::uint64_t version_ = 0;
  std::vector<double> plan_ms_;
  std::vector<std::pair<double, int>> fired_;
  std::vector<Event> events_;
  std::vector<std::string> timeline_;
  ros::WallTime wall0_;
  ros::Publisher clock_pub_, worker_pub_, detection_pub_, uwb_pub_, gesture_pub_, command_pub_, done_pub_;
  std::vector<ros::Subscriber> truth_subs_, plan_subs_;
  ros::Subscriber params_sub_, estimate_sub_, status_sub_;
  ros::WallTimer clock_timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::SimWorldNodelet, nodelet::Nodelet)

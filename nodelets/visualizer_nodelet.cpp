// Visualizer nodelet: rviz markers of what the formation thinks (config/rviz/gesture_formation.rviz).
// Namespaces: uavs (body spheres), frusta (camera frusta, line lists), worker (estimate),
// worker_cov (3σ covariance ellipsoid of the position), worker_truth (simulation only),
// references (stage-1 references), plans (planned trajectories), paths (stage-2 paths:
// the centre lines of the safe corridors), modes (the plan's mode and reason above a UAV that does
// not track: hold, search), map (occupied voxels of ~scenario_file), status
// (gesture filter and last command text), assistance (a red banner while the worker's request for
// assistance is pending). Colours per UAV: leader red, follower 1 green,
// follower 2 blue, then orange, purple.
//
// Topics: uav<i>/odometry, uav<i>/plan (i < ~uav_count), worker_state_in, worker_truth_in,
//   formation_params_in, gesture_status_in, assistance_in (the leader's AssistanceState) → markers_out (MarkerArray at ~rate_hz), map_out
//   (latched MarkerArray, published on the first tick with a valid time). Markers carry the time
//   they were drawn (ros::Time::now(): sim time in simulation and replay). No math beyond drawing (the ellipsoid's axes: eigen decomposition
//   of the 3×3 position covariance).
// Parameters (required): ~uav_count, ~world_frame, ~rate_hz, ~frustum_range_m,
//   ~frustum_hfov_deg, ~frustum_vfov_deg, ~scenario_file ("" = no map).
#include <mutex>
#include <optional>

#include <Eigen/Eigenvalues>
#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include "config_sources.hpp"
#include "conversions.hpp"
#include "gesture_formation/GestureStatus.h"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

namespace {
std_msgs::ColorRGBA color(int uav, float alpha = 1.0f) {
  static const float kColors[5][3] = {{0.9f, 0.1f, 0.1f}, {0.1f, 0.8f, 0.1f}, {0.1f, 0.3f, 1.0f}, {1.0f, 0.6f, 0.0f}, {0.6f, 0.2f, 0.8f}};
  const auto& c = kColors[uav % 5];
  std_msgs::ColorRGBA m;
  m.r = c[0];
  m.g = c[1];
  m.b = c[2];
  m.a = alpha;
  return m;
}
std_msgs::ColorRGBA rgba(float r, float g, float b, float a) {
  std_msgs::ColorRGBA m;
  m.r = r;
  m.g = g;
  m.b = b;
  m.a = a;
  return m;
}
}  // namespace

class VisualizerNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ParamLoader params(getPrivateNodeHandle());
    double rate_hz = 0.0;
    std::string scenario_file;
    params.load("uav_count", uav_count_, 1, 32);
    params.load("world_frame", world_frame_);
    params.load("rate_hz", rate_hz, 0.1, 60.0);
    params.load("frustum_range_m", frustum_range_m_, 0.1, 100.0);
    params.load("frustum_hfov_deg", hfov_deg_, 1.0, 179.0);
    params.load("frustum_vfov_deg", vfov_deg_, 1.0, 179.0);
    params.load("scenario_file", scenario_file);
    WorldMap world;
    if (!scenario_file.empty()) loadWorldMap(scenario_file, params, world);
    if (!params.ok()) {
      NODELET_ERROR_STREAM("Visualizer refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("Visualizer loaded:\n" << params.loaded());
    odom_.resize(static_cast<std::size_t>(uav_count_));
    plans_.resize(static_cast<std::size_t>(uav_count_));
    for (int i = 0; i < uav_count_; ++i) {
      const auto k = static_cast<std::size_t>(i);
      keepLatest<nav_msgs::Odometry>(nh, "uav" + std::to_string(i) + "/odometry", &odom_[k]);
      keepLatest<gesture_formation::PlannedTrajectory>(nh, "uav" + std::to_string(i) + "/plan", &plans_[k]);
    }
    keepLatest<gesture_formation::WorkerState>(nh, "worker_state_in", &worker_);
    keepLatest<nav_msgs::Odometry>(nh, "worker_truth_in", &truth_);
    keepLatest<gesture_formation::FormationParams>(nh, "formation_params_in", &params_);
    keepLatest<gesture_formation::GestureStatus>(nh, "gesture_status_in", &gesture_);
    keepLatest<gesture_formation::AssistanceState>(nh, "assistance_in", &assistance_);
    pub_ = nh.advertise<visualization_msgs::MarkerArray>("markers_out", 2);
    map_pub_ = nh.advertise<visualization_msgs::MarkerArray>("map_out", 1, true);
    map_ = world.map;
    timer_ = nh.createTimer(ros::Duration(1.0 / rate_hz), &VisualizerNodelet::onTimer, this);
  }

  /// Subscribes `topic`; its latest message goes to `*latest` (drawn at the next tick).
  template <class Msg>
  void keepLatest(ros::NodeHandle& nh, const std::string& topic, typename Msg::ConstPtr* latest) {
    subs_.push_back(nh.subscribe<Msg>(topic, 5, [this, latest](const typename Msg::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      *latest = m;
    }));
  }

  visualization_msgs::Marker marker(const std::string& ns, int id, int type, const ros::Time& stamp) const {
    visualization_msgs::Marker m;
    m.header.frame_id = world_frame_;
    m.header.stamp = stamp;
    m.ns = ns;
    m.id = id;
    m.type = type;
    m.action = visualization_msgs::Marker::ADD;
    m.pose.orientation.w = 1.0;
    m.lifetime = ros::Duration(2.0);
    return m;
  }

  /// A line strip or list `width_m` wide through `points`.
  visualization_msgs::Marker lines(const std::string& ns, int id, int type, const ros::Time& stamp, double width_m,
                                   const std_msgs::ColorRGBA& c, const std::vector<geometry_msgs::Point>& points) const {
    visualization_msgs::Marker m = marker(ns, id, type, stamp);
    m.scale.x = width_m;
    m.color = c;
    m.points = points;
    return m;
  }

  void publishMap(const planning::OccupancyMap& map, const ros::Time& stamp) {
    visualization_msgs::MarkerArray a;
    auto m = marker("map", 0, visualization_msgs::Marker::CUBE_LIST, stamp);
    m.lifetime = ros::Duration(0.0);
    m.scale.x = m.scale.y = m.scale.z = map.resolution();
    m.color = rgba(0.55f, 0.55f, 0.6f, 0.6f);
    for (const auto& c : map.occupiedCenters()) {
      if (c.z() > map.resolution()) m.points.push_back(toPoint(c));  // the ground is drawn by rviz' grid
    }
    a.markers.push_back(m);
    map_pub_.publish(a);
  }

  void onTimer(const ros::TimerEvent&) {
    std::lock_guard<std::mutex> lock(mutex_);
    const ros::Time now = ros::Time::now();
    if (now.isZero()) return;  // sim time not started
    if (map_) {
      publishMap(*map_, now);
      map_.reset();
    }
    visualization_msgs::MarkerArray a;
    const double th = std::tan(hfov_deg_ * M_PI / 360.0), tv = std::tan(vfov_deg_ * M_PI / 360.0);
    for (int i = 0; i < uav_count_; ++i) {
      const auto& o = odom_[static_cast<std::size_t>(i)];
      if (o) {
        auto body = marker("uavs", i, visualization_msgs::Marker::SPHERE, now);
        body.pose = o->pose.pose;
        body.scale.x = body.scale.y = body.scale.z = 0.7;
        body.color = color(i);
        a.markers.push_back(body);
        // Frustum: apex at the UAV, four corners at frustum_range_m along the camera axis.
        auto f = marker("frusta", i, visualization_msgs::Marker::LINE_LIST, now);
        f.pose = o->pose.pose;
        f.scale.x = 0.06;
        f.color = color(i, 0.9f);
        const double r = frustum_range_m_;
        const Eigen::Vector3d corners[4] = {{r, r * th, r * tv}, {r, -r * th, r * tv}, {r, -r * th, -r * tv}, {r, r * th, -r * tv}};
        for (int c = 0; c < 4; ++c) {
          f.points.push_back(toPoint(Eigen::Vector3d::Zero()));
          f.points.push_back(toPoint(corners[c]));
          f.points.push_back(toPoint(corners[c]));
          f.points.push_back(toPoint(corners[(c + 1) % 4]));
        }
        a.markers.push_back(f);
      }
      const auto& p = plans_[static_cast<std::size_t>(i)];
      if (p) {
        const auto strip = [&](const char* ns, double width_m, const std_msgs::ColorRGBA& c,
                               const std::vector<geometry_msgs::Point>& points) {
          if (points.size() >= 2) a.markers.push_back(lines(ns, i, visualization_msgs::Marker::LINE_STRIP, now, width_m, c, points));
        };
        strip("plans", 0.12, color(i), p->positions);
        strip("references", 0.3, color(i, 0.3f), p->reference);
        strip("paths", 0.05, rgba(1.0f, 1.0f, 1.0f, 0.8f), p->path);
        if (p->corridor_edges.size() >= 2 && p->corridor_edges.size() % 2 == 0) {
          a.markers.push_back(
              lines("corridors", i, visualization_msgs::Marker::LINE_LIST, now, 0.03, color(i, 0.35f), p->corridor_edges));
        }
        // A UAV that does not track says why (hold / search, docs/safety.md §1–2), above its body.
        if (o && !p->mode.empty() && p->mode != "track") {
          auto label = marker("modes", i, visualization_msgs::Marker::TEXT_VIEW_FACING, now);
          label.pose.position = o->pose.pose.position;
          label.pose.position.z += 1.5;
          label.scale.z = 0.6;
          label.color = color(i);
          label.text = p->mode + (p->mode_reason.empty() ? "" : ": " + p->mode_reason);
          a.markers.push_back(label);
        }
      }
    }
    geometry_msgs::Point text_at;
    if (worker_) {
      auto w = marker("worker", 0, visualization_msgs::Marker::SPHERE, now);
      w.pose.position = worker_->position;
      w.scale.x = w.scale.y = w.scale.z = 0.4;
      w.color = rgba(1.0f, 0.9f, 0.0f, 1.0f);
      a.markers.push_back(w);
      Eigen::Matrix3d P;
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) P(r, c) = worker_->covariance[static_cast<std::size_t>(6 * r + c)];
      }
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(P);
      Eigen::Matrix3d R = es.eigenvectors();
      if (R.determinant() < 0) R.col(2) = -R.col(2);
      const Eigen::Quaterniond q(R);
      auto cov = marker("worker_cov", 0, visualization_msgs::Marker::SPHERE, now);
      cov.pose.position = worker_->position;
      cov.pose.orientation.w = q.w();
      cov.pose.orientation.x = q.x();
      cov.pose.orientation.y = q.y();
      cov.pose.orientation.z = q.z();
      cov.scale.x = std::max(0.05, 6.0 * std::sqrt(std::max(0.0, es.eigenvalues()(0))));  // 3σ
      cov.scale.y = std::max(0.05, 6.0 * std::sqrt(std::max(0.0, es.eigenvalues()(1))));
      cov.scale.z = std::max(0.05, 6.0 * std::sqrt(std::max(0.0, es.eigenvalues()(2))));
      cov.color = rgba(1.0f, 0.9f, 0.0f, 0.35f);
      a.markers.push_back(cov);
      text_at = worker_->position;
    }
    if (truth_) {
      auto t = marker("worker_truth", 0, visualization_msgs::Marker::CYLINDER, now);
      t.pose.position = truth_->pose.pose.position;
      t.scale.x = t.scale.y = 0.6;
      t.scale.z = 1.78;
      t.color = rgba(0.9f, 0.5f, 0.1f, 0.5f);
      a.markers.push_back(t);
      if (!worker_) text_at = truth_->pose.pose.position;
    }
    std::string text;
    if (gesture_) {
      text += "gesture " + std::to_string(gesture_->gesture_id) + "  dominant " + std::to_string(gesture_->dominant_id) +
              " f_d " + std::to_string(gesture_->dominant_ratio).substr(0, 4) + "  " + gesture_->verdict;
      if (!gesture_->last_fired.empty()) text += "\nlast fired: " + gesture_->last_fired;
    }
    if (params_) {
      text += "\nparams v" + std::to_string(params_->version);
      for (std::size_t i = 0; i < params_->uavs.size(); ++i) {
        const auto& u = params_->uavs[i];
        text += std::string("\n") + (i == 0 ? "L" : std::to_string(i)) + ": beta " + std::to_string(static_cast<int>(std::lround(u.beta_deg))) +
                " gamma " + std::to_string(static_cast<int>(std::lround(u.gamma_deg))) + " d " + std::to_string(u.distance_m).substr(0, 4);
      }
      if (!params_->last_command.empty()) text += "\n" + params_->last_command + " -> " + params_->last_outcome;
    }
    if (!text.empty()) {
      auto t = marker("status", 0, visualization_msgs::Marker::TEXT_VIEW_FACING, now);
      t.pose.position = text_at;
      t.pose.position.z += 4.0;
      t.scale.z = 0.8;
      t.color = rgba(1.0f, 1.0f, 1.0f, 1.0f);
      t.text = text;
      a.markers.push_back(t);
    }
    // The worker's pending request for assistance: a red banner above the status (safety.md §2.10).
    auto banner = marker("assistance", 0, visualization_msgs::Marker::TEXT_VIEW_FACING, now);
    if (assistance_ && assistance_->phase == gesture_formation::AssistanceState::PHASE_REQUESTED) {
      banner.pose.position = text_at;
      banner.pose.position.z += 9.0;
      banner.scale.z = 1.6;
      banner.color = rgba(1.0f, 0.1f, 0.1f, 1.0f);
      banner.text = "ASSISTANCE REQUESTED at " + std::to_string(assistance_->requested_at.toSec()).substr(0, 6) +
                    " s (gf_command.py ack-assist)";
    } else {
      banner.action = visualization_msgs::Marker::DELETE;
    }
    a.markers.push_back(banner);
    pub_.publish(a);
  }

  std::mutex mutex_;
  int uav_count_ = 0;
  std::string world_frame_;
  double frustum_range_m_ = 3.0, hfov_deg_ = 69.0, vfov_deg_ = 42.0;
  std::vector<nav_msgs::Odometry::ConstPtr> odom_;
  std::vector<gesture_formation::PlannedTrajectory::ConstPtr> plans_;
  gesture_formation::WorkerState::ConstPtr worker_;
  nav_msgs::Odometry::ConstPtr truth_;
  gesture_formation::FormationParams::ConstPtr params_;
  gesture_formation::GestureStatus::ConstPtr gesture_;
  gesture_formation::AssistanceState::ConstPtr assistance_;
  std::shared_ptr<const planning::OccupancyMap> map_;  ///< to publish once (then released)
  std::vector<ros::Subscriber> subs_;
  ros::Publisher pub_, map_pub_;
  ros::Timer timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::VisualizerNodelet, nodelet::Nodelet)

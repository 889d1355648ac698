// ViewObserver nodelet: one UAV's vote in the formation's multi-view gesture fusion
// (docs/gestures.md §4.1, gesture::ViewFusion). It stamps this UAV's classifier output with the
// geometry of its camera to the worker, computed on this UAV from what it has: its own odometry
// and the worker state it holds (the leader's estimator; on followers, the leader's estimate
// received over LCM), predicted to the frame's time. The leader's GestureCommander fuses the
// views; followers' observations reach it through the LcmBridge.
//
// Topics: gesture_in (Gesture: this UAV's classifier, e.g. the Perception nodelet or SimWorld),
//   odometry_in (nav_msgs/Odometry of this UAV), worker_state_in (WorkerState)
//   → observation_out (GestureObservation, one per classifier output).
// Parameters (required): ~uav_index, ~max_state_age_s (odometry and worker state older than this
//   at the frame's time, or a lost worker: geometry unknown, the view does not vote).
#include <algorithm>
#include <cmath>
#include <mutex>
#include <optional>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>

#include "conversions.hpp"
#include "gesture_formation/Gesture.h"
#include "gesture_formation/common/angles.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class ViewObserverNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ParamLoader params(getPrivateNodeHandle());
    params.load("uav_index", uav_index_, 0, comm::kMaxUavIndex);
    params.load("max_state_age_s", max_state_age_s_, 0.01, 10.0);
    if (!params.ok()) {
      NODELET_ERROR_STREAM("ViewObserver refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("ViewObserver loaded:\n" << params.loaded());
    observation_pub_ = nh.advertise<gesture_formation::GestureObservation>("observation_out", 20);
    odometry_sub_ = nh.subscribe<nav_msgs::Odometry>("odometry_in", 5, [this](const nav_msgs::Odometry::ConstPtr& m) {
      std::lock_guard<std::mutex> lock(mutex_);
      odometry_ = *m;
    });
    worker_sub_ = nh.subscribe<gesture_formation::WorkerState>(
        "worker_state_in", 5, [this](const gesture_formation::WorkerState::ConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          worker_ = *m;
        });
    gesture_sub_ = nh.subscribe("gesture_in", 20, &ViewObserverNodelet::onGesture, this);
  }

  void onGesture(const gesture_formation::Gesture::ConstPtr& g) {
    gesture_formation::GestureObservation o;
    o.header = g->header;
    o.uav_index = static_cast<std::uint8_t>(uav_index_);
    o.gesture_id = g->gesture_id;
    o.probabilities = g->probabilities;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const double t = g->header.stamp.toSec();
      const auto fresh = [&](const ros::Time& s) { return std::abs(t - s.toSec()) <= max_state_age_s_; };
      if (odometry_ && worker_ && !worker_->lost && fresh(odometry_->header.stamp) && fresh(worker_->header.stamp)) {
        // The camera's distance and elevation from the worker estimate predicted to the frame.
        const Eigen::Vector3d p_worker =
            toEigen(worker_->position) + (t - worker_->header.stamp.toSec()) * toEigen(worker_->velocity);
        const Eigen::Vector3d rel = toEigen(odometry_->pose.pose.position) - p_worker;
        const double d = rel.norm();
        if (std::isfinite(d) && d > 1e-9) {
          o.geometry_known = true;
          o.distance_m = d;
          o.elevation_deg = common::radToDeg(std::asin(std::clamp(rel.z() / d, -1.0, 1.0)));
        }
      }
    }
    observation_pub_.publish(o);
  }

  std::mutex mutex_;
  int uav_index_ = 0;
  double max_state_age_s_ = 0.0;
  std::optional<nav_msgs::Odometry> odometry_;
  std::optional<gesture_formation::WorkerState> worker_;
  ros::Publisher observation_pub_;
  ros::Subscriber odometry_sub_, worker_sub_, gesture_sub_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::ViewObserverNodelet, nodelet::Nodelet)

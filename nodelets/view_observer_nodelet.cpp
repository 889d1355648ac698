// ViewObserver nodelet: one UAV's vote in the formation's multi-view gesture fusion
// (docs/gestures.md §4.1, gesture::ViewFusion). It stamps this UAV's classifier output with the
// geometry of its camera to the worker, computed on this UAV from what it has: its own odometry
// and the worker state it holds (the leader's estimator; on followers, the leader's estimate
// received over LCM), predicted to the frame's time. The leader's GestureCommander fuses the
// views; followers' observations reach it through the LcmBridge.
//
// A classification that carries its skeleton (Gesture.keypoints) gets the pose of its image's
// optical frame (the Gesture's frame_id) in the world frame at the frame's time from tf — on a
// UAV: its odometry and the camera's mounting — for the leader's 3-D confirmation
// (view_fusion.confirm_3d, docs/gestures.md §4.1); without a pose within ~tf_timeout_s, or with a
// skeleton or camera info that cannot be used, the observation goes without the skeleton (its
// 2-D vote is unaffected).
//
// Topics: gesture_in (Gesture: this UAV's classifier, e.g. the Perception nodelet or SimWorld),
//   odometry_in (nav_msgs/Odometry of this UAV), worker_state_in (WorkerState), tf
//   → observation_out (GestureObservation, one per classifier output).
// Parameters (required): ~uav_index, ~max_state_age_s (odometry and worker state older than this
//   at the frame's time, or a lost worker: geometry unknown, the view does not vote),
//   ~world_frame, ~tf_timeout_s (how long to wait for the camera's pose at the frame's time).
// odometry_in must be in the planner's convention (docs/ros.md): header.frame_id and
// child_frame_id = ~world_frame; other odometry is refused (onboard::checkOdometryFrames), the
// error naming the field, expected and received value, at most every 2 s, and counted.
// /diagnostics: `ViewObserver uav<i>`: observations per second, how many had their geometry and
// their skeleton, refused odometry, the ages of the odometry and worker state.
#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "conversions.hpp"
#include "diagnostics.hpp"
#include "gesture_formation/Gesture.h"
#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/onboard/frame_check.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class ViewObserverNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ParamLoader params(getPrivateNodeHandle());
    params.load("uav_index", uav_index_, 0, comm::kMaxUavIndex);
    params.load("max_state_age_s", max_state_age_s_, 0.01, 10.0);
    params.load("world_frame", world_frame_);
    params.load("tf_timeout_s", tf_timeout_s_, 0.0, 1.0);
    if (world_frame_.empty()) params.addError("world_frame: must be non-empty");
    if (!params.ok()) {
      NODELET_ERROR_STREAM("ViewObserver refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("ViewObserver loaded:\n" << params.loaded());
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(tf_buffer_);
    observation_pub_ = nh.advertise<gesture_formation::GestureObservation>("observation_out", 20);
    odometry_sub_ = nh.subscribe<nav_msgs::Odometry>("odometry_in", 5, [this](const nav_msgs::Odometry::ConstPtr& m) {
      const auto refusal = onboard::checkOdometryFrames("odometry_in", onboard::plannerOdometryFrames(world_frame_),
                                                        m->header.frame_id, m->child_frame_id);
      std::lock_guard<std::mutex> lock(mutex_);
      if (refusal) {
        ++odometry_refused_;
        last_refusal_ = *refusal;
        NODELET_ERROR_STREAM_THROTTLE(2.0, "ViewObserver: odometry refused (nothing from it is used): " << *refusal);
        return;
      }
      odometry_ = *m;
    });
    worker_sub_ = nh.subscribe<gesture_formation::WorkerState>(
        "worker_state_in", 5, [this](const gesture_formation::WorkerState::ConstPtr& m) {
          std::lock_guard<std::mutex> lock(mutex_);
          worker_ = *m;
        });
    gesture_sub_ = nh.subscribe("gesture_in", 20, &ViewObserverNodelet::onGesture, this);
    diagnostics_.start(nh, 1.0, [this](double since_s) { return health(since_s); });
  }

  /// This UAV's vote on /diagnostics: WARN when classifications went out without geometry (they
  /// do not vote) or odometry was refused since the last report.
  std::vector<diagnostic_msgs::DiagnosticStatus> health(double since_s) {
    std::lock_guard<std::mutex> lock(mutex_);
    const double t = ros::Time::now().toSec();
    const auto age = [t](const ros::Time& s) { return s.isZero() ? -1.0 : t - s.toSec(); };
    const std::uint64_t new_refusals = odometry_refused_ - refused_reported_;
    Health h("ViewObserver uav" + std::to_string(uav_index_), "uav" + std::to_string(uav_index_));
    h.warn(new_refusals > 0, std::to_string(new_refusals) + " odometry message(s) refused: " + last_refusal_)
        .warn(observations_ > with_geometry_,
              std::to_string(observations_ - with_geometry_) + " observation(s) without geometry (no vote)")
        .value("observations_per_s", observations_ / since_s)
        .value("with_geometry", with_geometry_)
        .value("with_skeleton", with_skeleton_)
        .value("odometry_refused", odometry_refused_)
        .value("odometry_age_s", odometry_ ? age(odometry_->header.stamp) : -1.0)
        .value("worker_state_age_s", worker_ ? age(worker_->header.stamp) : -1.0);
    refused_reported_ = odometry_refused_;
    observations_ = with_geometry_ = with_skeleton_ = 0;
    return {h.status()};
  }

  void onGesture(const gesture_formation::Gesture::ConstPtr& g) {
    gesture_formation::GestureObservation o;
    o.header = g->header;
    o.uav_index = static_cast<std::uint8_t>(uav_index_);
    o.gesture_id = g->gesture_id;
    o.probabilities = g->probabilities;
    if (!g->keypoints.empty()) attachSkeleton(*g, o);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      const double t = g->header.stamp.toSec();
      const auto fresh = [&](const ros::Time& s) { return std::abs(t - s.toSec()) <= max_state_age_s_; };
      if (odometry_ && worker_ && !worker_->lost && fresh(odometry_->header.stamp) && fresh(worker_->header.stamp)) {
        // The camera's distance and elevation from the worker estimate predicted to the frame.
        const Eigen::Vector3d p_worker = toWorkerKnowledge(*worker_).positionAt(t);
        const formation::ViewGeometry g = formation::viewGeometry(toEigen(odometry_->pose.pose.position), p_worker);
        if (std::isfinite(g.distance_m) && g.distance_m > 1e-9) {
          o.geometry_known = true;
          o.distance_m = g.distance_m;
          o.elevation_deg = g.elevation_deg;
        }
      }
      ++observations_;
      if (o.geometry_known) ++with_geometry_;
      if (!o.keypoints.empty()) ++with_skeleton_;
    }
    observation_pub_.publish(o);
  }

  /// The skeleton with its camera's pose at the frame's time, when both can be used.
  void attachSkeleton(const gesture_formation::Gesture& g, gesture_formation::GestureObservation& o) {
    geometry_msgs::TransformStamped T_world_camera;
    try {
      T_world_camera = tf_buffer_.lookupTransform(world_frame_, g.header.frame_id, g.header.stamp, ros::Duration(tf_timeout_s_));
    } catch (const tf2::TransformException& e) {
      NODELET_WARN_STREAM_THROTTLE(5.0, "ViewObserver: no camera pose for the skeleton (3-D confirmation): " << e.what());
      return;
    }
    const geometry_msgs::Pose pose = toPose(T_world_camera.transform);
    const auto c = toCalibrated(g.keypoints, g.camera, pose);
    if (!c) {
      NODELET_WARN_STREAM_THROTTLE(5.0, "ViewObserver: skeleton not usable for the 3-D confirmation: " << c.reason());
      return;
    }
    o.keypoints = g.keypoints;
    o.camera = g.camera;
    o.camera_pose = pose;
  }

  std::mutex mutex_;
  DiagnosticsPublisher diagnostics_;
  int observations_ = 0, with_geometry_ = 0, with_skeleton_ = 0;  ///< since the last report
  std::uint64_t odometry_refused_ = 0, refused_reported_ = 0;
  std::string last_refusal_;
  int uav_index_ = 0;
  double max_state_age_s_ = 0.0, tf_timeout_s_ = 0.0;
  std::string world_frame_;
  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::optional<nav_msgs::Odometry> odometry_;
  std::optional<gesture_formation::WorkerState> worker_;
  ros::Publisher observation_pub_;
  ros::Subscriber odometry_sub_, worker_sub_, gesture_sub_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::ViewObserverNodelet, nodelet::Nodelet)

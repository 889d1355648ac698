#pragma once
// SimWorld's camera outputs (docs/ros.md "SimWorld"): the leader camera's UWB range, and with the
// synthetic camera its CameraInfo and detection and every UAV's classification as its Perception
// nodelet would publish it (with the gesture camera on tf for the 3-D confirmation). The leader
// camera is the one of the UAV doing the leader's work (`owner`: UAV 0, or with ~leadership the UAV
// acting as leader, docs/safety.md §1.2 — as gfctl simulate gives every UAV the leader's sensors):
// its outputs go on uav<owner>/detection_out, uav<owner>/camera_info_out, uav<owner>/uwb_out, stamped
// in its camera frame. Thread safety: none (SimWorld's lock).
#include <optional>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include "sim_conversions.hpp"
#include "gesture_formation/sim/leader_camera.hpp"

namespace gesture_formation::nodelets {

class SimCameraTopics {
 public:
  /// UAV k's camera frame: `uav0_frame` (~leader_camera_frame) with its uav0/ prefix made uav<k>/.
  static std::string frameOf(const std::string& uav0_frame, int k) {
    const std::string prefix = "uav0/";
    if (k == 0 || uav0_frame.compare(0, prefix.size(), prefix) != 0) return uav0_frame;
    return "uav" + std::to_string(k) + "/" + uav0_frame.substr(prefix.size());
  }

  /// Every UAV's topics (n UAVs); `info` the leader camera's intrinsics; rendered: the UWB only.
  void advertise(ros::NodeHandle& nh, int n, bool rendered, const sensor_msgs::CameraInfo& info,
                 const std::string& uav0_frame, double uwb_max_range_m, bool calibrated_views) {
    rendered_ = rendered;
    info_ = info;
    uav0_frame_ = uav0_frame;
    uwb_max_range_m_ = uwb_max_range_m;
    calibrated_views_ = calibrated_views;
    for (int i = 0; i < n; ++i) {
      const std::string uav = "uav" + std::to_string(i) + "/";
      uwb_pubs_.push_back(nh.advertise<sensor_msgs::Range>(uav + "uwb_out", 10));
      if (rendered) continue;
      detection_pubs_.push_back(nh.advertise<gesture_formation::WorkerDetection>(uav + "detection_out", 10));
      info_pubs_.push_back(nh.advertise<sensor_msgs::CameraInfo>(uav + "camera_info_out", 2));
      gesture_pubs_.push_back(nh.advertise<gesture_formation::Gesture>(uav + "gesture_out", 10));
    }
  }

  /// The UAV index of the camera frame's followers[i]: the UAVs other than `owner`, in index order.
  static int followerUav(std::size_t i, int owner) {
    const int k = static_cast<int>(i);
    return k < owner ? k : k + 1;
  }

  /// One camera frame of the leader camera of UAV `owner`; `truth` every UAV's true state.
  void publish(const sim::LeaderCameraFrame& cf, int owner, const std::vector<std::optional<sim::MultirotorState>>& truth,
               const ros::Time& stamp) {
    const auto o = static_cast<std::size_t>(owner);
    const std::string frame = frameOf(uav0_frame_, owner);
    if (std::isfinite(cf.sensors.d_uwb_m)) uwb_pubs_[o].publish(toUwbRange(cf.sensors.d_uwb_m, uwb_max_range_m_, stamp, frame));
    if (rendered_) return;  // the Perception nodelets see the rendered images
    info_.header.stamp = stamp;
    info_.header.frame_id = frame;
    info_pubs_[o].publish(info_);
    // Each UAV's classifier output, the followers' first (the leader's closes the frame at the GestureCommander).
    for (std::size_t i = 0; i < cf.followers.size(); ++i) {
      const auto& f = cf.followers[i];
      if (f.classification) publishGesture(followerUav(i, owner), *f.classification, stamp, calibrated_views_ && f.visible ? &f.calibrated : nullptr, truth);
    }
    if (!cf.sensors.visible()) return;
    detection_pubs_[o].publish(toDetectionMsg(cf.sensors, stamp, frame));
    if (cf.classification) publishGesture(owner, *cf.classification, stamp, calibrated_views_ ? &cf.calibrated : nullptr, truth);
  }

 private:
  /// UAV `uav`'s classification as its Perception nodelet would publish it (with the 3-D
  /// confirmation: the skeleton and its camera on tf, toGestureMsg).
  void publishGesture(int uav, const gesture::Classification& c, const ros::Time& stamp, const gesture::CalibratedSkeleton* skeleton,
                      const std::vector<std::optional<sim::MultirotorState>>& truth) {
    const auto& t = truth[static_cast<std::size_t>(uav)];
    geometry_msgs::TransformStamped T;
    const auto g = toGestureMsg(uav, c, stamp, skeleton, t ? &*t : nullptr, &T);
    if (!T.child_frame_id.empty()) tf_.sendTransform(T);
    gesture_pubs_[static_cast<std::size_t>(uav)].publish(g);
  }

  bool rendered_ = false, calibrated_views_ = false;
  double uwb_max_range_m_ = 0.0;
  std::string uav0_frame_;
  sensor_msgs::CameraInfo info_;  ///< the leader camera's intrinsics (the estimator's camera model)
  tf2_ros::TransformBroadcaster tf_;  ///< the gesture cameras (3-D confirmation)
  std::vector<ros::Publisher> uwb_pubs_, detection_pubs_, info_pubs_, gesture_pubs_;  ///< per UAV
};

}  // namespace gesture_formation::nodelets

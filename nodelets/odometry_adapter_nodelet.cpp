// OdometryAdapter nodelet: a flight stack's nav_msgs/Odometry (MAVROS local_position/odom, the
// MRS system's odometry/odom_main: body attitude, twist in the body frame child_frame_id) + the
// camera mount → the odometry the FormationPlanner and the ViewObserver expect (docs/ros.md,
// odometry convention: orientation = the camera axis, twist in the world frame, child_frame_id =
// the world frame). A thin adapter over onboard::toPlannerState.
//
// A message whose header.frame_id is not ~world_frame or whose child_frame_id is not
// ~body_frame is refused — nothing from it is used — with an error naming the field, the
// expected and the received value (at most every 2 s; every refusal is counted on /diagnostics).
//
// Topics: odometry_in (nav_msgs/Odometry of the flight stack) → odometry_out (nav_msgs/Odometry,
//   the planner's convention, same stamp), /diagnostics.
// Parameters (required): ~world_frame (the odometry's fixed frame: MAVROS `map`, MRS
//   `<uav>/<estimator>_origin`), ~body_frame (its child_frame_id: MAVROS `base_link`, MRS
//   `<uav>/fcu`; = world_frame when the stack gives a world-frame twist), ~camera_mount (`tf`: the
//   transform body_frame → ~camera_frame at the odometry's stamp, waiting at most ~tf_timeout_s —
//   a gimbal's driver publishes it; `fixed`: ~camera_mount_rpy_rad [roll, pitch, yaw] of the camera
//   in the body, REP 103, pitch positive down), ~camera_optical_axis (`x`: an FLU camera frame such
//   as a RealSense camera_link; `z`: an optical frame), ~tf_timeout_s (tf only).
#include <cmath>
#include <memory>
#include <mutex>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "diagnostics.hpp"
#include "flight_stack_conversions.hpp"
#include "gesture_formation/onboard/frame_check.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class OdometryAdapterNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    ParamLoader params(pnh);
    params.load("world_frame", frames_.frame_id);
    params.load("body_frame", frames_.child_frame_id);
    std::string mount, axis;
    params.load("camera_mount", mount);
    params.load("camera_optical_axis", axis);
    if (axis == "x" || axis == "z") mount_.optical_axis = axis == "x" ? onboard::OpticalAxis::kX : onboard::OpticalAxis::kZ;
    else if (!axis.empty()) params.addError("camera_optical_axis '" + axis + "': expected x | z");
    if (mount == "tf") {
      params.load("camera_frame", camera_frame_);
      params.load("tf_timeout_s", tf_timeout_s_, 0.0, 1.0);
      if (frames_.child_frame_id == frames_.frame_id) params.addError("camera_mount 'tf': needs a body_frame other than world_frame");
    } else if (mount == "fixed") {
      loadFixedMount(pnh, params);
    } else if (!mount.empty()) {
      params.addError("camera_mount '" + mount + "': expected tf | fixed");
    }
    for (const auto* f : {&frames_.frame_id, &frames_.child_frame_id}) {
      if (f->empty()) params.addError("world_frame / body_frame: must be non-empty");
    }
    if (!params.ok()) {
      NODELET_ERROR_STREAM("OdometryAdapter refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("OdometryAdapter loaded:\n" << params.loaded());
    use_tf_ = mount == "tf";
    if (use_tf_) tf_listener_ = std::make_unique<tf2_ros::TransformListener>(tf_buffer_);
    odom_pub_ = nh.advertise<nav_msgs::Odometry>("odometry_out", 10);
    odom_sub_ = nh.subscribe("odometry_in", 10, &OdometryAdapterNodelet::onOdometry, this);
    diagnostics_.start(nh, 1.0, [this](double since_s) { return health(since_s); });
  }

  void loadFixedMount(ros::NodeHandle& pnh, ParamLoader& params) {
    std::vector<double> rpy;
    if (!pnh.getParam("camera_mount_rpy_rad", rpy) || rpy.size() != 3) {
      params.addError(pnh.resolveName("camera_mount_rpy_rad") + ": missing or not [roll, pitch, yaw] (3 numbers, rad)");
      return;
    }
    for (std::size_t i = 0; i < 3; ++i) {
      // Radians: degrees given by mistake (20 for 20°) would be read as a turn of 20 rad.
      if (!(std::abs(rpy[i]) <= M_PI)) {
        params.addError(pnh.resolveName("camera_mount_rpy_rad") + "[" + std::to_string(i) + "]: " + std::to_string(rpy[i]) +
                        " rad is outside [-pi, pi] (radians, not degrees)");
      }
    }
    if (!params.ok()) return;
    const auto axis = mount_.optical_axis;
    mount_ = onboard::CameraMount::fromRpy(rpy[0], rpy[1], rpy[2]);
    mount_.optical_axis = axis;
    params.note("camera_mount_rpy_rad = [" + std::to_string(rpy[0]) + ", " + std::to_string(rpy[1]) + ", " +
                std::to_string(rpy[2]) + "]");
  }

  void onOdometry(const nav_msgs::Odometry::ConstPtr& msg) {
    if (auto e = onboard::checkOdometryFrames("odometry_in", frames_, msg->header.frame_id, msg->child_frame_id)) {
      refuse(*e, refused_frames_);
      return;
    }
    onboard::CameraMount mount = mount_;
    if (use_tf_) {
      try {
        const auto T = tf_buffer_.lookupTransform(frames_.child_frame_id, camera_frame_, msg->header.stamp,
                                                  ros::Duration(tf_timeout_s_));
        mount.q_body_camera = toEigen(T.transform.rotation);
      } catch (const tf2::TransformException& ex) {
        refuse(std::string("no camera mount ") + frames_.child_frame_id + " → " + camera_frame_ + ": " + ex.what(), refused_mount_);
        return;
      }
    }
    const bool twist_in_body = frames_.child_frame_id != frames_.frame_id;
    const auto state = onboard::toPlannerState(toFlightStackOdometry(*msg, twist_in_body), mount);
    if (!state) {
      refuse("odometry_in " + state.reason(), refused_values_);
      return;
    }
    odom_pub_.publish(toPlannerOdometry(*state, msg->header.stamp, frames_.frame_id));
    std::lock_guard<std::mutex> lock(mutex_);
    ++published_since_report_;
    last_stamp_ = msg->header.stamp;
  }

  void refuse(const std::string& reason, std::uint64_t& counter) {
    NODELET_ERROR_STREAM_THROTTLE(2.0, "OdometryAdapter: odometry refused (nothing from it is used): " << reason);
    std::lock_guard<std::mutex> lock(mutex_);
    ++counter;
    last_refusal_ = reason;
  }

  /// The adapter on /diagnostics: ERROR when every message since the last report was refused,
  /// WARN when some were or none arrived.
  std::vector<diagnostic_msgs::DiagnosticStatus> health(double since_s) {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::uint64_t refused = refused_frames_ + refused_mount_ + refused_values_;
    const std::uint64_t new_refusals = refused - refused_reported_;
    Health h("OdometryAdapter " + getName(), frames_.child_frame_id);
    h.error(new_refusals > 0 && published_since_report_ == 0, "every odometry refused: " + last_refusal_)
        .warn(new_refusals > 0, std::to_string(new_refusals) + " odometry message(s) refused: " + last_refusal_)
        .warn(new_refusals == 0 && published_since_report_ == 0, "no odometry on odometry_in")
        .value("published_per_s", published_since_report_ / since_s)
        .value("refused_frames", refused_frames_)
        .value("refused_mount", refused_mount_)
        .value("refused_values", refused_values_)
        .value("last_age_s", last_stamp_.isZero() ? -1.0 : (ros::Time::now() - last_stamp_).toSec())
        .value("camera_mount", std::string(use_tf_ ? "tf " + camera_frame_ : "fixed"));
    refused_reported_ = refused;
    published_since_report_ = 0;
    return {h.status()};
  }

  std::mutex mutex_;  ///< guards the counters (the callbacks run on the manager's threads)
  onboard::OdometryFrames frames_;
  onboard::CameraMount mount_;
  bool use_tf_ = false;
  std::string camera_frame_;
  double tf_timeout_s_ = 0.0;
  int published_since_report_ = 0;
  std::uint64_t refused_frames_ = 0, refused_mount_ = 0, refused_values_ = 0, refused_reported_ = 0;
  std::string last_refusal_;
  ros::Time last_stamp_;
  DiagnosticsPublisher diagnostics_;
  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  ros::Publisher odom_pub_;
  ros::Subscriber odom_sub_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::OdometryAdapterNodelet, nodelet::Nodelet)

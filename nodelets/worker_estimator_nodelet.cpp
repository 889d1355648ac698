// WorkerEstimator nodelet: WorkerDetection (+ UWB range, + tf of the camera optical frame)
// → WorkerState. A thin adapter over estimation::HumanKalman (docs/estimation.md).
//
// Topics: detection_in (gesture_formation/WorkerDetection), uwb_in (sensor_msgs/Range),
//         camera_info_in (sensor_msgs/CameraInfo of the camera the detections come from),
//         worker_state_out (gesture_formation/WorkerState).
// Parameters (all required, listed at once when missing): ~config_file (estimator YAML, every
// key required), ~world_frame, ~uwb_max_age_s, ~tf_timeout_s, ~publish_rate_hz; optional
// ~intrinsics_source: camera_info (default: the camera model from camera_info_in, detections
// refused until it has arrived) or config (the YAML's camera section, an explicit override);
// estimation::CameraModelSource.
// Leader hand-over (optional ~leadership, default false; docs/safety.md §1.2): the estimator runs on
// every UAV and follows this UAV's leadership_state_in (LeadershipState). While the UAV does not act
// it ignores its detections and hands on the acting leader's estimate (shared_state_in, from the
// LcmBridge) as worker_state_out; starting to act it takes the last shared estimate over
// (HumanKalman::adopt: position, velocity, position covariance, last fusion) and fuses its own
// camera from there, publishing on worker_state_out and on share_out (to the LcmBridge) — as
// gfctl simulate's new leader does. Through a lapse of its lease in the term it acted in (frequent
// on a lossy link) it keeps its filter and fuses on, publishing to its own planner only (no share
// while the lease is out, as in gfctl simulate); only a new term of its own starts from the share.
#include <algorithm>
#include <mutex>
#include <optional>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <ros/ros.h>
#include <sensor_msgs/Range.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "conversions.hpp"
#include "diagnostics.hpp"
#include "gesture_formation/estimation/camera_model_source.hpp"
#include "gesture_formation/LeadershipState.h"
#include "gesture_formation/estimation/estimator_config.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class WorkerEstimatorNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ros::NodeHandle& pnh = getPrivateNodeHandle();
    ParamLoader params(pnh);
    std::string config_file;
    params.load("config_file", config_file);
    params.load("world_frame", world_frame_);
    params.load("uwb_max_age_s", uwb_max_age_s_, 0.0, 10.0);
    params.load("tf_timeout_s", tf_timeout_s_, 0.0, 1.0);
    double rate_hz = 0.0;
    params.load("publish_rate_hz", rate_hz, 0.1, 200.0);
    params.loadOptional("leadership", leadership_, false);  // optional (see the file comment); not a bool: refused
    std::string source_name;
    params.loadOptional("intrinsics_source", source_name, "camera_info");
    const auto source = estimation::parseIntrinsicsSource(source_name);
    if (!source) params.addError("intrinsics_source: " + source.reason());
    if (!config_file.empty()) {
      std::vector<std::string> unknown;
      const auto cfg = estimation::loadEstimatorConfig(config_file, common::ConfigReader::MissingKeys::kError, &unknown);
      refuseUnknown("estimator_config", unknown, params);
      if (cfg) {
        config_ = *cfg;
      } else {
        params.addErrors({cfg.reason()});
      }
    }
    if (!params.ok()) {
      NODELET_ERROR_STREAM("WorkerEstimator refuses to start; fix these parameters:\n" << params.report());
      return;  // stays uninitialised: no subscriptions, no output
    }
    NODELET_INFO_STREAM("WorkerEstimator loaded:\n" << params.loaded());
    camera_.emplace(*source, config_.camera);
    filter_ = estimation::HumanKalman(config_.filter);
    info_sub_ = nh.subscribe<sensor_msgs::CameraInfo>("camera_info_in", 2, [this](const sensor_msgs::CameraInfo::ConstPtr& m) {
      auto k = toIntrinsics(*m);
      std::lock_guard<std::mutex> lock(mutex_);
      const auto changed = k ? camera_->receive(*k) : common::Result<bool>::fail(k.reason());
      if (!changed) NODELET_WARN_STREAM_THROTTLE(5.0, "WorkerEstimator: camera_info_in not used: " << changed.reason());
      else if (*changed) NODELET_INFO_STREAM("WorkerEstimator: camera model from CameraInfo (" << m->header.frame_id << ")");
    });
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(tf_buffer_);
    state_pub_ = nh.advertise<gesture_formation::WorkerState>("worker_state_out", 10);
    detection_sub_ = nh.subscribe("detection_in", 10, &WorkerEstimatorNodelet::onDetection, this);
    uwb_sub_ = nh.subscribe("uwb_in", 10, &WorkerEstimatorNodelet::onUwb, this);
    timer_ = nh.createTimer(ros::Duration(1.0 / rate_hz), &WorkerEstimatorNodelet::onTimer, this);
    if (leadership_) {
      share_pub_ = nh.advertise<gesture_formation::WorkerState>("share_out", 10);
      shared_sub_ = nh.subscribe("shared_state_in", 10, &WorkerEstimatorNodelet::onShared, this);
      leadership_sub_ = nh.subscribe("leadership_state_in", 5, &WorkerEstimatorNodelet::onLeadership, this);
    }
    diagnostics_.start(nh, 1.0, [this](double since_s) { return health(since_s); });
  }

  /// The estimator on /diagnostics: WARN before the first track, while the worker is lost, when
  /// detections were rejected since the last report; values: rates and the ages that decide hold.
  std::vector<diagnostic_msgs::DiagnosticStatus> health(double since_s) {
    std::lock_guard<std::mutex> lock(mutex_);
    const double t = ros::Time::now().toSec();
    const double fused_age_s = last_fused_.isZero() ? -1.0 : t - last_fused_.toSec();
    const double uwb_age_s = last_uwb_stamp_.isZero() ? -1.0 : t - last_uwb_stamp_.toSec();
    const bool lost = filter_.confirmed() && filter_.lost(t);
    Health h("WorkerEstimator", "leader");
    if (!estimates()) {  // ~leadership, not acting: hands on the leader's estimate
      h.value("acting", 0).value("relayed_per_s", published_since_report_ / since_s);
      fused_since_report_ = rejected_since_report_ = published_since_report_ = 0;
      return {h.status()};
    }
    h.warn(!camera_->model(), camera_->refusal())
        .warn(!filter_.confirmed(), "no confirmed track of the worker")
        .warn(lost, "worker lost (no measurement fused for " + std::to_string(fused_age_s) + " s)")
        .warn(rejected_since_report_ > 0, std::to_string(rejected_since_report_) + " detection(s) rejected")
        .value("confirmed", filter_.confirmed() ? 1 : 0)
        .value("lost", lost ? 1 : 0)
        .value("fused_per_s", fused_since_report_ / since_s)
        .value("rejected", rejected_since_report_)
        .value("last_fused_age_s", fused_age_s)
        .value("last_uwb_age_s", uwb_age_s)
        .value("published_per_s", published_since_report_ / since_s);
    fused_since_report_ = rejected_since_report_ = published_since_report_ = 0;
    return {h.status()};
  }

  /// ~leadership: the estimate is this UAV's own only while it acts as leader.
  bool estimates() const { return !leadership_ || owns_; }
  void publish(const gesture_formation::WorkerState& out) {
    state_pub_.publish(out);
    if (leadership_) last_own_ = out;
    if (leadership_ && acting_) share_pub_.publish(out);
    ++published_since_report_;
  }

  // The acting leader's estimate over LCM: handed on while this UAV does not act, kept for a take-over.
  void onShared(const gesture_formation::WorkerState::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (owns_) return;
    // The newest by stamp (the link may deliver an older one late): handed on and kept, as gfctl simulate.
    if (last_share_ && msg->header.stamp <= last_share_->header.stamp) return;
    last_share_ = *msg;
    state_pub_.publish(*msg);
    ++published_since_report_;
  }

  // This UAV's leadership view: starting to act, the estimator continues from the last share.
  void onLeadership(const gesture_formation::LeadershipState::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    acting_ = msg->acting;
    // Its own filter while it acts and through a lapse of its lease in the term it acted in.
    const bool owns = msg->acting || (msg->role == gesture_formation::LeadershipState::ROLE_LEADER && msg->term == acted_term_);
    if (msg->acting) acted_term_ = msg->term;
    if (owns == owns_) return;
    owns_ = owns;
    // No longer its own: its last estimate is the newest it knows until the next leader shares one
    // (re-elected before any share arrives, it continues from its own, not a predecessor's older one).
    if (!owns_ && last_own_ && (!last_share_ || last_own_->header.stamp > last_share_->header.stamp)) last_share_ = last_own_;
    last_own_.reset();
    filter_ = estimation::HumanKalman(config_.filter);
    last_fused_ = ros::Time();
    if (!owns_ || !last_share_) {
      NODELET_WARN_STREAM("WorkerEstimator: " << (owns_ ? "acts as leader with no shared estimate: starts from its own detections"
                                                         : "no longer the leader of its term: hands on the leader's estimate"));
      return;
    }
    const auto& w = *last_share_;
    const double t = w.header.stamp.toSec(), fused = std::min(w.last_fused.toSec(), t);
    // Only the diagonal crosses the link (its correlations are lost): each variance at least
    // 1 m² — gfctl simulate's take-over starts from 1 m per axis (docs/safety.md §1.2).
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (int r = 0; r < 3; ++r) cov(r, r) = std::max(1.0, w.covariance[static_cast<std::size_t>(r * 6 + r)]);
    const bool adopted = filter_.adopt(t, toEigen(w.position), w.lost ? Eigen::Vector3d::Zero() : toEigen(w.velocity), cov, fused);
    if (adopted) last_fused_ = ros::Time(fused);
    NODELET_WARN_STREAM("WorkerEstimator: acts as leader (term " << msg->term << "): "
                        << (adopted ? "continues from the shared estimate of t = " + std::to_string(t) + " s"
                                    : std::string("the shared estimate was not usable: starts from its own detections")));
  }

  void onUwb(const sensor_msgs::Range::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    const bool valid = std::isfinite(msg->range) && msg->range >= msg->min_range && msg->range <= msg->max_range;
    last_uwb_m_ = valid ? msg->range : std::nan("");
    last_uwb_stamp_ = msg->header.stamp;
  }

  void onDetection(const gesture_formation::WorkerDetection::ConstPtr& msg) {
    if (!msg->detected) return;
    geometry_msgs::TransformStamped T_world_camera;
    try {
      T_world_camera = tf_buffer_.lookupTransform(world_frame_, msg->header.frame_id, msg->header.stamp,
                                                  ros::Duration(tf_timeout_s_));
    } catch (const tf2::TransformException& e) {
      NODELET_WARN_STREAM_THROTTLE(1.0, "WorkerEstimator: no camera pose for the detection: " << e.what());
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    if (!estimates()) return;
    const double t = msg->header.stamp.toSec();
    const double uwb_age_s = std::abs((msg->header.stamp - last_uwb_stamp_).toSec());
    const double d_uwb = uwb_age_s <= uwb_max_age_s_ ? last_uwb_m_ : std::nan("");
    if (!camera_->model()) {
      ++rejected_since_report_;
      NODELET_WARN_STREAM_THROTTLE(1.0, "WorkerEstimator: detection refused: " << camera_->refusal());
      return;
    }
    const auto m = estimation::makeMeasurement(*camera_->model(), toCameraPose(T_world_camera), toBox(*msg), d_uwb,
                                               msg->stereo_distance_m, config_.human_height_m, config_.noise,
                                               config_.max_apparent_distance_m);
    if (!m) {
      ++rejected_since_report_;
      NODELET_WARN_STREAM_THROTTLE(1.0, "WorkerEstimator: detection rejected: " << m.reason());
      return;
    }
    const auto outcome = filter_.step(t, *m);
    if (estimation::accepted(outcome)) {
      last_fused_ = msg->header.stamp;
      ++fused_since_report_;
    } else {
      ++rejected_since_report_;
    }
    if (!filter_.confirmed()) return;  // a tentative track is not published (docs/estimation.md)
    auto out = toWorkerState(filter_.state(), filter_.covariance());
    out.header.stamp = ros::Time(filter_.time());
    out.header.frame_id = world_frame_;
    out.source = estimation::toString(m->source);
    out.accepted = estimation::accepted(outcome);
    out.lost = filter_.lost(t);
    out.predicted = false;
    out.last_fused = last_fused_;
    publish(out);
  }

  void onTimer(const ros::TimerEvent& event) {
    std::lock_guard<std::mutex> lock(mutex_);
    const double t = event.current_real.toSec();
    // ROS time went back (sim time restarted, a bag replayed in a loop): the track is of another
    // time line — every new detection would be refused as out of order while the old track, its
    // stamps now in the future, kept being published as fresh. Start afresh.
    // A tentative track too (its stamps would refuse every new detection), and a follower's kept
    // share (every newer share would be refused as older than it: nothing handed on, no take-over).
    if (filter_.initialized() && t < filter_.time() - kTimeJumpS) {
      NODELET_WARN_STREAM("WorkerEstimator: ROS time went back from " << filter_.time() << " s to " << t
                                                                      << " s: the track is dropped, starting afresh");
      filter_ = estimation::HumanKalman(config_.filter);
      last_fused_ = ros::Time();
      last_uwb_stamp_ = ros::Time();
      last_share_.reset();
      last_own_.reset();
      return;
    }
    if (last_share_ && t < last_share_->header.stamp.toSec() - kTimeJumpS) {
      NODELET_WARN_STREAM("WorkerEstimator: ROS time went back from " << last_share_->header.stamp.toSec() << " s to " << t
                                                                      << " s: the kept shared estimate is dropped");
      last_share_.reset();
    }
    if (!estimates() || !filter_.confirmed()) return;
    const auto [x, P] = filter_.predictedState(t);  // one prediction: a consistent 6x6 covariance
    auto out = toWorkerState(x, P);
    out.header.stamp = event.current_real;
    out.header.frame_id = world_frame_;
    out.source = "none";
    out.accepted = false;
    out.lost = filter_.lost(t);
    out.predicted = true;
    out.last_fused = last_fused_;
    publish(out);
  }

  std::mutex mutex_;
  DiagnosticsPublisher diagnostics_;
  int fused_since_report_ = 0, rejected_since_report_ = 0, published_since_report_ = 0;
  estimation::EstimatorConfig config_;
  std::optional<estimation::CameraModelSource> camera_;  ///< from CameraInfo, or the config (override)
  estimation::HumanKalman filter_;
  std::string world_frame_;
  double uwb_max_age_s_ = 0.0;
  double tf_timeout_s_ = 0.0;
  double last_uwb_m_ = std::nan("");
  ros::Time last_uwb_stamp_;
  ros::Time last_fused_;  ///< the last accepted measurement's stamp (WorkerState.last_fused)
  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  bool leadership_ = false, acting_ = false;  ///< ~leadership; this UAV acts as leader (its lease holds)
  /// ROS time this far behind the filter's time is a jump back, not a late timer tick [s].
  static constexpr double kTimeJumpS = 1.0;
  bool owns_ = false;                         ///< it keeps its own filter: acting, or lapsed in the term it acted in
  std::uint32_t acted_term_ = 0;              ///< the last term in which it acted
  std::optional<gesture_formation::WorkerState> last_share_;  ///< the acting leader's last estimate (~leadership)
  std::optional<gesture_formation::WorkerState> last_own_;    ///< its own last estimate while it owns the filter
  ros::Publisher state_pub_, share_pub_;
  ros::Subscriber detection_sub_, shared_sub_, leadership_sub_;
  ros::Subscriber uwb_sub_, info_sub_;
  ros::Timer timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::WorkerEstimatorNodelet, nodelet::Nodelet)

// SimUav nodelet: one simulated UAV of the mission (the sim core of `gfctl simulate`:
// sim::Multirotor plant + sim::TrackingController + sim::Odometry, in the same wind field, with
// the same seeds), stepping at the mission's step_s in sim time. It takes the plans of its
// FormationPlanner by the SetpointRelay's rules (onboard::SetpointRelay::accept: an empty,
// broken or older plan is refused and the held one flown on — what flies on hardware) and tracks
// them as gfctl simulate's UAVs do (PlannedTrajectory::sampleAt, the relay's sampling too). Its callbacks run on its
// own thread, not the nodelet manager's workers; odometry and tf carry the state at the clock.
//
// Topics: plan_in (PlannedTrajectory) → odometry_out (nav_msgs/Odometry, the noisy estimate the
//   planner and estimator use; orientation = camera axis, docs/ros.md), ground_truth_out (the
//   true state, for the world's sensors and metrics), wind_estimate_out
//   (geometry_msgs/TwistWithCovarianceStamped, twist.linear = the wind, as mavros
//   `wind_estimation`: sim::WindEstimate, for the planner's wind allowance), tf world → <tf_prefix>/camera_axis and
//   <tf_prefix>/camera_optical (from the estimate, as the onboard camera pose would be).
// Parameters (required): ~mission_file, ~uav_index, ~seed, ~world_frame, ~tf_prefix,
//   ~publish_rate_hz.
#include <mutex>
#include <optional>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <geometry_msgs/TwistWithCovarianceStamped.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include "sim_config_sources.hpp"
#include "sim_conversions.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/formation/worker_heading.hpp"
#include "gesture_formation/onboard/setpoint_relay.hpp"
#include "gesture_formation/sim/multirotor.hpp"
#include "gesture_formation/sim/odometry.hpp"
#include "gesture_formation/sim/random.hpp"
#include "gesture_formation/sim/synthetic_sensors.hpp"
#include "gesture_formation/sim/tracking_controller.hpp"
#include "gesture_formation/sim/wind.hpp"
#include "gesture_formation/sim/worker_model.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class SimUavNodelet : public nodelet::Nodelet {
 public:
  ~SimUavNodelet() override {
    if (spinner_) spinner_->stop();
    step_timer_.stop();
    publish_timer_.stop();
  }

 private:
  void onInit() override {
    // The flight stack's own thread: the plant, its odometry and the camera tf must not wait for the
    // nodelet manager's workers, which the planner and blocking tf lookups (ViewObserver,
    // WorkerEstimator: up to tf_timeout_s) can all hold at once — as a flight controller does not
    // wait for the onboard computer.
    ros::NodeHandle nh(getNodeHandle());
    nh.setCallbackQueue(&queue_);
    ParamLoader params(getPrivateNodeHandle());
    std::string mission_file;
    int seed = 0;
    double rate_hz = 0.0;
    params.load("mission_file", mission_file);
    params.load("uav_index", index_, 0, comm::kMaxUavIndex);
    params.load("seed", seed, 0, 1 << 30);
    params.load("world_frame", world_frame_);
    params.load("tf_prefix", tf_prefix_);
    params.load("publish_rate_hz", rate_hz, 1.0, 500.0);
    sim::MissionConfig cfg;
    if (!mission_file.empty() && loadMission(mission_file, params, cfg) &&
        index_ >= static_cast<int>(cfg.uavs.size())) {
      params.addError("uav_index: " + std::to_string(index_) + " but the mission has " + std::to_string(cfg.uavs.size()) + " UAVs");
    }
    if (!params.ok()) {
      NODELET_ERROR_STREAM("SimUav refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("SimUav loaded:\n" << params.loaded());
    const auto s = static_cast<std::uint64_t>(seed);
    // Initial state: the formation reference around the worker's start (as gfctl simulate).
    const sim::WorkerModel worker(cfg.worker, sim::mixSeed(s ^ static_cast<std::uint64_t>(sim::Stream::kWorker)));
    const sim::WorkerState w0 = worker.stateAt(0.0);
    const double hphi0 = formation::WorkerHeading(cfg.formation.worker_heading).heading();
    const auto& fp = cfg.formation.params;
    const formation::UavReference lref = formation::leaderReference(w0.p_world, hphi0, fp.leader);
    const formation::UavReference ref =
        index_ == 0 ? lref
                    : formation::followerReference(w0.p_world, lref.heading_rad, lref.pitch_rad,
                                                   fp.followers[static_cast<std::size_t>(index_ - 1)]);
    const sim::UavConfig& ucfg = cfg.uavs[static_cast<std::size_t>(index_)];
    sim::MultirotorState s0;
    s0.p_world = ucfg.initial_position.value_or(ref.p_world);
    s0.heading_rad = ref.heading_rad;
    s0.pitch_rad = ref.pitch_rad;
    step_s_ = cfg.step_s;
    ground_m_ = -1e9;  // the scenario's ground plane is applied by the plant when enabled
    auto sc = planning::loadScenario(mission_file);
    if (sc && sc->ground.enabled) ground_m_ = sc->ground.height_m;
    plant_.emplace(ucfg.plant, s0);
    ctl_.emplace(cfg.controller, ucfg.plant);
    odo_.emplace(cfg.odometry, sim::makeRng(s, sim::Stream::kOdometry, static_cast<std::uint64_t>(index_)));
    wind_.emplace(cfg.wind, sim::makeRng(s, sim::Stream::kWind));  // one field: same stream in every UAV
    est_ = odo_->measure(plant_->state(), 0.0);

    odom_pub_ = nh.advertise<nav_msgs::Odometry>("odometry_out", 10);
    truth_pub_ = nh.advertise<nav_msgs::Odometry>("ground_truth_out", 10);
    wind_pub_ = nh.advertise<geometry_msgs::TwistWithCovarianceStamped>("wind_estimate_out", 10);
    plan_sub_ = nh.subscribe("plan_in", 5, &SimUavNodelet::onPlan, this);
    step_timer_ = nh.createTimer(ros::Duration(step_s_), &SimUavNodelet::onStep, this);
    publish_timer_ = nh.createTimer(ros::Duration(1.0 / rate_hz), &SimUavNodelet::onPublish, this);
    spinner_.emplace(1, &queue_);
    spinner_->start();
  }

  void onPlan(const gesture_formation::PlannedTrajectory::ConstPtr& msg) {
    auto plan = fromMsg(*msg);
    std::lock_guard<std::mutex> lock(mutex_);
    const std::optional<std::string> refusal =
        plan ? relay_.accept(*plan, ros::Time::now().toSec()) : std::optional<std::string>(plan.reason());
    if (refusal) {
      NODELET_ERROR_STREAM_THROTTLE(2.0, "SimUav: plan refused (the held plan is flown on): " << *refusal);
      return;
    }
    ctl_->setPlan(*plan);
  }

  void onStep(const ros::TimerEvent&) {
    std::lock_guard<std::mutex> lock(mutex_);
    advanceTo(ros::Time::now().toSec());
  }

  /// Steps the plant up to `now` (caller holds mutex_).
  void advanceTo(double now) {
    if (t_ < 0.0) t_ = now;
    // Catch up in fixed steps (the clock may advance by more than one step between calls).
    for (int n = 0; t_ + step_s_ <= now + 1e-9 && n < 1000; ++n) {
      est_ = odo_->measure(plant_->state(), step_s_);
      const Eigen::Vector3d w = wind_->step(t_, step_s_);
      const sim::MultirotorCommand cmd = ctl_->update(t_, step_s_, est_);
      plant_->step(step_s_, cmd, w, ground_m_);
      wind_estimate_.update(w, step_s_);
      t_ += step_s_;
    }
  }

  nav_msgs::Odometry odometry(const ros::Time& stamp, const Eigen::Vector3d& p, const Eigen::Vector3d& v,
                              double heading, double pitch) const {
    nav_msgs::Odometry o;
    o.header.stamp = stamp;
    o.header.frame_id = world_frame_;
    o.child_frame_id = world_frame_;  // twist in the world frame
    o.pose.pose.position = toPoint(p);
    o.pose.pose.orientation = cameraAxisOrientation(heading, pitch);
    o.twist.twist.linear = toVector3(v);
    return o;
  }

  void onPublish(const ros::TimerEvent&) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (t_ < 0.0) return;
    advanceTo(ros::Time::now().toSec());  // the state at the clock, not at the last step timer's call
    const ros::Time stamp(t_);
    const auto& s = plant_->state();
    odom_pub_.publish(odometry(stamp, est_.p_world, est_.v_world, est_.heading_rad, est_.pitch_rad));
    truth_pub_.publish(odometry(stamp, s.p_world, s.v_world, s.heading_rad, s.pitch_rad));
    if (wind_estimate_.value().allFinite()) {
      geometry_msgs::TwistWithCovarianceStamped wind;
      wind.header.stamp = stamp;
      wind.header.frame_id = world_frame_;
      wind.twist.twist.linear = toVector3(wind_estimate_.value());
      wind_pub_.publish(wind);
    }
    geometry_msgs::TransformStamped axis;
    axis.header.stamp = stamp;
    axis.header.frame_id = world_frame_;
    axis.child_frame_id = tf_prefix_ + "/camera_axis";
    axis.transform.translation = toVector3(est_.p_world);
    axis.transform.rotation = cameraAxisOrientation(est_.heading_rad, est_.pitch_rad);
    const estimation::CameraPose cam = sim::cameraPose(est_.p_world, est_.heading_rad, est_.pitch_rad);
    geometry_msgs::TransformStamped optical;
    optical.header = axis.header;
    optical.child_frame_id = tf_prefix_ + "/camera_optical";
    optical.transform.translation = toVector3(cam.t_world_camera);
    optical.transform.rotation.w = cam.q_world_camera.w();
    optical.transform.rotation.x = cam.q_world_camera.x();
    optical.transform.rotation.y = cam.q_world_camera.y();
    optical.transform.rotation.z = cam.q_world_camera.z();
    tf_.sendTransform(std::vector<geometry_msgs::TransformStamped>{axis, optical});
  }

  std::mutex mutex_;
  int index_ = 0;
  std::string world_frame_, tf_prefix_;
  double step_s_ = 0.01, ground_m_ = 0.0, t_ = -1.0;
  std::optional<sim::Multirotor> plant_;
  std::optional<sim::TrackingController> ctl_;
  onboard::SetpointRelay relay_;  ///< the hardware relay's acceptance rules for the plans flown
  std::optional<sim::Odometry> odo_;
  std::optional<sim::WindModel> wind_;
  sim::WindEstimate wind_estimate_;
  sim::EstimatedState est_;
  tf2_ros::TransformBroadcaster tf_;
  ros::Publisher odom_pub_, truth_pub_, wind_pub_;
  ros::CallbackQueue queue_;  ///< served by spinner_ (declared before what it serves, destroyed after)
  ros::Subscriber plan_sub_;
  ros::Timer step_timer_, publish_timer_;
  std::optional<ros::AsyncSpinner> spinner_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::SimUavNodelet, nodelet::Nodelet)

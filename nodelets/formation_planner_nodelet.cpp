// FormationPlanner nodelet: one UAV's replanning at a fixed period, staggered by UAV index — a thin
// adapter around planning::ReplanStep, the step gfctl simulate's UAVs run (docs/planning.md "The
// replanning step"): freshness and hold / search (docs/safety.md §1), listening before moving
// (§2.4), the stage-1 reference on the worker's prediction, the request around the other UAVs'
// received plans (planning::buildPlanRequest) and the verified plan or its fallback (flagged
// `fallback`: every other UAV plans around it). The leader's instance owns the formation's parameters
// (onboard::ParamsOwnership in planner_params_role.hpp; commands in on formation_command_in, parameters out on
// formation_params_out; a leader whose lease lapsed applies the commands kept meanwhile if it resumes in its term).
// With ~leadership true (optional, default false) the role, the slot flown and whose plan is the leader's
// follow this UAV's own leadership_state_in (LeadershipState; docs/safety.md §1.2). With ~mapping_config
// it plans on a live map of its depth camera (planner_live_map.hpp: depth_in, depth_info_in).
//
// Topics (docs/ros.md "FormationPlanner"): odometry_in (nav_msgs/Odometry, orientation = camera axis),
//   worker_state_in (WorkerState), plans_in (PlannedTrajectory of other UAVs), formation_params_in,
//   formation_command_in, wind_estimate_in (TwistWithCovarianceStamped, optional, safety.md §4.7),
//   abort_in (AbortCommand: every copy), assistance_in → plan_out (PlannedTrajectory: mode track | hold
//   | search | abort and its reason), trajectory_out (MultiDOFJointTrajectory), formation_params_out
//   (latched), abort_state_out (latched, §2.8), command_ack_out (§2.9), assistance_state_out (§2.10).
// Parameters (all required unless noted): ~uav_index, ~uav_count, ~world_frame, ~scenario_file (the
//   map), ~params_rate_hz, ~max_wind_estimate_age_s, loadPlannerSettings' (config_sources.hpp:
//   ~mission_file, or ~replanning_period_s, ~horizon_*, ~max_*_age_s, ~avoid_all_plans, ~brake_accel_mps2,
//   ~search_*, ~abort, ~formation_config, ~planner_config) and the live map's (~mapping_*).
#include <cmath>
#include <mutex>
#include <optional>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <geometry_msgs/TwistWithCovarianceStamped.h>
#include <ros/ros.h>

#include "config_sources.hpp"
#include "conversions.hpp"
#include "diagnostics.hpp"
#include "planner_health.hpp"
#include "planner_live_map.hpp"
#include "planner_params_role.hpp"
#include "gesture_formation/onboard/frame_check.hpp"
#include "gesture_formation/onboard/odometry_adapter.hpp"
#include "gesture_formation/onboard/wind_input.hpp"
#include "gesture_formation/planning/replan_health.hpp"
#include "gesture_formation/planning/replan_step.hpp"
#include "param_loader.hpp"

namespace gesture_formation::nodelets {

class FormationPlannerNodelet : public nodelet::Nodelet {
 private:
  void onInit() override {
    ros::NodeHandle& nh = getNodeHandle();
    ParamLoader params(getPrivateNodeHandle());
    params.load("uav_index", uav_index_, 0, comm::kMaxUavIndex);
    params.load("uav_count", uav_count_, 1, comm::kMaxUavIndex + 1);
    params.load("world_frame", world_frame_);
    std::string scenario_file, mission_file;
    params.load("scenario_file", scenario_file);
    params.loadOptional("mission_file", mission_file, "");
    double max_wind_age_s = 0.0;
    params.load("max_wind_estimate_age_s", max_wind_age_s, 0.1, 60.0);
    wind_ = onboard::WindInput(max_wind_age_s);
    double params_rate_hz = 0.0;
    params.load("params_rate_hz", params_rate_hz, 0.1, 50.0);
    params.load("max_odometry_age_s", max_odometry_age_s_, 0.01, 10.0);
    params.loadOptional("leadership", leadership_, false);  // optional (see the file comment); not a bool: refused
    PlannerSettings settings;  // from ~mission_file (simulation) or the parameters (config_sources.hpp)
    loadPlannerSettings(getPrivateNodeHandle(), params, mission_file, settings);
    const formation::FormationConfig& fcfg = settings.formation;
    planning::ReplanConfig& rc = settings.replan;
    period_s_ = settings.replanning_period_s;
    // Every source is checked before refusing (cross-field checks whenever both fields loaded).
    if (settings.formation_loaded && fcfg.params.uavCount() != uav_count_) {
      params.addError("uav_count: " + std::to_string(uav_count_) + " but the formation config has " + std::to_string(fcfg.params.uavCount()) + " UAVs");
    }
    if (uav_index_ >= uav_count_) params.addError("uav_index: must be < uav_count");
    loadWorldMap(scenario_file, params, world_);
    live_map_.setUp(nh, getPrivateNodeHandle(), params, world_, world_frame_, uav_index_);  // ~mapping_config: planner_live_map.hpp
    if (!params.ok()) {
      NODELET_ERROR_STREAM("FormationPlanner refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("FormationPlanner (UAV " << uav_index_ << ") loaded:\n" << params.loaded());
    rc.uav_index = uav_index_;
    rc.uav_count = uav_count_;
    rc.worker_heading = fcfg.worker_heading;
    rc.formation_limits = fcfg.limits;
    planner_config_ = settings.planner;
    step_ = std::make_unique<planning::ReplanStep>(rc, makePlanner(), retreatSpace(world_));
    received_.resize(static_cast<std::size_t>(uav_count_));
    plan_pub_ = nh.advertise<gesture_formation::PlannedTrajectory>("plan_out", 5);
    traj_pub_ = nh.advertise<trajectory_msgs::MultiDOFJointTrajectory>("trajectory_out", 5);
    odom_sub_ = nh.subscribe("odometry_in", 5, &FormationPlannerNodelet::onOdometry, this);
    worker_sub_ = nh.subscribe("worker_state_in", 5, &FormationPlannerNodelet::onWorker, this);
    plans_sub_ = nh.subscribe("plans_in", 20, &FormationPlannerNodelet::onPlan, this);
    wind_sub_ = nh.subscribe("wind_estimate_in", 5, &FormationPlannerNodelet::onWind, this);
    abort_sub_ = nh.subscribe("abort_in", 20, &FormationPlannerNodelet::onAbort, this);
    abort_pub_ = nh.advertise<gesture_formation::AbortState>("abort_state_out", 5, true);
    abort_pub_.publish(toAbortState(step_->abort(), uav_index_, ros::Time::now().toSec(), "", -1, world_frame_));
    params_role_.setUp(nh, getPrivateNodeHandle(), mutex_, fcfg, uav_index_, leadership_, params_rate_hz, settings.max_command_age_s, world_frame_);
    // Staggered replanning: UAV i plans at k·period + i·period/n (as in gfctl simulate).
    offset_s_ = period_s_ * uav_index_ / uav_count_;
    timer_ = nh.createTimer(ros::Duration(period_s_ / 8.0), &FormationPlannerNodelet::onTimer, this);
    diagnostics_.start(nh, 1.0, [this](double since_s) { return health(since_s); });
  }

  void onOdometry(const nav_msgs::Odometry::ConstPtr& msg) {
    if (auto e = onboard::checkOdometryFrames("odometry_in", onboard::plannerOdometryFrames(world_frame_),
                                              msg->header.frame_id, msg->child_frame_id)) {
      NODELET_ERROR_STREAM_THROTTLE(2.0, "FormationPlanner: odometry refused (nothing from it is used): " << *e);
      return;
    }
    const planning::UavKinematicState state = toKinematicState(*msg);
    if (!state.p_world.allFinite() || !state.v_world.allFinite() || !std::isfinite(state.heading_rad) ||
        !std::isfinite(state.pitch_rad)) {
      // Nothing from it is used: the last good odometry ages out (max_odometry_age_s) and the relay
      // flies the last verified plan to its end and holds, as with no odometry at all.
      NODELET_ERROR_STREAM_THROTTLE(2.0, "FormationPlanner UAV " << uav_index_ << ": odometry with a non-finite position, velocity or orientation refused");
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    odom_ = state;
    odom_stamp_s_ = msg->header.stamp.toSec();
  }
  void onWind(const geometry_msgs::TwistWithCovarianceStamped::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    const std::string why = wind_.receive(msg->header.frame_id, world_frame_, toEigen(msg->twist.twist.linear), msg->header.stamp.toSec());
    if (why.empty()) return;
    NODELET_WARN_STREAM_THROTTLE(2.0, "FormationPlanner: wind estimate rejected (" << why << "); " << wind_.rejected()
                                                                               << " rejected so far");
  }
  void onWorker(const gesture_formation::WorkerState::ConstPtr& msg) {
    // A non-finite estimate (a diverged filter) is no worker knowledge: every distance to it would
    // be NaN, which the reach and the verifier's comparisons would read as "far".
    if (!toEigen(msg->position).allFinite() || !toEigen(msg->velocity).allFinite()) {
      NODELET_ERROR_STREAM_THROTTLE(1.0, "FormationPlanner UAV " << uav_index_ << ": worker state with a non-finite position or velocity dropped");
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    worker_ = *msg;
  }
  void onPlan(const gesture_formation::PlannedTrajectory::ConstPtr& msg) {
    if (msg->uav_index == uav_index_ || msg->uav_index < 0 || msg->uav_index >= uav_count_) return;
    auto plan = fromMsg(*msg);
    if (!plan) {
      NODELET_WARN_STREAM_THROTTLE(1.0, "FormationPlanner: plan dropped: " << plan.reason());
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    auto& slot = received_[static_cast<std::size_t>(msg->uav_index)];
    if (!slot || plan->t0_s >= slot->plan.t0_s) slot = planning::ReceivedPlan{std::move(*plan), msg->fallback != 0};
  }
  // Every copy of an abort (operator over LCM, the other UAVs' relay, the gesture commander): the
  // ReplanStep accepts the first that is fresh enough (planning::AbortPlanner::receive).
  void onAbort(const gesture_formation::AbortCommand::ConstPtr& msg) {
    auto c = fromMsg(*msg);
    std::lock_guard<std::mutex> lock(mutex_);
    const double t = ros::Time::now().toSec();
    if (t <= 0.0) return;  // no ROS time yet (sim time before the first /clock): the copies are repeated
    const auto a = c ? step_->receiveAbort(*c, t) : planning::AbortAcceptance::kStale;
    if (a == planning::AbortAcceptance::kAlreadyAborting) return;
    if (a != planning::AbortAcceptance::kAccepted) {
      NODELET_WARN_STREAM_THROTTLE(1.0, "FormationPlanner UAV " << uav_index_ << ": abort " << msg->sender << "#"
                                        << msg->sequence << " refused: "
                                        << (!c ? c.reason()
                                               : a == planning::AbortAcceptance::kFromTheFuture
                                                     ? "sent more than abort.max_command_age_s after now (ROS time went back?)"
                                                     : "older than abort.max_command_age_s"));
      return;
    }
    abort_link_sender_ = msg->link_sender;
    NODELET_WARN_STREAM("FormationPlanner UAV " << uav_index_ << ": abort accepted: " << msg->sender << "#" << msg->sequence << " ("
                        << planning::toString(c->source) << ", via " << (msg->link_sender < 0 ? std::string("ROS") : "LCM sender " + std::to_string(msg->link_sender)) << ")");
    abort_pub_.publish(toAbortState(step_->abort(), uav_index_, t, "accepted", abort_link_sender_, world_frame_));
  }

  void onTimer(const ros::TimerEvent&) {
    std::lock_guard<std::mutex> lock(mutex_);
    const double t = ros::Time::now().toSec();
    if (t <= 0.0) return;
    // ROS time went back (sim time restarted, a bag looped): the schedule starts again from now —
    // else no replanning until the clock caught up with the old schedule.
    if (next_plan_s_ > t + 2.0 * period_s_) {
      NODELET_WARN_STREAM("FormationPlanner UAV " << uav_index_ << ": ROS time went back from " << next_plan_s_ << " s to " << t
                                                  << " s: replanning from now");
      next_plan_s_ = -1.0;
      for (auto& r : received_) r.reset();  // stamped in the old future: each newer plan would be refused as older
      worker_.reset();
      odom_.reset();
      // The replanning step and the planner hold times of the old timeline (listening's start, the
      // hold, the abort's phase, the last verified and brake plans): it restarts as after a reboot
      // — it listens before it moves (a listening hold would otherwise last until the clock caught
      // up) — but keeps an accepted abort.
      // An accepted abort is kept (the senders may have stopped repeating it): taken again on the
      // new timeline, its phase and goals chosen anew.
      const std::optional<planning::AbortCommand> abort = step_->abort().command();
      step_->restart(makePlanner());
      if (abort) {
        planning::AbortCommand again = *abort;
        again.sent_s = t;
        step_->receiveAbort(again, t);
        abort_pub_.publish(toAbortState(step_->abort(), uav_index_, t, "kept across the clock jump", abort_link_sender_, world_frame_));
      }
    }
    if (next_plan_s_ < 0.0) next_plan_s_ = (std::floor(t / period_s_) + 1.0) * period_s_ + offset_s_;
    if (t < next_plan_s_) return;
    next_plan_s_ += period_s_ * std::max(1.0, std::ceil((t - next_plan_s_) / period_s_ + 1e-9));
    replan(t);
  }

  void replan(double t) {
    if (!odom_) return;
    // A plan starts from the UAV's state: from an old one it would be verified from where the UAV
    // was, and the relay would pull the UAV back along a path nobody checked. No new plan then —
    // the relay flies the last verified one to its end and holds, as in a planner outage.
    if (!(t - odom_stamp_s_ <= max_odometry_age_s_)) {
      NODELET_ERROR_STREAM_THROTTLE(1.0, "FormationPlanner UAV " << uav_index_ << ": no replanning: the odometry is "
                                                                 << t - odom_stamp_s_ << " s old (max_odometry_age_s "
                                                                 << max_odometry_age_s_ << ")");
      return;
    }
    const auto map_lock = live_map_.readLock();  // a live map's updates wait for this replanning
    // The replanning step gfctl simulate's UAVs run too (planning::ReplanStep): freshness and
    // hold, listen before moving, the worker's extrapolation, hold / search, the request.
    std::optional<planning::WorkerKnowledge> worker;
    if (worker_) worker = toWorkerKnowledge(*worker_);
    planning::ReplanInputs in;
    in.t_s = t;
    in.state = onboard::carriedTo(*odom_, odom_stamp_s_, t);  // the odometry's stamp is up to max_odometry_age_s earlier
    if (const auto w = wind_.at(t)) in.wind_estimate_mps = *w;
    in.worker = worker ? &*worker : nullptr;
    in.params = &params_role_.own().role().params();
    in.slot = params_role_.own().slot();  // ~leadership: the acting leader flies slot 0 (docs/safety.md §1.2)
    in.leader_index = params_role_.own().leaderIndex();
    if (const auto& l = received_[static_cast<std::size_t>(in.leader_index)]) in.leader_plan = &l->plan;
    in.received = &received_;
    const planning::ReplanOutcome out = step_->step(in);
    if (!out.planned()) return;
    if (!out.note.empty()) NODELET_WARN_STREAM("FormationPlanner UAV " << uav_index_ << ": " << out.note);
    if (out.backoff_started) NODELET_WARN_STREAM("FormationPlanner UAV " << uav_index_ << ": " << out.backoff);
    const std::string mode = planning::toString(out.mode);
    if (out.aborting()) {
      abort_pub_.publish(toAbortState(step_->abort(), uav_index_, t, out.reason, abort_link_sender_, world_frame_));
    }
    if (mode != mode_) {
      if (out.holding() || out.aborting()) NODELET_WARN_STREAM("FormationPlanner UAV " << uav_index_ << ": " << mode << ": " << out.reason);
      else NODELET_INFO_STREAM("FormationPlanner UAV " << uav_index_ << ": track: fresh data");
      mode_ = mode;
    }
    health_.record(out, t);
    logPlanProblems(out.result, uav_index_);
    const auto msg = toMsg(out, uav_index_, t, params_role_.own().role().params(), params_role_.own().version(), world_frame_);
    plan_pub_.publish(msg);
    traj_pub_.publish(toMultiDof(msg, "uav" + std::to_string(uav_index_)));
  }

  /// This UAV's planner on /diagnostics (planning::ReplanHealth).
  std::vector<diagnostic_msgs::DiagnosticStatus> health(double since_s) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto status = plannerHealth(health_.report(ros::Time::now().toSec(), period_s_), uav_index_, since_s);  // ROS (sim) time
    live_map_.report(status, since_s);
    return {status};
  }

  std::mutex mutex_;
  DiagnosticsPublisher diagnostics_;
  planning::ReplanHealth health_;  ///< /diagnostics: plans, fallbacks, the last plan's age
  int uav_index_ = 0, uav_count_ = 0;
  std::string world_frame_;
  double period_s_ = 0.0, offset_s_ = 0.0, next_plan_s_ = -1.0;
  onboard::WindInput wind_;  ///< wind_estimate_in, checked and aged (docs/safety.md §4.7)
  PlannerParamsRole params_role_;  ///< the parameters' role, following the leadership or the index
  bool leadership_ = false;  ///< ~leadership: the parameters' role follows this UAV's leadership_state
  std::string mode_ = "track";             ///< track | hold | search | abort (logged on change)
  WorldMap world_;  ///< the map and field the planner and the abort's goal search use (live: live_map_'s)
  PlannerLiveMap live_map_;  ///< ~mapping_config: the depth camera's live map
  /// A new planner over the world's map (and the live map's seen space).
  std::unique_ptr<planning::Planner> makePlanner() {
    return std::make_unique<planning::UavPlannerAdapter>(
        std::make_unique<planning::UavPlanner>(planner_config_, world_.map, world_.field, live_map_.seen()));
  }

  planning::PlannerConfig planner_config_;
  std::unique_ptr<planning::ReplanStep> step_;  ///< planner, hold / search, listening (shared with gfctl simulate)
  std::optional<planning::UavKinematicState> odom_;
  double odom_stamp_s_ = 0.0;         ///< odom_'s stamp (ROS time)
  double max_odometry_age_s_ = 0.5;   ///< ~max_odometry_age_s: older odometry stops replanning
  std::optional<gesture_formation::WorkerState> worker_;
  std::vector<std::optional<planning::ReceivedPlan>> received_;  ///< by sender (the leader's: params_role_.own().leaderIndex())
  int abort_link_sender_ = -1;  ///< who delivered the accepted abort (LCM sender id; -1: ROS)
  ros::Publisher plan_pub_, traj_pub_, abort_pub_;
  ros::Subscriber odom_sub_, worker_sub_, plans_sub_, wind_sub_, abort_sub_;
  ros::Timer timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::FormationPlannerNodelet, nodelet::Nodelet)

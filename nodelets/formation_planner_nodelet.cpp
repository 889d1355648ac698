// FormationPlanner nodelet: one UAV's replanning (planning::UavPlanner, design.md §4) at a fixed
// period, staggered by UAV index. A thin adapter: stage-1 references from the formation core
// (formation::leaderHorizon / followerHorizon) on the worker's constant-velocity prediction,
// the plans received from the other UAVs, and the planner's verified plan (or its fallback:
// previous plan / brake, flagged `fallback` so that every other UAV plans around it).
// The leader's instance also owns the formation's parameters (formation::FormationState):
// commands arrive on formation_command_in (gestures, operator over LCM) and the parameters go
// out on formation_params_out. The request (reference + the other UAVs' plans to avoid) is
// planning::buildPlanRequest, the same as gfctl simulate's: with avoid_all_plans every UAV plans
// around every other UAV's received plan.
//
// Topics: odometry_in (nav_msgs/Odometry, orientation = camera axis, docs/ros.md),
//   worker_state_in (WorkerState: the leader's estimator, or the leader's share over LCM),
//   plans_in (PlannedTrajectory of other UAVs), formation_params_in (followers),
//   formation_command_in (leader), wind_estimate_in (geometry_msgs/TwistWithCovarianceStamped in
//   world_frame, twist.linear = the wind: mavros `wind_estimation`; optional — without it no
//   wind allowance, docs/safety.md §4.7) → plan_out (PlannedTrajectory), trajectory_out
//   (trajectory_msgs/MultiDOFJointTrajectory), formation_params_out (leader, latched).
// Parameters (all required unless noted): ~uav_index, ~uav_count, ~world_frame,
//   ~scenario_file (the map), ~mission_file (optional: take formation + planner from a
//   scenario's mission) or ~formation_config + ~planner_config, ~replanning_period_s,
//   ~horizon_dt_s, ~horizon_steps, ~max_share_age_s, ~params_rate_hz, ~max_wind_estimate_age_s; without ~mission_file
//   also ~avoid_all_plans, ~max_plan_age_s, ~max_worker_age_s, ~brake_accel_mps2,
//   ~search_timeout_s, ~search_height_m, ~search_vertical_speed_mps, ~search_period_s,
//   ~search_horizontal_speed_mps (with it: the mission's faults.* of the
//   same names and controller.brake_accel_mps2, as gfctl simulate); optional ~faults_file (a fault
//   profile merged into the mission, as `gfctl simulate --faults`).
// Listen before moving (docs/safety.md §2.4, planning::listeningReason — gfctl simulate's rule for a
// rejoining follower): from its first replanning, the planner holds until it has a plan made since
// then from every other follower, or for at most max_plan_age_s.
// Hold (docs/safety.md §1 rules 2–4, planning::holdReason — the decision gfctl simulate makes):
// the leader holds when its estimate's last fused measurement (WorkerState.last_fused) is older
// than max_worker_age_s; a follower when the leader's worker state (over LCM) is older than
// max_share_age_s, or the estimate it carries older than max_worker_age_s. A holding UAV plans
// to its latched braking point (planning::HoldPlanner: camera on the worker estimate, the
// estimator's prediction), avoiding every received plan; its plan is flagged `fallback` (others avoid
// it) with mode `hold` and the reason; the first replanning with fresh data tracks again. The
// leader, holding because it has not seen the worker, searches (mode `search`, for at most
// search_timeout_s): once the estimator has lost him (WorkerState.lost) its camera sweeps up and
// down through the estimate (planning::HoldPlanner, as gfctl simulate).
#include <cmath>
#include <map>
#include <mutex>
#include <optional>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>
#include <geometry_msgs/TwistWithCovarianceStamped.h>
#include <ros/ros.h>

#include "config_sources.hpp"
#include "conversions.hpp"
#include "diagnostics.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/formation/worker_heading.hpp"
#include "gesture_formation/planning/replan_health.hpp"
#include "gesture_formation/planning/replan_step.hpp"
#include "gesture_formation/planning/trajectory_qp.hpp"
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
    std::string scenario_file, mission_file, formation_file, planner_file;
    params.load("scenario_file", scenario_file);
    params.loadOptional("mission_file", mission_file, "");
    params.load("max_wind_estimate_age_s", max_wind_age_s_, 0.1, 60.0);
    double params_rate_hz = 0.0;
    params.load("params_rate_hz", params_rate_hz, 0.1, 50.0);
    formation::FormationConfig fcfg;
    planning::PlannerConfig pcfg;
    planning::ReplanConfig rc;  ///< the replanning step's settings, from either source
    bool formation_loaded = false;
    if (!mission_file.empty()) {
      // Simulation: the mission file's settings — the very values gfctl simulate runs with —
      // win over every parameter; the replanning parameters below are not read.
      onboard::OnboardSettings mission;
      if (loadOnboard(mission_file, params, mission)) {
        formation_loaded = true;
        fcfg = mission.formation;
        pcfg = mission.planner;
        period_s_ = mission.replanning_period_s;
        rc = mission.replan;
        params.note("from mission_file: replanning_period_s " + std::to_string(period_s_) + ", horizon_dt_s " +
                    std::to_string(rc.dt_s) + ", horizon_steps " + std::to_string(rc.steps) +
                    ", faults.* limits, controller.brake_accel_mps2, formation, planner");
      }
    } else {
      params.load("replanning_period_s", period_s_, onboard::ranges::kReplanningPeriodS);
      params.loadFields(planning::replanConfigFields(), rc);  // horizon_*, *_age_s, brake_accel_mps2, search_*
      params.load("avoid_all_plans", rc.rule.avoid_all_plans);
      params.load("formation_config", formation_file);
      params.load("planner_config", planner_file);
      formation_loaded = !formation_file.empty() && loadFormation(formation_file, params, fcfg);
      if (!planner_file.empty()) loadPlanner(planner_file, params, pcfg);
    }
    // Every source is checked before refusing (cross-field checks whenever both fields loaded).
    if (formation_loaded && fcfg.params.uavCount() != uav_count_) {
      params.addError("uav_count: " + std::to_string(uav_count_) + " but the formation config has " +
                      std::to_string(fcfg.params.uavCount()) + " UAVs");
    }
    if (uav_index_ >= uav_count_) params.addError("uav_index: must be < uav_count");
    WorldMap world;
    loadWorldMap(scenario_file, params, world);
    if (!params.ok()) {
      NODELET_ERROR_STREAM("FormationPlanner refuses to start; fix these parameters:\n" << params.report());
      return;
    }
    NODELET_INFO_STREAM("FormationPlanner (UAV " << uav_index_ << ") loaded:\n" << params.loaded());
    params_ = fcfg.params;
    if (uav_index_ == formation::kLeader) {
      auto st = formation::FormationState::create(fcfg.params, fcfg.limits, fcfg.duplicates);
      state_.emplace(std::move(*st));  // the config was validated by its loader
    }
    rc.uav_index = uav_index_;
    rc.worker_heading = fcfg.worker_heading;
    step_ = std::make_unique<planning::ReplanStep>(
        rc, std::make_unique<planning::UavPlannerAdapter>(std::make_unique<planning::UavPlanner>(pcfg, world.map, world.field)));
    received_.resize(static_cast<std::size_t>(uav_count_));

    plan_pub_ = nh.advertise<gesture_formation::PlannedTrajectory>("plan_out", 5);
    traj_pub_ = nh.advertise<trajectory_msgs::MultiDOFJointTrajectory>("trajectory_out", 5);
    odom_sub_ = nh.subscribe("odometry_in", 5, &FormationPlannerNodelet::onOdometry, this);
    worker_sub_ = nh.subscribe("worker_state_in", 5, &FormationPlannerNodelet::onWorker, this);
    plans_sub_ = nh.subscribe("plans_in", 20, &FormationPlannerNodelet::onPlan, this);
    wind_sub_ = nh.subscribe("wind_estimate_in", 5, &FormationPlannerNodelet::onWind, this);
    if (uav_index_ == formation::kLeader) {
      params_pub_ = nh.advertise<gesture_formation::FormationParams>("formation_params_out", 5, true);
      command_sub_ = nh.subscribe("formation_command_in", 20, &FormationPlannerNodelet::onCommand, this);
      params_timer_ = nh.createTimer(ros::Duration(1.0 / params_rate_hz), [this](const ros::TimerEvent&) {
        std::lock_guard<std::mutex> lock(mutex_);
        publishParams();
      });
    } else {
      params_sub_ = nh.subscribe("formation_params_in", 5, &FormationPlannerNodelet::onParams, this);
    }
    // Staggered replanning: UAV i plans at k·period + i·period/n (as in gfctl simulate).
    offset_s_ = period_s_ * uav_index_ / uav_count_;
    timer_ = nh.createTimer(ros::Duration(period_s_ / 8.0), &FormationPlannerNodelet::onTimer, this);
    diagnostics_.start(nh, 1.0, [this](double since_s) { return health(since_s); });
  }

  void onOdometry(const nav_msgs::Odometry::ConstPtr& msg) {
    std::lock_guard<std::mutex> lock(mutex_);
    odom_ = toKinematicState(*msg);
  }
  void onWind(const geometry_msgs::TwistWithCovarianceStamped::ConstPtr& msg) {
    const Eigen::Vector3d w = toEigen(msg->twist.twist.linear);
    std::lock_guard<std::mutex> lock(mutex_);
    if (msg->header.frame_id != world_frame_ || !w.allFinite() || w.norm() > kMaxWindMps) {
      ++wind_rejected_;
      NODELET_WARN_STREAM_THROTTLE(2.0, "FormationPlanner: wind estimate rejected (frame_id '"
                                            << msg->header.frame_id << "', expected '" << world_frame_
                                            << "'; wind " << w.transpose() << " m/s, at most " << kMaxWindMps
                                            << "); " << wind_rejected_ << " rejected so far");
      return;
    }
    wind_ = w;
    wind_stamp_s_ = msg->header.stamp.toSec();
  }
  void onWorker(const gesture_formation::WorkerState::ConstPtr& msg) {
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
  void onParams(const gesture_formation::FormationParams::ConstPtr& msg) {
    auto p = fromMsg(*msg);
    std::lock_guard<std::mutex> lock(mutex_);
    if (!p || p->uavCount() != uav_count_) {
      NODELET_WARN_STREAM_THROTTLE(1.0, "FormationPlanner: formation parameters dropped: "
                                            << (p ? "wrong UAV count" : p.reason()));
      return;
    }
    params_ = *p;
    received_version_ = msg->version;
  }
  void onCommand(const gesture_formation::FormationCommand::ConstPtr& msg) {
    auto cmd = fromMsg(*msg);
    std::lock_guard<std::mutex> lock(mutex_);
    last_command_ = msg->source + " " + msg->sender + "#" + std::to_string(msg->sequence) + ": " + msg->target +
                    "." + msg->parameter + (msg->kind == "set" ? " = " : " += ") + std::to_string(msg->amount);
    last_source_ = msg->source;
    last_stamp_ = msg->header.stamp;
    last_uavs_.clear();
    if (!cmd) {
      last_outcome_ = "rejected: " + cmd.reason();
      last_status_ = formation::toString(formation::CommandStatus::kRejected);
    } else {
      const auto out = state_->apply(*cmd);
      last_outcome_ = out.describe();
      last_status_ = formation::toString(out.status);
      if (out.status == formation::CommandStatus::kApplied) {
        ++version_;
        params_ = state_->params();
        for (const auto& c : out.changes) last_uavs_.push_back(c.uav);
      }
    }
    NODELET_INFO_STREAM("FormationPlanner: command " << last_command_ << " → " << last_outcome_);
    publishParams();
  }
  void publishParams() {
    auto m = toMsg(params_, version_);
    m.header.stamp = ros::Time::now();
    m.header.frame_id = world_frame_;
    m.last_command = last_command_;
    m.last_outcome = last_outcome_;
    m.last_command_source = last_source_;
    m.last_command_stamp = last_stamp_;
    m.last_command_status = last_status_;
    m.last_command_uavs = last_uavs_;
    params_pub_.publish(m);
  }

  void onTimer(const ros::TimerEvent&) {
    std::lock_guard<std::mutex> lock(mutex_);
    const double t = ros::Time::now().toSec();
    if (t <= 0.0) return;
    if (next_plan_s_ < 0.0) next_plan_s_ = (std::floor(t / period_s_) + 1.0) * period_s_ + offset_s_;
    if (t < next_plan_s_) return;
    next_plan_s_ += period_s_ * std::max(1.0, std::ceil((t - next_plan_s_) / period_s_ + 1e-9));
    replan(t);
  }

  void replan(double t) {
    if (!odom_) return;
    // The replanning step gfctl simulate's UAVs run too (planning::ReplanStep): freshness and
    // hold, listen before moving, the worker's extrapolation, hold / search, the request.
    std::optional<planning::WorkerKnowledge> worker;
    if (worker_) worker = toWorkerKnowledge(*worker_);
    planning::ReplanInputs in;
    in.t_s = t;
    in.state = *odom_;
    if (wind_ && t - wind_stamp_s_ <= max_wind_age_s_) in.wind_estimate_mps = *wind_;
    in.worker = worker ? &*worker : nullptr;
    in.params = &params_;
    in.leader_plan = received_[0] ? &received_[0]->plan : nullptr;
    in.received = &received_;
    const planning::ReplanOutcome out = step_->step(in);
    if (!out.planned()) return;
    if (!out.note.empty()) NODELET_WARN_STREAM("FormationPlanner UAV " << uav_index_ << ": " << out.note);
    const std::string mode = planning::toString(out.mode);
    if (mode != mode_) {
      if (out.holding()) {
        NODELET_WARN_STREAM("FormationPlanner UAV " << uav_index_ << ": " << mode << ": " << out.reason);
      } else {
        NODELET_INFO_STREAM("FormationPlanner UAV " << uav_index_ << ": track: fresh data");
      }
      mode_ = mode;
    }
    const planning::PlanResult& res = out.result;
    health_.record(out, t);
    if (res.status != planning::PlanStatus::kOptimized) {
      NODELET_WARN_STREAM_THROTTLE(2.0, "FormationPlanner UAV " << uav_index_ << ": " << planning::toString(res.status)
                                                                << ": " << res.reason);
    }
    if (res.qp_sparse_timeouts > 0) {
      NODELET_ERROR_STREAM("FormationPlanner UAV " << uav_index_ << ": " << res.qp_sparse_timeouts
                                                   << " QP solve(s) stopped (deadline qp.solve_timeout_s, or ProxQP's "
                                                   << "sparse solver broke an invariant: dense backend; docs/safety.md 4.5)");
    }
    auto msg = toMsg(res);
    msg.fallback = out.fallback;  // a holding UAV or a fallback plan has right of way (rule 3)
    msg.mode = mode;
    msg.mode_reason = out.reason;
    msg.header.frame_id = world_frame_;
    msg.uav_index = uav_index_;
    msg.params_version = uav_index_ == formation::kLeader ? version_ : received_version_;
    msg.planned_at = ros::Time(t);
    msg.formation = toMsg(params_, 0).uavs;
    for (int k = 0; k < out.reference.steps(); ++k) msg.reference.push_back(toPoint(out.reference.p_world.col(k)));
    for (int k = 0; k < out.worker.steps(); ++k) msg.worker.push_back(toPoint(out.worker.p_world.col(k)));
    plan_pub_.publish(msg);
    traj_pub_.publish(toMultiDof(msg, "uav" + std::to_string(uav_index_)));
  }

  /// This UAV's planner on /diagnostics (planning::ReplanHealth).
  std::vector<diagnostic_msgs::DiagnosticStatus> health(double since_s) {
    std::lock_guard<std::mutex> lock(mutex_);
    const planning::ReplanHealthReport r = health_.report(ros::Time::now().toSec(), period_s_);  // ROS (sim) time
    Health h("FormationPlanner uav" + std::to_string(uav_index_), "uav" + std::to_string(uav_index_));
    h.error(r.level == planning::ReplanHealthReport::Level::kError, r.message)
        .warn(r.level == planning::ReplanHealthReport::Level::kWarn, r.message)
        .value("mode", r.mode)
        .value("plans_per_s", since_s > 0.0 ? r.plans / since_s : 0.0)
        .value("fallbacks", r.fallbacks)
        .value("last_status", r.last_status)
        .value("last_planning_ms", r.last_planning_ms)
        .value("last_plan_age_s", r.last_plan_age_s);
    return {h.status()};
  }

  std::mutex mutex_;
  DiagnosticsPublisher diagnostics_;
  planning::ReplanHealth health_;  ///< /diagnostics: plans, fallbacks, the last plan's age
  int uav_index_ = 0, uav_count_ = 0;
  std::string world_frame_;
  double period_s_ = 0.0, offset_s_ = 0.0, next_plan_s_ = -1.0;
  static constexpr double kMaxWindMps = 60.0;  ///< a larger wind estimate is garbage
  double max_wind_age_s_ = 0.0, wind_stamp_s_ = 0.0;
  std::optional<Eigen::Vector3d> wind_;
  std::uint64_t wind_rejected_ = 0;
  formation::FormationParams params_;
  std::optional<formation::FormationState> state_;
  std::uint64_t version_ = 0;           ///< leader: the parameters' version
  std::uint64_t received_version_ = 0;  ///< followers: the version received (0 over LCM: not carried)
  std::string mode_ = "track";             ///< track | hold | search (logged on change)
  std::string last_command_, last_outcome_, last_source_, last_status_;
  ros::Time last_stamp_;
  std::vector<int> last_uavs_;
  std::unique_ptr<planning::ReplanStep> step_;  ///< planner, hold / search, listening (shared with gfctl simulate)
  std::optional<planning::UavKinematicState> odom_;
  std::optional<gesture_formation::WorkerState> worker_;
  std::vector<std::optional<planning::ReceivedPlan>> received_;  ///< by sender; [0] the leader's plan
  ros::Publisher plan_pub_, traj_pub_, params_pub_;
  ros::Subscriber odom_sub_, worker_sub_, plans_sub_, params_sub_, command_sub_, wind_sub_;
  ros::Timer timer_, params_timer_;
};

}  // namespace gesture_formation::nodelets

PLUGINLIB_EXPORT_CLASS(gesture_formation::nodelets::FormationPlannerNodelet, nodelet::Nodelet)

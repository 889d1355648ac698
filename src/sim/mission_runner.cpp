#include "gesture_formation/sim/mission_runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <optional>
#include <sstream>

#include <Eigen/Geometry>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/estimation/human_kalman.hpp"
#include "gesture_formation/estimation/measurement_model.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/formation/worker_heading.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/plan_request_builder.hpp"
#include "gesture_formation/sim/random.hpp"
#include "gesture_formation/sim/wind.hpp"

namespace gesture_formation::sim {

// --------------------------------------------------------------------------------------
// Product adapters
namespace {

class UavPlannerAdapter : public MissionPlanner {
 public:
  UavPlannerAdapter(const planning::PlannerConfig& c, std::shared_ptr<const planning::OccupancyMap> map,
                    std::shared_ptr<const planning::DistanceField> field)
      : planner_(c, std::move(map), std::move(field)) {}
  planning::PlanResult plan(const planning::PlanRequest& r) override { return planner_.plan(r); }

 private:
  planning::UavPlanner planner_;
};

}  // namespace

PlannerFactory uavPlannerFactory(const planning::PlannerConfig& config,
                                 std::shared_ptr<const planning::OccupancyMap> map,
                                 std::shared_ptr<const planning::DistanceField> field) {
  return [config, map, field](int) -> std::unique_ptr<MissionPlanner> {
    return std::make_unique<UavPlannerAdapter>(config, map, field);
  };
}

// --------------------------------------------------------------------------------------
namespace {

/// What the leader shares every replanning (design.md §1: human state, leader plan, parameters).
struct LeaderShare {
  double stamp_s = 0.0;
  double worker_stamp_s = 0.0;  ///< time of the leader's last fused worker measurement
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();
  double human_heading_rad = 0.0;
  formation::FormationParams params;
  std::uint64_t params_version = 0;
  planning::PlannedTrajectory plan;
};

/// A follower's plan with its planner status: a UAV that could not plan (braking or on its
/// previous plan) is avoided by every other UAV, also higher-priority ones (right of way).
using PlanMessage = planning::ReceivedPlan;

struct OperatorMessage {
  std::size_t record = 0;
  double sent_s = 0.0;
  formation::FormationCommand command;
};

struct UavRuntime {
  UavRuntime(const UavConfig& u, const MissionConfig& c, const MultirotorState& s0, std::uint64_t seed, int index)
      : plant(u.plant, s0),
        ctl(c.controller, u.plant),
        odo(c.odometry, makeRng(seed, Stream::kOdometry, static_cast<std::uint64_t>(index))) {}
  Multirotor plant;
  TrackingController ctl;
  Odometry odo;
  std::unique_ptr<MissionPlanner> planner;
  EstimatedState est;
  WindEstimate wind_estimate;  ///< the flight stack's wind estimate (planning's wind allowance)
  double next_plan_s = 0.0;
  std::optional<LeaderShare> share;                           ///< followers: last received from the leader
  std::vector<std::optional<PlanMessage>> received;  ///< plans received from the followers
  bool offline = false;                                      ///< follower dropout in progress
  double rejoined_s = -std::numeric_limits<double>::infinity();  ///< end of the last dropout
  std::string mode = "start";                                ///< last mode recorded (ModeChange)
  planning::HoldPlanner hold;                                ///< hold / search decision and its latched state
};

void addCounters(MissionMetrics& M, const LinkCounters& c) {
  M.messages_sent += static_cast<long>(c.sent);
  M.messages_lost += static_cast<long>(c.lost);
  M.messages_duplicated += static_cast<long>(c.duplicated);
  M.messages_reordered += static_cast<long>(c.reordered);
}

}  // namespace

common::Result<MissionOutput> runMission(const MissionConfig& cfg, const MissionWorld& world,
                                         const PlannerFactory& planners, MissionClassifier* classifier,
                                         std::uint64_t seed, double duration_s) {
  using R = common::Result<MissionOutput>;
  if (world.field == nullptr) return R::fail("runMission: a distance field is required");
  const auto wall0 = std::chrono::steady_clock::now();
  const double duration = duration_s > 0.0 ? duration_s : cfg.duration_s;
  const int n = cfg.formation.params.uavCount();
  if (static_cast<int>(cfg.uavs.size()) != n) return R::fail("runMission: uavs and formation disagree on the UAV count");

  auto fstate_r = formation::FormationState::create(cfg.formation.params, cfg.formation.limits, cfg.formation.duplicates);
  if (!fstate_r) return R::fail(fstate_r.reason());
  formation::FormationState fstate = std::move(*fstate_r);
  std::uint64_t params_version = 0;

  WorkerModel worker(cfg.worker, mixSeed(seed ^ static_cast<std::uint64_t>(Stream::kWorker)));
  formation::WorkerHeading human_heading(cfg.formation.worker_heading);
  WindModel wind(cfg.wind, makeRng(seed, Stream::kWind));
  LeaderCamera camera(cfg, world.map, seed);
  estimation::HumanKalman kf(cfg.estimator.filter);
  const estimation::CameraModel cam_model(cfg.estimator.camera);
  gesture::GestureFilter filter(cfg.gesture_filter);
  // The formation's cameras vote (docs/gestures.md §4.1); min_agreeing_views 1 = the paper's
  // pipeline on the leader's camera alone.
  const bool follower_views = cfg.view_fusion.min_agreeing_views > 1;
  gesture::ViewFusion fusion(cfg.view_fusion, follower_views ? n : 1, cfg.gesture_filter.max_gesture_id);

  // --- UAVs: initial states at the formation references around the worker's start -------
  const WorkerState w0 = worker.stateAt(0.0);
  const double hphi0 = human_heading.heading();
  const formation::UavReference lref0 = formation::leaderReference(w0.p_world, hphi0, cfg.formation.params.leader);
  std::vector<std::unique_ptr<UavRuntime>> uavs;
  const planning::FreshnessLimits freshness{cfg.faults.max_share_age_s, cfg.faults.max_worker_age_s};
  for (int i = 0; i < n; ++i) {
    const formation::UavReference ref =
        i == 0 ? lref0
               : formation::followerReference(w0.p_world, lref0.heading_rad, lref0.pitch_rad,
                                              cfg.formation.params.followers[static_cast<std::size_t>(i - 1)]);
    MultirotorState s0;
    s0.p_world = cfg.uavs[static_cast<std::size_t>(i)].initial_position.value_or(ref.p_world);
    s0.heading_rad = ref.heading_rad;
    s0.pitch_rad = ref.pitch_rad;
    const double clearance = world.field->clearance(s0.p_world);
    if (clearance < cfg.planner.path_clearance_m) {
      std::ostringstream os;
      os << cfg.source << ": mission.uavs[" << i << "].initial_position: (" << s0.p_world.transpose()
         << ") has clearance " << clearance << " m < planner path_clearance_m " << cfg.planner.path_clearance_m
         << " (set an initial_position in free space)";
      return R::fail(os.str());
    }
    auto u = std::make_unique<UavRuntime>(cfg.uavs[static_cast<std::size_t>(i)], cfg, s0, seed, i);
    u->planner = planners(i);
    u->next_plan_s = cfg.replanning_period_s * static_cast<double>(i) / static_cast<double>(n);
    u->received.resize(static_cast<std::size_t>(n));
    u->hold = planning::HoldPlanner(freshness, cfg.faults.search, cfg.controller.brake_accel_mps2);
    uavs.push_back(std::move(u));
  }

  // --- links -----------------------------------------------------------------------------
  std::uint64_t link_index = 0;
  Link<OperatorMessage> operator_link(cfg.operator_link, makeRng(seed, Stream::kLink, link_index++));
  std::vector<std::unique_ptr<Link<LeaderShare>>> share_links;  // [i]: leader → follower i
  std::vector<std::vector<std::unique_ptr<Link<PlanMessage>>>> plan_links(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    share_links.push_back(std::make_unique<Link<LeaderShare>>(cfg.link, makeRng(seed, Stream::kLink, link_index++)));
    plan_links[static_cast<std::size_t>(i)].resize(static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j) {
      if (j == i) continue;
      plan_links[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] =
          std::make_unique<Link<PlanMessage>>(cfg.link, makeRng(seed, Stream::kLink, link_index++));
    }
  }
  // [i]: follower i's gesture votes → the leader over the same lossy link (the ROS system:
  // ViewObserver → LcmBridge → the leader's GestureCommander). Created after the other links:
  // their random streams are unchanged.
  std::vector<std::unique_ptr<Link<gesture::ViewObservation>>> vote_links(static_cast<std::size_t>(n));
  for (int i = 1; follower_views && i < n; ++i) {
    vote_links[static_cast<std::size_t>(i)] =
        std::make_unique<Link<gesture::ViewObservation>>(cfg.link, makeRng(seed, Stream::kLink, link_index++));
  }

  MetricsAccumulator metrics(cfg, ObstacleDistance{world.field, world.solids, world.ground_height_m}, seed);
  MissionMetrics& M = metrics.counters();
  std::vector<ModeChange> modes;
  std::uint64_t gesture_seq = 0;
  OperatorSchedule schedule(cfg.requests, "operator");
  int last_class = -1;
  double last_ratio = 0.0;
  double last_fused_s = -std::numeric_limits<double>::infinity();  // the leader's last fused worker measurement

  const double dt = cfg.step_s;
  const long steps = std::lround(duration / dt);
  StepSchedule camera_frames(1.0 / cfg.camera.rate_hz, dt);
  StepSchedule timeline_samples(1.0 / cfg.timeline_rate_hz, dt);
  const double hdt = cfg.horizon_dt_s;
  const int hsteps = cfg.horizon_steps;

  auto applyCommand = [&](std::size_t record, const formation::FormationCommand& cmd, double t) {
    const auto outcome = fstate.apply(cmd);
    if (outcome.status == formation::CommandStatus::kDuplicate) ++M.commands_duplicate;
    if (metrics.request(record).status == "applied") return;  // a duplicate copy of an applied command changes nothing
    const bool applied = outcome.status == formation::CommandStatus::kApplied;
    std::vector<int> addressed;
    for (const auto& ch : outcome.changes) addressed.push_back(ch.uav);
    metrics.requestOutcome(record, formation::toString(outcome.status), t, applied ? ++params_version : 0, addressed);
  };

  auto setMode = [&](int i, double t, const std::string& mode, const std::string& reason) {
    UavRuntime& u = *uavs[static_cast<std::size_t>(i)];
    if (u.mode == mode) return;
    u.mode = mode;
    modes.push_back(ModeChange{t, i, mode, reason});
  };

  auto replan = [&](int i, double t) {
    UavRuntime& u = *uavs[static_cast<std::size_t>(i)];
    if (u.offline) {
      ++M.plans_skipped;
      return;
    }
    for (const auto& o : cfg.faults.planner_outages) {
      if (o.uav == i && t >= o.from_s && t < o.to_s) {
        ++M.plans_skipped;
        setMode(i, t, "outage", "planner outage: the loaded plan is flown to its end and held");
        return;
      }
    }
    Eigen::Vector3d p0, v0;
    double hphi = 0.0;
    formation::FormationParams params;
    std::uint64_t version = 0;
    const LeaderShare* share = nullptr;
    double worker_stamp = 0.0;
    bool worker_lost = false;
    std::string hold;  // non-empty: hold a safe position (docs/safety.md), the reason
    if (i == 0) {
      // Nothing to plan on before the first estimate, nor on a tentative track (initialised from
      // one measurement that may be a gross range error: range_outliers / harsh seed 97): fly the
      // last plan, as the ROS leader does while its WorkerEstimator publishes nothing new.
      if (!kf.confirmed()) {
        ++M.plans_skipped;
        return;
      }
      const estimation::Vector6d& x = kf.state();
      worker_stamp = last_fused_s;
      worker_lost = kf.lost(t);
      hold = planning::holdReason(i, t, t, worker_stamp, freshness);
      const bool stale = !hold.empty() || worker_lost;
      v0 = stale ? Eigen::Vector3d::Zero() : Eigen::Vector3d(x.tail<3>());
      // Stale: the estimator's prediction (constant velocity for lost_timeout_s, then held) — what
      // the WorkerEstimator nodelet publishes — serves as camera target and obstacle only.
      p0 = stale ? kf.predicted(t).p_world : Eigen::Vector3d(x.head<3>() + (t - kf.time()) * v0);
      hphi = stale ? human_heading.heading() : human_heading.update(v0);
      params = fstate.params();
      version = params_version;
    } else {
      if (!u.share) {
        ++M.plans_skipped;  // nothing known about the worker: the controller holds (its plan's end, or brakes)
        setMode(i, t, "hold", "no leader share received yet");
        return;
      }
      share = &*u.share;
      worker_stamp = share->worker_stamp_s;
      hold = planning::holdReason(i, t, share->stamp_s, worker_stamp, freshness);
      if (hold.empty() && u.rejoined_s > -std::numeric_limits<double>::infinity()) {
        hold = planning::listeningReason(i, u.rejoined_s, u.received,
                                         [&](int j) { return uavs[static_cast<std::size_t>(j)]->offline; });
        if (hold.empty()) u.rejoined_s = -std::numeric_limits<double>::infinity();
      }
      const bool stale = !hold.empty();
      v0 = stale ? Eigen::Vector3d::Zero() : Eigen::Vector3d(share->v_world);
      p0 = share->p_world + (stale ? 0.0 : (t - share->stamp_s)) * v0;
      hphi = share->human_heading_rad;
      params = share->params;
      version = share->params_version;
    }
    // Hold (stop where braking at the controller's deceleration ends, camera on the worker
    // estimate; the stale data serve only as an obstacle and camera target) or, the leader that
    // lost the worker, search with the camera — the decision the FormationPlanner makes too.
    planning::HoldPlanner::Situation situation;
    situation.uav_index = i;
    situation.t_s = t;
    situation.dt_s = hdt;
    situation.steps = hsteps;
    situation.hold_reason = hold;
    situation.worker_stamp_s = worker_stamp;
    situation.worker_lost = worker_lost;
    situation.p_world = u.est.p_world;
    situation.v_world = u.est.v_world;
    situation.heading_rad = u.est.heading_rad;
    situation.worker_world = p0;
    const planning::HoldPlanner::Decision decision = u.hold.decide(situation);
    if (decision.holding()) {
      ++M.plans_hold;
      setMode(i, t, decision.mode, hold);
    } else {
      setMode(i, t, "track", "fresh data");
    }
    const formation::WorkerHorizon wh = formation::constantVelocityHorizon(p0, v0, hphi, hsteps, hdt);
    planning::PlanRequestInputs in;
    in.uav_index = i;
    in.t_s = t;
    in.dt_s = hdt;
    in.state.p_world = u.est.p_world;
    in.state.v_world = u.est.v_world;
    in.state.a_world = u.plant.state().a_world;
    in.state.heading_rad = u.est.heading_rad;
    in.state.pitch_rad = u.est.pitch_rad;
    in.wind_estimate_mps = u.wind_estimate.value();
    in.worker = wh;
    in.params = &params;
    in.leader_plan = share != nullptr ? &share->plan : nullptr;
    in.received = &u.received;
    in.hold_reference = decision.holding() ? &decision.reference : nullptr;
    if (decision.camera_target.cols() > 0) in.camera_target = &decision.camera_target;
    in.rule = planning::AvoidanceRule{cfg.faults.avoid_all_plans, cfg.faults.max_plan_age_s};
    const planning::PlanRequest req = planning::buildPlanRequest(in);
    const planning::PlanResult res = u.planner->plan(req);
    metrics.plan(i, t, version, res.status, res.timings.total_ms, res.reason, res.qp_sparse_timeouts);
    if (res.trajectory.empty()) {
      u.ctl.clearPlan();
    } else {
      u.ctl.setPlan(res.trajectory);
    }
    if (i == 0) {
      LeaderShare s;
      s.stamp_s = t;
      s.worker_stamp_s = worker_stamp;
      s.p_world = p0;
      s.v_world = v0;
      s.human_heading_rad = hphi;
      s.params = params;
      s.params_version = version;
      s.plan = res.trajectory;
      for (int j = 1; j < n; ++j) share_links[static_cast<std::size_t>(j)]->send(t, s);
    } else {
      const PlanMessage msg{res.trajectory, res.status != planning::PlanStatus::kOptimized || !hold.empty()};
      for (int j = 0; j < n; ++j) {
        if (j != i) plan_links[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)]->send(t, msg);
      }
    }
  };

  for (long k = 0; k <= steps; ++k) {
    const double t = static_cast<double>(k) * dt;
    const WorkerState ws = worker.stateAt(t);

    // Operator requests → operator link → the leader's FormationState.
    for (const auto& d : schedule.due(t)) operator_link.send(t, OperatorMessage{metrics.addRequest(d.record), t, d.command});
    for (const auto& msg : operator_link.receive(t)) {
      RequestRecord& rec = metrics.request(msg.record);
      if (t - msg.sent_s > cfg.faults.max_command_age_s) {  // never act on a command older than its age
        ++M.commands_stale;
        if (rec.status == "lost") rec.status = "stale";
        continue;
      }
      applyCommand(msg.record, msg.command, t);
    }

    // Follower dropouts: offline → nothing runs; back online → a rebooted computer with no memory.
    for (int i = 1; i < n; ++i) {
      UavRuntime& u = *uavs[static_cast<std::size_t>(i)];
      const bool off = cfg.faults.followerOffline(i, t);
      if (off && !u.offline) {
        setMode(i, t, "offline", "follower dropout: the loaded plan is flown to its end and held");
      } else if (!off && u.offline) {
        u.share.reset();
        for (auto& r : u.received) r.reset();
        u.planner = planners(i);
        u.rejoined_s = t;
        setMode(i, t, "rejoin", "back online: listening before it moves");
      }
      u.offline = off;
    }

    // Inter-UAV messages (an offline UAV's radio drops what arrives).
    for (int i = 1; i < n; ++i) {
      UavRuntime& u = *uavs[static_cast<std::size_t>(i)];
      for (auto& s : share_links[static_cast<std::size_t>(i)]->receive(t)) {
        if (u.offline) continue;
        if (!u.share || s.stamp_s > u.share->stamp_s) u.share = std::move(s);
      }
    }
    for (int i = 0; i < n; ++i) {
      UavRuntime& u = *uavs[static_cast<std::size_t>(i)];
      for (int j = 1; j < n; ++j) {
        if (j == i) continue;
        for (auto& p : plan_links[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)]->receive(t)) {
          if (u.offline) continue;
          auto& slot = u.received[static_cast<std::size_t>(j)];
          if (!slot || p.plan.t0_s > slot->plan.t0_s) slot = std::move(p);  // duplicates and late copies ignored
        }
      }
    }

    // Odometry of every UAV at this step (used by sensing, planning and control).
    for (auto& u : uavs) u->est = u->odo.measure(u->plant.state(), dt);

    // Leader camera frame: box → estimator; skeleton → classifier → filter → command.
    if (camera_frames.due(k)) {
      std::vector<MultirotorState> follower_states;
      std::vector<bool> online;
      if (follower_views) {
        for (int i = 1; i < n; ++i) {
          follower_states.push_back(uavs[static_cast<std::size_t>(i)]->plant.state());
          online.push_back(!uavs[static_cast<std::size_t>(i)]->offline);
        }
      }
      const LeaderCameraFrame cf = camera.frame(t, uavs[0]->plant.state(), follower_states, online, ws, worker, classifier);
      const SensorFrame& frame = cf.sensors;
      M.range_outliers += cf.range_outliers;
      if (frame.visible()) {
        const UavRuntime& L = *uavs[0];
        const estimation::CameraPose est_pose = cameraPose(L.est.p_world, L.est.heading_rad, L.est.pitch_rad);
        const auto meas = estimation::makeMeasurement(cam_model, est_pose, frame.box, frame.d_uwb_m, frame.d_stereo_m,
                                                      cfg.estimator.human_height_m, cfg.estimator.noise);
        if (meas && estimation::accepted(kf.step(t, *meas))) last_fused_s = t;
      }
      // Each camera's classification → the vote (geometry from the leader's worker estimate
      // and each UAV's odometry: a view votes only inside the classifier's envelope) → filter.
      bool classified = false;
      const std::optional<Eigen::Vector3d> worker_est =
          kf.confirmed() ? std::optional<Eigen::Vector3d>(kf.predicted(t).p_world) : std::nullopt;
      const auto observation = [&](int view, const gesture::Classification& c, const gesture::CalibratedSkeleton& cal) {
        gesture::ViewObservation o;
        o.view = view;
        o.t_s = t;
        o.gesture_id = c.gesture_id;
        o.distance_m = std::nan("");
        o.elevation_deg = std::nan("");
        if (worker_est) {
          const Eigen::Vector3d rel = uavs[static_cast<std::size_t>(view)]->est.p_world - *worker_est;
          o.distance_m = rel.norm();
          o.elevation_deg = common::radToDeg(std::asin(std::clamp(rel.z() / std::max(1e-9, rel.norm()), -1.0, 1.0)));
        }
        if (cfg.view_fusion.confirm_3d) {
          // The camera pose as the UAV knows it: the rendering pose moved by its odometry's
          // position and heading errors.
          const UavRuntime& u = *uavs[static_cast<std::size_t>(view)];
          const MultirotorState truth = u.plant.state();
          gesture::CalibratedSkeleton known = cal;
          known.p_world_camera += u.est.p_world - truth.p_world;
          known.R_world_camera =
              Eigen::AngleAxisd(common::wrapAngle(u.est.heading_rad - truth.heading_rad), Eigen::Vector3d::UnitZ()) *
              cal.R_world_camera;
          o.calibrated = known;
        }
        return o;
      };
      if (cf.classification) classified = fusion.observe(observation(0, *cf.classification, cf.calibrated));
      // The followers' votes travel the link; those that arrived by now are counted. The views are
      // compared view_fusion.fusion_lag_s in the past (the link's delay budget): a vote that is
      // older than max_age_s at that moment, or arrives later than the lag, does not count.
      for (std::size_t i = 0; i < cf.followers.size(); ++i) {
        if (cf.followers[i].classification) {
          vote_links[i + 1]->send(t, observation(static_cast<int>(i) + 1, *cf.followers[i].classification,
                                                 cf.followers[i].calibrated));
        }
      }
      for (int i = 1; follower_views && i < n; ++i) {
        for (const auto& o : vote_links[static_cast<std::size_t>(i)]->receive(t)) classified = fusion.observe(o) || classified;
      }
      if (classified) {
        const double t_fused = follower_views ? t - cfg.view_fusion.fusion_lag_s : t;
        const int fused = follower_views ? fusion.fuse(t_fused).gesture_id : cf.classification->gesture_id;
        last_class = fused;
        const auto fo = filter.update(t_fused, fused);
        last_ratio = fo.dominant_ratio;
        if (fo.fired) {
          const std::size_t record = metrics.addRequest(firedGestureRecord(t, fo.dominant_id, cfg.gesture_mapping));
          const gesture::GestureAction* action = cfg.gesture_mapping.find(fo.dominant_id);
          if (action != nullptr && action->kind != gesture::GestureAction::Kind::kEvent) {
            applyCommand(record, gesture::toCommand(*action, ++gesture_seq), t);
          }
        }
      }
      // The estimate the system acts on (a tentative track is not published: docs/estimation.md).
      Eigen::Vector3d estimate = Eigen::Vector3d::Zero();
      if (kf.confirmed()) estimate = kf.predicted(t).p_world;
      metrics.cameraFrame(frame.visible(), kf.confirmed() ? &estimate : nullptr, ws.p_world);
    }

    // Replanning, staggered, in priority order within a step.
    for (int i = 0; i < n; ++i) {
      UavRuntime& u = *uavs[static_cast<std::size_t>(i)];
      if (t + 1e-9 >= u.next_plan_s) {
        u.next_plan_s += cfg.replanning_period_s;
        replan(i, t);
      }
    }

    // Safety metrics at every step (true states).
    std::vector<Eigen::Vector3d> p_true;
    for (const auto& u : uavs) p_true.push_back(u->plant.state().p_world);
    metrics.sampleSafety(t, p_true, ws);

    // Timeline and tracking errors at the timeline rate.
    if (timeline_samples.due(k)) {
      TimelineInput in;
      in.t_s = t;
      in.worker = ws;
      if (kf.confirmed()) in.estimate_world = kf.predicted(t).p_world;
      in.visible = camera.lastVisibleS() > t - 0.2 ? 1 : 0;
      in.gesture_true = worker.performingAt(t);
      in.gesture_class = last_class;
      in.dominant_ratio = last_ratio;
      in.params = fstate.params();
      in.human_heading_rad = human_heading.heading();
      for (const auto& u : uavs) in.uavs.push_back(u->plant.state());
      metrics.sampleTimeline(in);
    }

    if (k == steps) break;
    // Control and plant.
    const Eigen::Vector3d w = wind.step(t, dt);
    for (auto& u : uavs) {
      const MultirotorCommand cmd = u->ctl.update(t, dt, u->est);
      u->plant.step(dt, cmd, w, world.ground_height_m);
      u->wind_estimate.update(w, dt);
    }
  }

  for (const auto& l : share_links) addCounters(M, l->counters());
  for (const auto& l : vote_links) {
    if (l) addCounters(M, l->counters());
  }
  for (const auto& row : plan_links) {
    for (const auto& l : row) {
      if (l) addCounters(M, l->counters());
    }
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  MissionOutput out = metrics.finish(worker.episodes(), static_cast<double>(steps) * dt, wall_s);
  out.modes = std::move(modes);
  return R::ok(std::move(out));
}

}  // namespace gesture_formation::sim

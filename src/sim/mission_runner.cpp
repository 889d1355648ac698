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
#include "gesture_formation/gesture/gesture_frames.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/replan_step.hpp"
#include "gesture_formation/sim/random.hpp"
#include "gesture_formation/sim/wind.hpp"

namespace gesture_formation::sim {

PlannerFactory uavPlannerFactory(const planning::PlannerConfig& config,
                                 std::shared_ptr<const planning::OccupancyMap> map,
                                 std::shared_ptr<const planning::DistanceField> field) {
  return [config, map, field](int) -> std::unique_ptr<MissionPlanner> {
    return std::make_unique<planning::UavPlannerAdapter>(std::make_unique<planning::UavPlanner>(config, map, field));
  };
}

// --------------------------------------------------------------------------------------
namespace {

/// What the leader shares every replanning (design.md §1: human state, leader plan, formation
/// params) — in ROS the WorkerState, PlannedTrajectory and FormationParams it sends over LCM.
struct LeaderShare {
  planning::WorkerKnowledge worker;  ///< stamp_s = when the leader sent it
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
  std::unique_ptr<planning::ReplanStep> step;  ///< the product's replanning step (planner, hold, listening)
  EstimatedState est;
  WindEstimate wind_estimate;  ///< the flight stack's wind estimate (planning's wind allowance)
  double next_plan_s = 0.0;
  std::optional<LeaderShare> share;                           ///< followers: last received from the leader
  std::vector<std::optional<PlanMessage>> received;  ///< plans received from the followers
  bool offline = false;                                      ///< follower dropout in progress
  std::string mode = "start";                                ///< last mode recorded (ModeChange)
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
  WindModel wind(cfg.wind, makeRng(seed, Stream::kWind));
  LeaderCamera camera(cfg, world.map, seed);
  estimation::HumanKalman kf(cfg.estimator.filter);
  const estimation::CameraModel cam_model(cfg.estimator.camera);
  // The formation's cameras vote (docs/gestures.md §4.1); min_agreeing_views 1 = the paper's
  // pipeline on the leader's camera alone.
  const bool follower_views = cfg.view_fusion.min_agreeing_views > 1;
  gesture::GestureFrames frames(cfg.gesture_filter, cfg.view_fusion, cfg.gesture_mapping, n, 0.0);

  // --- UAVs: initial states at the formation references around the worker's start -------
  const WorkerState w0 = worker.stateAt(0.0);
  const double hphi0 = formation::WorkerHeading(cfg.formation.worker_heading).heading();
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
    planning::ReplanConfig rc;
    rc.uav_index = i;
    rc.dt_s = cfg.horizon_dt_s;
    rc.steps = cfg.horizon_steps;
    rc.freshness = freshness;
    rc.rule = planning::AvoidanceRule{cfg.faults.avoid_all_plans, cfg.faults.max_plan_age_s};
    rc.search = cfg.faults.search;
    rc.brake_accel_mps2 = cfg.controller.brake_accel_mps2;
    rc.worker_heading = cfg.formation.worker_heading;
    u->step = std::make_unique<planning::ReplanStep>(rc, planners(i));
    u->next_plan_s = cfg.replanning_period_s * static_cast<double>(i) / static_cast<double>(n);
    u->received.resize(static_cast<std::size_t>(n));
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
  std::optional<planning::WorkerKnowledge> leader_knowledge;        // the leader's last confirmed estimate

  const double dt = cfg.step_s;
  const long steps = std::lround(duration / dt);
  StepSchedule camera_frames(1.0 / cfg.camera.rate_hz, dt);
  StepSchedule timeline_samples(1.0 / cfg.timeline_rate_hz, dt);

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
    // What this UAV knows: the leader its estimator's state as the WorkerEstimator publishes it
    // (only a confirmed track, the prediction to now; the last one kept while the track is
    // re-initialised), a follower the leader's last share.
    const LeaderShare* share = nullptr;
    const formation::FormationParams* params = &fstate.params();
    std::uint64_t version = params_version;
    if (i == 0) {
      if (kf.confirmed()) {
        planning::WorkerKnowledge w;
        w.stamp_s = t;
        w.fused_s = last_fused_s;
        w.p_world = kf.predicted(t).p_world;
        w.v_world = kf.state().tail<3>();
        w.lost = kf.lost(t);
        leader_knowledge = w;
      }
    } else if (u.share) {
      share = &*u.share;
      params = &share->params;
      version = share->params_version;
    }
    planning::ReplanInputs in;
    in.t_s = t;
    in.state.p_world = u.est.p_world;
    in.state.v_world = u.est.v_world;
    in.state.heading_rad = u.est.heading_rad;
    in.state.pitch_rad = u.est.pitch_rad;
    in.wind_estimate_mps = u.wind_estimate.value();
    in.worker = i == 0 ? (leader_knowledge ? &*leader_knowledge : nullptr) : (share != nullptr ? &share->worker : nullptr);
    in.params = params;
    in.leader_plan = share != nullptr ? &share->plan : nullptr;
    in.received = &u.received;
    const planning::ReplanOutcome out = u.step->step(in);
    if (!out.planned()) {
      ++M.plans_skipped;  // nothing known about the worker: the controller holds (its plan's end, or brakes)
      if (i != 0) setMode(i, t, "hold", out.reason);
      return;
    }
    if (out.holding()) ++M.plans_hold;
    setMode(i, t, planning::toString(out.mode), out.holding() ? out.reason : "fresh data");
    const planning::PlanResult& res = out.result;
    metrics.plan(i, t, version, res.status, res.timings.total_ms, res.reason, res.qp_sparse_timeouts);
    if (res.trajectory.empty()) {
      u.ctl.clearPlan();
    } else {
      u.ctl.setPlan(res.trajectory);
    }
    if (i == 0) {
      LeaderShare s;
      s.worker = *leader_knowledge;  // the estimator's state, as the WorkerEstimator's over LCM
      s.params = *params;
      s.params_version = version;
      s.plan = res.trajectory;
      for (int j = 1; j < n; ++j) share_links[static_cast<std::size_t>(j)]->send(t, s);
    } else {
      const PlanMessage msg{res.trajectory, out.fallback};
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
        u.step->restart(planners(i));
        setMode(i, t, "rejoin", "back online: listening before it moves");
      }
      u.offline = off;
    }

    // Inter-UAV messages (an offline UAV's radio drops what arrives).
    for (int i = 1; i < n; ++i) {
      UavRuntime& u = *uavs[static_cast<std::size_t>(i)];
      for (auto& s : share_links[static_cast<std::size_t>(i)]->receive(t)) {
        if (u.offline) continue;
        if (!u.share || s.worker.stamp_s > u.share->worker.stamp_s) u.share = std::move(s);
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
          const formation::ViewGeometry g = formation::viewGeometry(uavs[static_cast<std::size_t>(view)]->est.p_world, *worker_est);
          o.distance_m = g.distance_m;
          o.elevation_deg = g.elevation_deg;
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
      // The leader's classification and the followers' votes that arrived by now go to the
      // frame aggregation the GestureCommander nodelet runs (gesture::GestureFrames): a frame is
      // fused once every view reported it, or view_fusion.fusion_lag_s after its stamp.
      std::vector<gesture::GestureFrame> closed;
      const auto take = [&closed](std::vector<gesture::GestureFrame> frames_closed) {
        for (auto& f : frames_closed) closed.push_back(std::move(f));
      };
      if (cf.classification) take(frames.observe(observation(0, *cf.classification, cf.calibrated)));
      for (std::size_t i = 0; i < cf.followers.size(); ++i) {
        if (cf.followers[i].classification) {
          vote_links[i + 1]->send(t, observation(static_cast<int>(i) + 1, *cf.followers[i].classification,
                                                 cf.followers[i].calibrated));
        }
      }
      for (int i = 1; follower_views && i < n; ++i) {
        for (const auto& o : vote_links[static_cast<std::size_t>(i)]->receive(t)) take(frames.observe(o));
      }
      take(frames.closeDue(t));
      for (const gesture::GestureFrame& f : closed) {
        last_class = f.fused.gesture_id;
        last_ratio = f.filter.dominant_ratio;
        if (!f.filter.fired) continue;
        const std::size_t record = metrics.addRequest(firedGestureRecord(t, f.filter.dominant_id, cfg.gesture_mapping));
        if (f.action != nullptr && f.action->kind != gesture::GestureAction::Kind::kEvent) {
          applyCommand(record, gesture::toCommand(*f.action, ++gesture_seq), t);
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
      in.human_heading_rad = uavs[0]->step->workerHeading();
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

#include "gesture_formation/sim/mission_runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <optional>
#include <random>
#include <regex>
#include <sstream>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/common/csv.hpp"
#include "gesture_formation/estimation/human_kalman.hpp"
#include "gesture_formation/estimation/measurement_model.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/formation/worker_heading.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/sim/random.hpp"

namespace gesture_formation::sim {

using common::formatDouble;
using common::radToDeg;
using common::wrapAngle;

// --------------------------------------------------------------------------------------
// Product adapters
namespace {

/// The obstacle-distance metric (MissionWorld::solids).
double obstacleDistance(const MissionWorld& world, const Eigen::Vector3d& p) {
  const double field = world.field->clearance(p);
  if (world.solids == nullptr || field >= 2.5) return field;
  return std::min(world.solids->distance(p), p.z() - world.ground_height_m);
}

/// The planner's first failure reason without its numbers (so equal causes group together).
std::string reasonKey(const std::string& reason) {
  std::string first = reason.substr(0, reason.find(';'));
  static const std::regex number(R"([-+]?[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?)");
  first = std::regex_replace(first, number, "#");
  return first.empty() ? "(no reason given)" : first;
}

class UavPlannerAdapter : public MissionPlanner {
 public:
  UavPlannerAdapter(const planning::PlannerConfig& c, std::shared_ptr<const planning::OccupancyMap> map,
                    std::shared_ptr<const planning::DistanceField> field)
      : planner_(c, std::move(map), std::move(field)) {}
  planning::PlanResult plan(const planning::PlanRequest& r) override { return planner_.plan(r); }

 private:
  planning::UavPlanner planner_;
};

class OnnxClassifier : public MissionClassifier {
 public:
  explicit OnnxClassifier(gesture::GestureClassifier c) : c_(std::move(c)) {}
  common::Result<gesture::Classification> classify(const gesture::SkeletonWindow& w) override { return c_.classify(w); }

 private:
  gesture::GestureClassifier c_;
};

}  // namespace

PlannerFactory uavPlannerFactory(const planning::PlannerConfig& config,
                                 std::shared_ptr<const planning::OccupancyMap> map,
                                 std::shared_ptr<const planning::DistanceField> field) {
  return [config, map, field](int) -> std::unique_ptr<MissionPlanner> {
    return std::make_unique<UavPlannerAdapter>(config, map, field);
  };
}

common::Result<std::unique_ptr<MissionClassifier>> loadOnnxClassifier(const std::string& onnx_path) {
  using R = common::Result<std::unique_ptr<MissionClassifier>>;
  auto c = gesture::GestureClassifier::load(onnx_path);
  if (!c) return R::fail(c.reason());
  return R::ok(std::make_unique<OnnxClassifier>(std::move(*c)));
}

// --------------------------------------------------------------------------------------
namespace {

/// What the leader shares every replanning (DESIGN §1: human state, leader plan, formation params).
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
struct PlanMessage {
  planning::PlannedTrajectory plan;
  bool fallback = false;
};

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
  double next_plan_s = 0.0;
  std::optional<LeaderShare> share;                           ///< followers: last received from the leader
  std::vector<std::optional<PlanMessage>> received;  ///< plans received from the followers
  int last_status = -1;
  bool in_obstacle = false, in_worker = false;
  bool offline = false;                                      ///< follower dropout in progress
  double rejoined_s = -std::numeric_limits<double>::infinity();  ///< end of the last dropout
  std::string mode = "start";                                ///< last mode recorded (ModeChange)
  std::optional<Eigen::Vector3d> hold_p;                     ///< latched hold point while holding
};

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const auto idx = static_cast<std::size_t>(std::max(0.0, std::ceil(q * static_cast<double>(v.size())) - 1.0));
  return v[std::min(idx, v.size() - 1)];
}

double median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::string describe(const formation::FormationCommand& c, const std::string& target_text) {
  std::ostringstream os;
  os << target_text << '.' << formation::parameterName(c.parameter) << ' '
     << (c.kind == formation::CommandKind::kSet ? "= " : (c.amount >= 0 ? "+" : "")) << c.amount;
  return os.str();
}

void addCounters(MissionMetrics& M, const LinkCounters& c) {
  M.messages_sent += static_cast<long>(c.sent);
  M.messages_lost += static_cast<long>(c.lost);
  M.messages_duplicated += static_cast<long>(c.duplicated);
  M.messages_reordered += static_cast<long>(c.reordered);
}

/// Distance from p to a vertical cylinder (radius r) from z0 to z1 around axis (x, y).
double cylinderDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& feet, double r, double h) {
  const double radial = std::max(0.0, (p - feet).head<2>().norm() - r);
  const double dz = p.z() < feet.z() ? feet.z() - p.z() : (p.z() > feet.z() + h ? p.z() - feet.z() - h : 0.0);
  return std::hypot(radial, dz);
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
  SyntheticSensors sensors(cfg.camera, cfg.stereo, cfg.uwb, world.map, makeRng(seed, Stream::kCamera),
                           makeRng(seed, Stream::kStereo), makeRng(seed, Stream::kUwb));
  estimation::HumanKalman kf(cfg.estimator.filter);
  const estimation::CameraModel cam_model(cfg.estimator.camera);
  gesture::GestureFilter filter(cfg.gesture_filter);
  gesture::SkeletonWindow window;

  // --- UAVs: initial states at the formation references around the worker's start -------
  const WorkerState w0 = worker.stateAt(0.0);
  const double hphi0 = human_heading.heading();
  const formation::UavReference lref0 = formation::leaderReference(w0.p_world, hphi0, cfg.formation.params.leader);
  std::vector<std::unique_ptr<UavRuntime>> uavs;
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

  MissionOutput out;
  MissionMetrics& M = out.metrics;
  M.seed = seed;
  M.min_mutual_distance_m = M.min_obstacle_distance_m = M.min_human_distance_m = std::numeric_limits<double>::infinity();
  std::vector<double> plan_ms;
  double dist_sq = 0.0, angle_sq = 0.0, est_sq = 0.0;
  long dist_n = 0, est_n = 0, frames = 0, visible_frames = 0;
  std::vector<std::vector<bool>> pair_collision(static_cast<std::size_t>(n), std::vector<bool>(static_cast<std::size_t>(n), false));
  std::uint64_t operator_seq = 0, gesture_seq = 0;
  std::size_t next_request = 0;
  int last_class = -1;
  double last_ratio = 0.0, last_skeleton_t = -1e9;
  double last_fused_s = -std::numeric_limits<double>::infinity();  // the leader's last fused worker measurement
  std::mt19937_64 fault_rng = makeRng(seed, Stream::kFault);
  std::uniform_real_distribution<double> u01(0.0, 1.0);

  const double dt = cfg.step_s;
  const long steps = std::lround(duration / dt);
  const double cam_period = 1.0 / cfg.camera.rate_hz;
  const double log_period = 1.0 / cfg.timeline_rate_hz;
  long next_cam_k = 0, next_log_k = 0;
  long cam_count = 0, log_count = 0;
  const double hdt = cfg.horizon_dt_s;
  const int hsteps = cfg.horizon_steps;

  auto applyCommand = [&](RequestRecord& rec, const formation::FormationCommand& cmd, double t) {
    const auto outcome = fstate.apply(cmd);
    if (outcome.status == formation::CommandStatus::kDuplicate) ++M.commands_duplicate;
    if (rec.status == "applied") return;  // a duplicate copy of an applied command changes nothing
    rec.status = formation::toString(outcome.status);
    if (outcome.status == formation::CommandStatus::kApplied) {
      rec.applied_s = t;
      rec.params_version = ++params_version;
      for (const auto& ch : outcome.changes) {
        if (std::find(rec.uavs.begin(), rec.uavs.end(), ch.uav) == rec.uavs.end()) rec.uavs.push_back(ch.uav);
      }
    }
  };

  auto setMode = [&](int i, double t, const std::string& mode, const std::string& reason) {
    UavRuntime& u = *uavs[static_cast<std::size_t>(i)];
    if (u.mode == mode) return;
    u.mode = mode;
    out.modes.push_back(ModeChange{t, i, mode, reason});
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
    std::string hold;  // non-empty: hold a safe position (docs/safety.md), the reason
    if (i == 0) {
      if (!kf.initialized()) {
        ++M.plans_skipped;
        return;
      }
      const estimation::Vector6d& x = kf.state();
      worker_stamp = last_fused_s;
      if (t - worker_stamp > cfg.faults.max_worker_age_s) hold = "worker not seen for more than max_worker_age_s";
      const bool stale = !hold.empty() || kf.lost(t);
      v0 = stale ? Eigen::Vector3d::Zero() : Eigen::Vector3d(x.tail<3>());
      p0 = x.head<3>() + (stale ? 0.0 : (t - kf.time())) * v0;
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
      if (t - share->stamp_s > cfg.faults.max_share_age_s) {
        hold = "leader share older than max_share_age_s";
      } else if (t - worker_stamp > cfg.faults.max_worker_age_s) {
        hold = "worker estimate older than max_worker_age_s";
      } else if (u.rejoined_s > -std::numeric_limits<double>::infinity()) {
        for (int j = 1; j < n && hold.empty(); ++j) {
          const auto& m = u.received[static_cast<std::size_t>(j)];
          if (j != i && !uavs[static_cast<std::size_t>(j)]->offline && (!m || m->plan.t0_s < u.rejoined_s)) {
            hold = "rejoined: waiting for a plan from every other UAV";
          }
        }
        if (hold.empty()) u.rejoined_s = -std::numeric_limits<double>::infinity();
      }
      const bool stale = !hold.empty();
      v0 = stale ? Eigen::Vector3d::Zero() : Eigen::Vector3d(share->v_world);
      p0 = share->p_world + (stale ? 0.0 : (t - share->stamp_s)) * v0;
      hphi = share->human_heading_rad;
      params = share->params;
      version = share->params_version;
    }
    if (!hold.empty()) {
      ++M.plans_hold;
      setMode(i, t, "hold", hold);
    } else {
      setMode(i, t, "track", "fresh data");
    }
    const formation::WorkerHorizon wh = formation::constantVelocityHorizon(p0, v0, hphi, hsteps, hdt);
    planning::PlanRequest req;
    req.uav_index = i;
    req.t_now_s = t;
    req.dt_s = hdt;
    req.state.t_s = t;
    req.state.p_world = u.est.p_world;
    req.state.v_world = u.est.v_world;
    req.state.a_world = u.plant.state().a_world;
    req.state.heading_rad = u.est.heading_rad;
    req.state.pitch_rad = u.est.pitch_rad;
    req.worker = wh;
    if (!hold.empty()) {
      // Hold: stop where braking at the controller's deceleration ends, camera on the last
      // known worker position; the stale data serve only as an obstacle and camera target.
      if (!u.hold_p) u.hold_p = brakingPoint(u.est, cfg.controller.brake_accel_mps2);  // latched: no drift
      req.reference = holdReference(*u.hold_p, p0, u.est.heading_rad, hsteps);
      if (share != nullptr && !share->plan.empty()) req.higher_priority_plans.push_back(share->plan);
      for (int j = 1; j < n; ++j) {
        const auto& m = u.received[static_cast<std::size_t>(j)];
        if (j != i && m && !m->plan.empty()) req.higher_priority_plans.push_back(m->plan);
      }
    } else if (i == 0) {
      u.hold_p.reset();
      formation::leaderHorizon(wh, params.leader, req.reference);
    } else {
      formation::LeaderPlan lp;
      const bool has_plan = !share->plan.empty();
      if (has_plan) {
        lp.heading_rad.resize(1, hsteps);
        lp.pitch_rad.resize(1, hsteps);
        for (int k = 0; k < hsteps; ++k) {
          const auto s = share->plan.sampleAt(t + k * hdt);
          lp.heading_rad(k) = s.heading_rad;
          lp.pitch_rad(k) = s.pitch_rad;
        }
      }
      u.hold_p.reset();
      formation::followerHorizon(wh, params.leader, has_plan ? &lp : nullptr,
                                 params.followers[static_cast<std::size_t>(i - 1)], req.reference);
      if (has_plan) req.higher_priority_plans.push_back(share->plan);
    }
    if (hold.empty()) {
      for (int j = 1; j < n; ++j) {
        const auto& m = u.received[static_cast<std::size_t>(j)];
        // A UAV not heard from for max_plan_age_s (dropout, outage, lost link) cannot be
        // expected to dodge: it has right of way, like one that fell back.
        const bool silent = m && t - m->plan.t0_s > cfg.faults.max_plan_age_s;
        if (j != i && m && !m->plan.empty() && (j < i || m->fallback || silent || cfg.faults.avoid_all_plans)) {
          req.higher_priority_plans.push_back(m->plan);
        }
      }
    }
    const planning::PlanResult res = u.planner->plan(req);
    ++M.plans;
    if (res.status == planning::PlanStatus::kFallbackPrevious) ++M.plans_fallback_previous;
    if (res.status == planning::PlanStatus::kFallbackBrake) ++M.plans_fallback_brake;
    if (res.status != planning::PlanStatus::kOptimized) ++M.plan_failure_reasons[reasonKey(res.reason)];
    plan_ms.push_back(res.timings.total_ms);
    u.last_status = static_cast<int>(res.status);
    if (res.trajectory.empty()) {
      u.ctl.clearPlan();
    } else {
      u.ctl.setPlan(res.trajectory);
    }
    for (auto& rec : out.requests) {
      if (std::isnan(rec.adaptation_start_s) && !std::isnan(rec.applied_s) && version >= rec.params_version &&
          std::find(rec.uavs.begin(), rec.uavs.end(), i) != rec.uavs.end()) {
        rec.adaptation_start_s = t;
      }
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
    while (next_request < cfg.requests.size() && cfg.requests[next_request].t_s <= t + 1e-9) {
      const OperatorRequest& q = cfg.requests[next_request++];
      formation::FormationCommand cmd;
      cmd.id = {"operator", ++operator_seq};
      cmd.source = formation::CommandSource::kOperator;
      cmd.target = q.target;
      cmd.parameter = q.parameter;
      cmd.kind = q.kind;
      cmd.amount = q.amount;
      RequestRecord rec;
      rec.t_s = t;
      rec.source = "operator";
      rec.description = describe(cmd, q.target_text);
      rec.status = "lost";
      out.requests.push_back(rec);
      operator_link.send(t, OperatorMessage{out.requests.size() - 1, t, cmd});
    }
    for (const auto& msg : operator_link.receive(t)) {
      RequestRecord& rec = out.requests[msg.record];
      if (t - msg.sent_s > cfg.faults.max_command_age_s) {  // never act on a command older than its age
        ++M.commands_stale;
        if (rec.status == "lost") rec.status = "stale";
        continue;
      }
      applyCommand(rec, msg.command, t);
    }

    // Follower dropouts: offline → nothing runs; back online → a rebooted computer with no memory.
    for (int i = 1; i < n; ++i) {
      UavRuntime& u = *uavs[static_cast<std::size_t>(i)];
      bool off = false;
      for (const auto& o : cfg.faults.follower_dropouts) off = off || (o.uav == i && t >= o.from_s && t < o.to_s);
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
    if (k >= next_cam_k) {
      ++cam_count;
      next_cam_k = std::lround(static_cast<double>(cam_count) * cam_period / dt);
      const MultirotorState& ls = uavs[0]->plant.state();
      const estimation::CameraPose true_pose = cameraPose(ls.p_world, ls.heading_rad, ls.pitch_rad);
      bool blackout = false;
      for (const auto& [a, b] : cfg.faults.camera_blackouts) blackout = blackout || (t >= a && t < b);
      SensorFrame frame = sensors.observe(true_pose, ws.feet_world, ws.p_world, cfg.worker.height_m, blackout);
      if (inWindow(cfg.faults.uwb_dropouts, t)) frame.d_uwb_m = std::numeric_limits<double>::quiet_NaN();
      if (inWindow(cfg.faults.stereo_dropouts, t)) frame.d_stereo_m = std::numeric_limits<double>::quiet_NaN();
      for (double* d : {&frame.d_uwb_m, &frame.d_stereo_m}) {
        const double u_hit = u01(fault_rng), u_size = u01(fault_rng), u_sign = u01(fault_rng);  // fixed draws per frame
        if (std::isfinite(*d) && u_hit < cfg.faults.range_outliers.probability) {
          const RangeOutlierConfig& ro = cfg.faults.range_outliers;
          const double err = ro.min_error_m + u_size * (ro.max_error_m - ro.min_error_m);
          *d = std::max(0.1, *d + (u_sign < 0.5 ? -err : err));
          ++M.range_outliers;
        }
      }
      const gesture::SynthFrame sk = worker.skeletonAt(t, true_pose.t_world_camera);
      ++frames;
      if (frame.visible()) {
        ++visible_frames;
        const UavRuntime& L = *uavs[0];
        const estimation::CameraPose est_pose = cameraPose(L.est.p_world, L.est.heading_rad, L.est.pitch_rad);
        const auto meas = estimation::makeMeasurement(cam_model, est_pose, frame.box, frame.d_uwb_m, frame.d_stereo_m,
                                                      cfg.estimator.human_height_m, cfg.estimator.noise);
        if (meas && estimation::accepted(kf.step(t, *meas))) last_fused_s = t;
        if (t - last_skeleton_t > 0.5) window.clear();  // a gap breaks the FIFO's temporal consistency
        window.push(sk.skeleton);
        last_skeleton_t = t;
        if (classifier != nullptr && window.full()) {
          const auto c = classifier->classify(window);
          if (c) {
            last_class = c->gesture_id;
            const auto fo = filter.update(t, c->gesture_id);
            last_ratio = fo.dominant_ratio;
            if (fo.fired) {
              RequestRecord rec;
              rec.t_s = t;
              rec.source = "gesture";
              rec.gesture_id = fo.dominant_id;
              const gesture::GestureAction* action = cfg.gesture_mapping.find(fo.dominant_id);
              if (action == nullptr) {
                rec.status = "unmapped";
                rec.description = "gesture " + std::to_string(fo.dominant_id) + " (unmapped)";
                out.requests.push_back(rec);
              } else if (action->kind == gesture::GestureAction::Kind::kEvent) {
                rec.status = "event";
                rec.description = std::string("gesture ") + std::to_string(fo.dominant_id) + " → " + toString(action->event);
                out.requests.push_back(rec);
              } else {
                const auto cmd = gesture::toCommand(*action, ++gesture_seq);
                rec.description = "gesture " + std::to_string(fo.dominant_id) + " → " + describe(cmd, action->parameter_path.substr(0, action->parameter_path.find('.')));
                out.requests.push_back(rec);
                applyCommand(out.requests.back(), cmd, t);
              }
            }
          }
        }
      }
      if (kf.initialized()) {
        const estimation::PredictedSample p = kf.predicted(t);
        est_sq += (p.p_world - ws.p_world).squaredNorm();
        ++est_n;
      }
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
    for (int i = 0; i < n; ++i) {
      UavRuntime& u = *uavs[static_cast<std::size_t>(i)];
      const Eigen::Vector3d& p = u.plant.state().p_world;
      const double r = u.plant.params().body_radius_m;
      const double d_o = obstacleDistance(world, p);
      if (d_o < M.min_obstacle_distance_m) {
        M.min_obstacle_distance_m = d_o;
        M.min_obstacle_uav = i;
        M.min_obstacle_t_s = t;
      }
      const bool in_obstacle = d_o < r;
      if (in_obstacle && !u.in_obstacle) ++M.collisions;
      u.in_obstacle = in_obstacle;
      M.min_human_distance_m = std::min(M.min_human_distance_m, (p - ws.p_world).norm());
      const bool in_worker = cylinderDistance(p, ws.feet_world, 0.3, cfg.worker.height_m) < r;
      if (in_worker && !u.in_worker) ++M.collisions;
      u.in_worker = in_worker;
      for (int j = i + 1; j < n; ++j) {
        const UavRuntime& v = *uavs[static_cast<std::size_t>(j)];
        const double d = (p - v.plant.state().p_world).norm();
        M.min_mutual_distance_m = std::min(M.min_mutual_distance_m, d);
        const bool hit = d < r + v.plant.params().body_radius_m;
        if (hit && !pair_collision[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)]) ++M.collisions;
        pair_collision[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)] = hit;
      }
    }

    // Timeline and tracking errors at the timeline rate.
    if (k >= next_log_k) {
      ++log_count;
      next_log_k = std::lround(static_cast<double>(log_count) * log_period / dt);
      TimelineRow row;
      row.t_s = t;
      row.worker_world = ws.p_world;
      if (kf.initialized()) row.estimate_world = kf.predicted(t).p_world;
      row.visible = visible_frames > 0 && last_skeleton_t > t - 0.2 ? 1 : 0;
      row.gesture_true = worker.performingAt(t);
      row.gesture_class = last_class;
      row.dominant_ratio = last_ratio;
      const formation::FormationParams& P = fstate.params();
      const formation::UavReference lref = formation::leaderReference(ws.p_world, human_heading.heading(), P.leader);
      for (int i = 0; i < n; ++i) {
        const UavRuntime& u = *uavs[static_cast<std::size_t>(i)];
        const MultirotorState& s = u.plant.state();
        const formation::UavReference ref =
            i == 0 ? lref
                   : formation::followerReference(ws.p_world, lref.heading_rad, lref.pitch_rad,
                                                  P.followers[static_cast<std::size_t>(i - 1)]);
        UavSample us;
        us.p_world = s.p_world;
        const Eigen::Vector3d to_worker = ws.p_world - s.p_world;
        us.d_t = to_worker.norm();
        us.d_ref = P.uav(i).distance_m;
        us.d_o = obstacleDistance(world, s.p_world);
        us.phi_deg = radToDeg(std::atan2(to_worker.y(), to_worker.x()));
        us.phi_ref_deg = radToDeg(ref.heading_rad);
        us.elev_deg = radToDeg(std::asin(std::clamp(-to_worker.z() / std::max(1e-9, us.d_t), -1.0, 1.0)));
        us.elev_ref_deg = formation::elevationDeg(P, i);
        us.heading_deg = radToDeg(s.heading_rad);
        us.pitch_deg = radToDeg(s.pitch_rad);
        us.speed_mps = s.v_world.norm();
        us.plan_status = u.last_status;
        row.uavs.push_back(us);
        dist_sq += (us.d_t - us.d_ref) * (us.d_t - us.d_ref);
        const double ae = radToDeg(wrapAngle(common::degToRad(us.phi_deg - us.phi_ref_deg)));
        angle_sq += ae * ae;
        ++dist_n;
        for (int j = i + 1; j < n; ++j) {
          row.mutual_m.push_back((s.p_world - uavs[static_cast<std::size_t>(j)]->plant.state().p_world).norm());
        }
      }
      out.timeline.push_back(std::move(row));
    }

    if (k == steps) break;
    // Control and plant.
    const Eigen::Vector3d w = wind.step(t, dt);
    for (auto& u : uavs) {
      const MultirotorCommand cmd = u->ctl.update(t, dt, u->est);
      u->plant.step(dt, cmd, w, world.ground_height_m);
    }
  }

  // --- gesture metrics: match fired gesture commands to performed gestures ---------------
  out.gestures = worker.episodes();
  std::vector<bool> used(out.gestures.size(), false);
  double latency_sum = 0.0;
  int latency_n = 0;
  for (auto& rec : out.requests) {
    if (rec.source != "gesture") continue;
    for (std::size_t e = 0; e < out.gestures.size(); ++e) {
      const GestureEpisode& ep = out.gestures[e];
      if (!used[e] && ep.gesture_id == rec.gesture_id && ep.start_s <= rec.t_s &&
          rec.t_s - ep.start_s <= cfg.gesture_match_window_s) {
        used[e] = true;
        rec.matched_episode = static_cast<int>(e);
        break;
      }
    }
    if (rec.matched_episode < 0) {
      ++M.false_adaptations;
      continue;
    }
    const GestureEpisode& ep = out.gestures[static_cast<std::size_t>(rec.matched_episode)];
    const double start = std::isnan(rec.adaptation_start_s) ? rec.t_s : rec.adaptation_start_s;
    if (!std::isnan(rec.adaptation_start_s) && rec.adaptation_start_s <= ep.end_s) ++M.gestures_successful;
    latency_sum += start - ep.start_s;
    ++latency_n;
  }
  M.gestures_performed = static_cast<int>(out.gestures.size());
  for (const auto& rec : out.requests) {
    if (rec.status == "applied") {
      ++M.requests_applied;
      (rec.source == "operator" ? M.operator_requests_applied : M.gesture_requests_applied)++;
    }
  }
  M.requests_total = static_cast<int>(cfg.requests.size()) + M.gestures_performed;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  M.gesture_success_rate = M.gestures_performed > 0 ? static_cast<double>(M.gestures_successful) / M.gestures_performed : nan;
  M.gesture_mean_latency_s = latency_n > 0 ? latency_sum / latency_n : nan;
  M.distance_error_rms_m = dist_n > 0 ? std::sqrt(dist_sq / static_cast<double>(dist_n)) : nan;
  M.angle_error_rms_deg = dist_n > 0 ? std::sqrt(angle_sq / static_cast<double>(dist_n)) : nan;
  M.human_estimate_error_rms_m = est_n > 0 ? std::sqrt(est_sq / static_cast<double>(est_n)) : nan;
  for (const auto& l : share_links) addCounters(M, l->counters());
  for (const auto& row : plan_links) {
    for (const auto& l : row) {
      if (l) addCounters(M, l->counters());
    }
  }
  M.planning_ms_median = median(plan_ms);
  M.planning_ms_p99 = percentile(plan_ms, 0.99);
  M.visible_fraction = frames > 0 ? static_cast<double>(visible_frames) / static_cast<double>(frames) : 0.0;
  M.sim_time_s = static_cast<double>(steps) * dt;
  M.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  M.real_time_factor = M.wall_time_s > 0 ? M.sim_time_s / M.wall_time_s : nan;
  return R::ok(std::move(out));
}

Eigen::Vector3d brakingPoint(const EstimatedState& est, double brake_accel_mps2) {
  const double a = std::max(1e-3, brake_accel_mps2);
  return est.p_world + est.v_world * (est.v_world.norm() / (2.0 * a));
}

formation::ReferenceTrajectory holdReference(const Eigen::Vector3d& hold_world, const Eigen::Vector3d& worker_world,
                                             double heading_rad, int steps) {
  const Eigen::Vector3d to_worker = worker_world - hold_world;
  const double horizontal = to_worker.head<2>().norm();
  const double heading = horizontal > 1e-6 ? std::atan2(to_worker.y(), to_worker.x()) : heading_rad;
  const double pitch = std::atan2(to_worker.z(), std::max(1e-6, horizontal));
  formation::ReferenceTrajectory ref;
  ref.resize(steps);
  for (int k = 0; k < steps; ++k) {
    ref.p_world.col(k) = hold_world;
    ref.heading_rad(k) = heading;
    ref.pitch_rad(k) = pitch;
  }
  return ref;
}

// --------------------------------------------------------------------------------------
std::string metricsJson(const MissionMetrics& m) {
  std::ostringstream os;
  auto num = [](double v) { return std::isfinite(v) ? formatDouble(v) : std::string("null"); };
  os << "{\n";
  os << "  \"min_mutual_distance_m\": " << num(m.min_mutual_distance_m) << ",\n";
  os << "  \"min_obstacle_distance_m\": " << num(m.min_obstacle_distance_m) << ",\n";
  os << "  \"min_obstacle_uav\": " << m.min_obstacle_uav << ",\n";
  os << "  \"min_obstacle_t_s\": " << num(m.min_obstacle_t_s) << ",\n";
  os << "  \"min_human_distance_m\": " << num(m.min_human_distance_m) << ",\n";
  os << "  \"collisions\": " << m.collisions << ",\n";
  os << "  \"distance_error_rms_m\": " << num(m.distance_error_rms_m) << ",\n";
  os << "  \"angle_error_rms_deg\": " << num(m.angle_error_rms_deg) << ",\n";
  os << "  \"requests_applied\": " << m.requests_applied << ",\n";
  os << "  \"gesture_success_rate\": " << num(m.gesture_success_rate) << ",\n";
  os << "  \"gesture_mean_latency_s\": " << num(m.gesture_mean_latency_s) << ",\n";
  os << "  \"false_adaptations\": " << m.false_adaptations << ",\n";
  os << "  \"planning_ms_median\": " << num(m.planning_ms_median) << ",\n";
  os << "  \"planning_ms_p99\": " << num(m.planning_ms_p99) << ",\n";
  os << "  \"human_estimate_error_rms_m\": " << num(m.human_estimate_error_rms_m) << ",\n";
  os << "  \"requests_total\": " << m.requests_total << ",\n";
  os << "  \"operator_requests_applied\": " << m.operator_requests_applied << ",\n";
  os << "  \"gesture_requests_applied\": " << m.gesture_requests_applied << ",\n";
  os << "  \"gestures_performed\": " << m.gestures_performed << ",\n";
  os << "  \"gestures_successful\": " << m.gestures_successful << ",\n";
  os << "  \"plans\": " << m.plans << ",\n";
  os << "  \"plans_fallback_previous\": " << m.plans_fallback_previous << ",\n";
  os << "  \"plans_fallback_brake\": " << m.plans_fallback_brake << ",\n";
  os << "  \"plans_skipped\": " << m.plans_skipped << ",\n";
  os << "  \"plans_hold\": " << m.plans_hold << ",\n";
  os << "  \"commands_stale\": " << m.commands_stale << ",\n";
  os << "  \"commands_duplicate\": " << m.commands_duplicate << ",\n";
  os << "  \"range_outliers\": " << m.range_outliers << ",\n";
  os << "  \"messages_sent\": " << m.messages_sent << ",\n";
  os << "  \"messages_lost\": " << m.messages_lost << ",\n";
  os << "  \"messages_duplicated\": " << m.messages_duplicated << ",\n";
  os << "  \"messages_reordered\": " << m.messages_reordered << ",\n";
  os << "  \"visible_fraction\": " << num(m.visible_fraction) << ",\n";
  os << "  \"sim_time_s\": " << num(m.sim_time_s) << ",\n";
  os << "  \"seed\": " << m.seed << ",\n";
  os << "  \"wall_time_s\": " << num(m.wall_time_s) << ",\n";
  os << "  \"real_time_factor\": " << num(m.real_time_factor) << ",\n";
  os << "  \"wall_clock_keys\": [\"planning_ms_median\", \"planning_ms_p99\", \"wall_time_s\", \"real_time_factor\"]\n";
  os << "}\n";
  return os.str();
}

bool writeTimelineCsv(const std::string& path, const MissionOutput& out, int uav_count, std::string* error) {
  std::ofstream f(path);
  if (!f) {
    if (error) *error = path + ": cannot open for writing";
    return false;
  }
  f << "t,worker_x,worker_y,worker_z,est_x,est_y,est_z,visible,gesture_true,gesture_class,dominant_ratio";
  for (int i = 0; i < uav_count; ++i) {
    const std::string u = formation::uavLabel(i) + "_";
    for (const char* c : {"x", "y", "z", "d_t", "d_ref", "d_o", "phi_deg", "phi_ref_deg", "elev_deg", "elev_ref_deg",
                          "heading_deg", "pitch_deg", "speed", "plan_status"}) {
      f << ',' << u << c;
    }
  }
  for (int i = 0; i < uav_count; ++i) {
    for (int j = i + 1; j < uav_count; ++j) f << ",d_m_" << formation::uavLabel(i) << '_' << formation::uavLabel(j);
  }
  f << '\n';
  for (const auto& r : out.timeline) {
    f << formatDouble(r.t_s);
    for (int k = 0; k < 3; ++k) f << ',' << formatDouble(r.worker_world(k));
    for (int k = 0; k < 3; ++k) f << ',' << formatDouble(r.estimate_world(k));
    f << ',' << r.visible << ',' << r.gesture_true << ',' << r.gesture_class << ',' << formatDouble(r.dominant_ratio);
    for (const auto& u : r.uavs) {
      for (int k = 0; k < 3; ++k) f << ',' << formatDouble(u.p_world(k));
      for (double v : {u.d_t, u.d_ref, u.d_o, u.phi_deg, u.phi_ref_deg, u.elev_deg, u.elev_ref_deg, u.heading_deg,
                       u.pitch_deg, u.speed_mps}) {
        f << ',' << formatDouble(v);
      }
      f << ',' << u.plan_status;
    }
    for (double d : r.mutual_m) f << ',' << formatDouble(d);
    f << '\n';
  }
  f.flush();
  if (!f) {
    if (error) *error = path + ": write failed";
    return false;
  }
  return true;
}

bool writeEventsCsv(const std::string& path, const MissionOutput& out, std::string* error) {
  std::ofstream f(path);
  if (!f) {
    if (error) *error = path + ": cannot open for writing";
    return false;
  }
  f << "t,source,description,status,applied_t,adaptation_start_t,gesture_id,gesture_start_t,gesture_end_t,uavs\n";
  for (const auto& r : out.requests) {
    std::string uavs;
    for (std::size_t i = 0; i < r.uavs.size(); ++i) uavs += (i ? ";" : "") + formation::uavLabel(r.uavs[i]);
    double gs = std::numeric_limits<double>::quiet_NaN(), ge = gs;
    if (r.matched_episode >= 0) {
      gs = out.gestures[static_cast<std::size_t>(r.matched_episode)].start_s;
      ge = out.gestures[static_cast<std::size_t>(r.matched_episode)].end_s;
    }
    std::string desc = r.description;
    std::replace(desc.begin(), desc.end(), ',', ';');
    f << formatDouble(r.t_s) << ',' << r.source << ',' << desc << ',' << r.status << ',' << formatDouble(r.applied_s)
      << ',' << formatDouble(r.adaptation_start_s) << ',' << r.gesture_id << ',' << formatDouble(gs) << ','
      << formatDouble(ge) << ',' << uavs << '\n';
  }
  // Performed gestures that never fired anything.
  for (std::size_t e = 0; e < out.gestures.size(); ++e) {
    bool matched = false;
    for (const auto& r : out.requests) matched = matched || r.matched_episode == static_cast<int>(e);
    if (!matched) {
      const auto& g = out.gestures[e];
      f << formatDouble(g.start_s) << ",worker,gesture " << g.gesture_id << " not recognised,missed,nan,nan,"
        << g.gesture_id << ',' << formatDouble(g.start_s) << ',' << formatDouble(g.end_s) << ",\n";
    }
  }
  f.flush();
  if (!f) {
    if (error) *error = path + ": write failed";
    return false;
  }
  return true;
}

bool writeModesCsv(const std::string& path, const MissionOutput& out, std::string* error) {
  std::ofstream f(path);
  if (!f) {
    if (error) *error = path + ": cannot open for writing";
    return false;
  }
  f << "t,uav,mode,reason\n";
  for (const auto& m : out.modes) {
    std::string why = m.reason;
    std::replace(why.begin(), why.end(), ',', ';');
    f << formatDouble(m.t_s) << ',' << formation::uavLabel(m.uav) << ',' << m.mode << ',' << why << '\n';
  }
  f.flush();
  if (!f) {
    if (error) *error = path + ": write failed";
    return false;
  }
  return true;
}

}  // namespace gesture_formation::sim

#include "gesture_formation/sim/mission_runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <sstream>

#include <Eigen/Geometry>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/estimation/camera_model_source.hpp"
#include "gesture_formation/estimation/human_kalman.hpp"
#include "gesture_formation/estimation/measurement_model.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/formation/worker_heading.hpp"
#include "gesture_formation/gesture/gesture_frames.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/replan_step.hpp"
#include "gesture_formation/sim/leader_handover.hpp"
#include "gesture_formation/sim/random.hpp"
#include "gesture_formation/sim/site_mapping.hpp"
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
  int from = 0;  ///< the sending (acting) leader
};

/// What a UAV sends every replanning period (the ROS PlannedTrajectory and the LcmBridge's
/// heartbeat over LCM).
struct PlanMessage {
  /// The plan with its planner status: a UAV that could not plan (braking or on its previous plan)
  /// is avoided by every other UAV, also higher-priority ones (right of way). None: its planner
  /// did not run (an outage), only the abort below goes out.
  std::optional<planning::ReceivedPlan> plan;
  /// The abort this UAV accepted, relayed every period from then on, planner or not (the
  /// repetition that reaches a UAV across losses, outages and restarts; docs/safety.md §2.8).
  std::optional<planning::AbortCommand> abort;
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
  std::unique_ptr<planning::ReplanStep> step;  ///< the product's replanning step (planner, hold, listening)
  EstimatedState est;
  WindEstimate wind_estimate;  ///< the flight stack's wind estimate (planning's wind allowance)
  double next_plan_s = 0.0;
  std::optional<LeaderShare> share;                           ///< followers: last received from the leader
  std::vector<std::optional<planning::ReceivedPlan>> received;  ///< plans received from the other UAVs
  bool offline = false;                                      ///< follower dropout in progress
  std::string mode = "start";                                ///< last mode recorded (ModeChange)
};

/// The world's obstacle distance: the mapped solids, and the unmapped obstacles (site_mapping.hpp).
ObstacleDistance obstacleDistance(const MissionWorld& w) {
  const ObstacleDistance mapped{w.field, w.solids, w.ground_height_m};
  return w.site != nullptr ? w.site->withUnmapped(mapped) : mapped;
}

void addCounters(MissionMetrics& M, const LinkCounters& c) {
  M.messages_sent += static_cast<long>(c.sent);
  M.messages_lost += static_cast<long>(c.lost);
  M.messages_duplicated += static_cast<long>(c.duplicated);
  M.messages_reordered += static_cast<long>(c.reordered);
}

/// One simulated mission (docs/simulation.md): the world, the UAVs and their links, stepped at
/// cfg.step_s. Each step: operator messages, dropouts, inter-UAV messages, odometry, the leader's
/// camera frame, replanning, safety sampling, the timeline, control. Members are declared in the
/// order they were always created (their random streams depend on it).
class MissionRun {
 public:
  MissionRun(const MissionConfig& cfg, const MissionWorld& world, const PlannerFactory& planners,
             MissionClassifier* classifier, std::uint64_t seed, formation::FormationState fstate, CameraSource* camera)
      : cfg_(cfg),
        world_(world),
        planners_(planners),
        classifier_(classifier),
        seed_(seed),
        n_(cfg.formation.params.uavCount()),
        fstate_(std::move(fstate)),
        worker_(cfg.worker, mixSeed(seed ^ static_cast<std::uint64_t>(Stream::kWorker))),
        wind_(cfg.wind, makeRng(seed, Stream::kWind)),
        own_camera_(camera != nullptr ? nullptr : std::make_unique<LeaderCamera>(cfg, world.map, seed)),
        camera_(camera != nullptr ? *camera : *own_camera_),
        kf_(cfg.estimator.filter),
        cam_model_(estimation::IntrinsicsSource::kCameraInfo, cfg.estimator.camera),
        // The formation's cameras vote (docs/gestures.md §4.1); min_agreeing_views 1 = the
        // paper's pipeline on the leader's camera alone.
        follower_views_(cfg.view_fusion.min_agreeing_views > 1),
        frames_(cfg.gesture_filter, cfg.view_fusion, cfg.gesture_mapping, n_, 0.0),
        operator_link_(cfg.operator_link, makeRng(seed, Stream::kLink, link_index_++)),
        metrics_(cfg, obstacleDistance(world), seed),
        M_(metrics_.counters()),
        schedule_(cfg.requests, "operator") {}

  /// UAVs at the formation references around the worker's start; empty or why not.
  std::string addUavs();
  void openLinks();
  /// The leadership's links and those a leader other than UAV 0 needs (leader_handover.hpp).
  void openHandoverLinks();
  MissionOutput run(double duration_s, std::chrono::steady_clock::time_point wall0);

 private:
  UavRuntime& uav(int i) { return *uavs_[static_cast<std::size_t>(i)]; }
  bool silentAt(int i, double t) const;
  int slotOf(int i);
  void stepLeadership(double t);
  void takeOver(int k, double t);
  Link<LeaderShare>& shareLink(int from, int to);
  Link<gesture::ViewObservation>* voteLink(int from, int to);
  Link<OperatorMessage>& operatorLink(int to);
  void receiveShare(int i, LeaderShare s);
  void deliverOperatorMessages(double t);
  void updateDropouts(double t);
  void deliverUavMessages(double t);
  void cameraFrame(double t, const WorkerState& ws);
  gesture::ViewObservation observation(int uav_index, int view, double t, const gesture::Classification& c,
                                       const gesture::CalibratedSkeleton& cal,
                                       const std::optional<Eigen::Vector3d>& worker_est);
  std::vector<gesture::GestureFrame> aggregateViews(double t, const LeaderCameraFrame& cf);
  void actOnFrames(double t, const std::vector<gesture::GestureFrame>& closed);
  /// One closed frame into votes_ (the readings noted for its stamp, the vote, the filter).
  void recordVote(const gesture::GestureFrame& f);
  void replanDue(double t);
  void replan(int i, double t);
  /// UAV i's accepted abort, alone, to every other UAV (its planner did not run).
  void relayAbort(int i, double t);
  void sendPlan(int i, double t, const planning::ReplanOutcome& out, const formation::FormationParams& params,
                std::uint64_t version);
  void sampleTimeline(double t, const WorkerState& ws);
  void control(double t, double dt);
  void applyCommand(std::size_t record, const formation::FormationCommand& cmd, double t);
  void applyOperatorMessage(const OperatorMessage& msg, double t);
  /// A command sent at `sent_s` is older than faults.max_command_age_s at `t`: counted, its record "stale".
  bool staleAt(std::size_t record, double sent_s, double t);
  void setMode(int i, double t, const std::string& mode, const std::string& reason);
  void deliverAbort(double t);
  void receiveAbort(int i, const planning::AbortCommand& command, double t);
  void divertWorker(double t);

  const MissionConfig& cfg_;
  const MissionWorld& world_;
  const PlannerFactory& planners_;
  MissionClassifier* classifier_;
  std::uint64_t seed_;
  int n_;
  formation::FormationState fstate_;
  std::uint64_t params_version_ = 0;
  WorkerModel worker_;
  WindModel wind_;
  std::unique_ptr<LeaderCamera> own_camera_;  ///< the synthetic camera, when no other was given
  CameraSource& camera_;
  estimation::HumanKalman kf_;
  /// The estimator's camera model: the leader camera's own intrinsics, from its frames (as the
  /// WorkerEstimator nodelet takes them from CameraInfo).
  estimation::CameraModelSource cam_model_;
  bool follower_views_;
  gesture::GestureFrames frames_;
  std::vector<std::unique_ptr<UavRuntime>> uavs_;
  std::uint64_t link_index_ = 0;
  Link<OperatorMessage> operator_link_;
  std::vector<std::unique_ptr<Link<LeaderShare>>> share_links_;  // [i]: leader → follower i
  std::vector<std::vector<std::unique_ptr<Link<PlanMessage>>>> plan_links_;  // [i][j]: i → j
  std::vector<std::unique_ptr<Link<gesture::ViewObservation>>> vote_links_;  // [i]: follower i → leader
  std::vector<std::unique_ptr<Link<planning::AbortCommand>>> abort_links_;   // [i]: ground station → UAV i
  AbortSender abort_sender_{cfg_.faults.abort, cfg_.replan.abort.repeats, cfg_.replan.abort.repeat_period_s,
                            cfg_.replan.abort.resend_period_s};
  std::optional<AbortRecorder> abort_record_;
  std::optional<ApproachRecorder> approach_record_;  ///< faults.worker_approach
  AssistanceDrill assistance_{cfg_.assistance_acks_s};  ///< the acting leader's latch (docs/safety.md §2.10)
  bool diverted_ = false;                            ///< the worker left his route (faults.worker_approach)
  MetricsAccumulator metrics_;
  MissionMetrics& M_;
  std::vector<ModeChange> modes_;
  std::map<double, std::vector<int>> frame_views_;  ///< per open frame stamp: each UAV's reading that reached the vote
  std::vector<VoteRecord> votes_;                   ///< votes.csv
  std::uint64_t gesture_seq_ = 0;
  OperatorSchedule schedule_;
  int last_class_ = -1;
  double last_ratio_ = 0.0;
  double last_fused_s_ = -std::numeric_limits<double>::infinity();  // the leader's last fused worker measurement
  std::optional<planning::WorkerKnowledge> leader_knowledge_;        // the leader's last confirmed estimate
  // Leader hand-over (leader_handover.hpp): the estimator, the gesture frames, the FormationState
  // and the share are the work of owner_, the UAV that acted as leader last; its outputs (share,
  // commands, the abort relay) go out only while it acts.
  std::unique_ptr<LeadershipNet> lead_;
  std::optional<HandoverRecorder> handover_;
  std::vector<bool> acting_;  ///< per UAV, at the current step
  /// Per UAV: when its own camera last detected the worker (the leader's camera or its follower
  /// view; −inf: never) — with its share, the freshness it brings to an election.
  std::vector<double> own_seen_s_;
  /// What the leader (owner_) received or fired while its lease had lapsed in the term it acts in —
  /// operator requests, its gesture commands and assistance requests — and that term: each applied
  /// (with the time then) if it acts again in that term (onboard::ParamsOwnership::keepsCommand).
  std::vector<std::function<void(double)>> kept_;
  std::uint32_t kept_term_ = 0;
  std::uint32_t owner_term_ = 0;  ///< the term in which owner_ last acted
  int owner_ = 0;
  double took_over_s_ = -std::numeric_limits<double>::infinity();  ///< commands sent before are the previous leader's
  int silenced_ = -1;                                                ///< faults.leader_silence's UAV
  std::uint64_t handover_link_index_ = 0;
  std::vector<std::unique_ptr<Link<OperatorMessage>>> operator_links_;            // [i]: ground station → UAV i ≥ 1
  std::vector<std::vector<std::unique_ptr<Link<LeaderShare>>>> share_from_;      // [from ≥ 1][to]
  std::vector<std::vector<std::unique_ptr<Link<gesture::ViewObservation>>>> vote_to_;  // [to ≥ 1][from]
};

std::string MissionRun::addUavs() {
  const WorkerState w0 = worker_.stateAt(0.0);
  const double hphi0 = formation::WorkerHeading(cfg_.formation.worker_heading).heading();
  const formation::UavReference lref0 = formation::leaderReference(w0.p_world, hphi0, cfg_.formation.params.leader);
  for (int i = 0; i < n_; ++i) {
    const formation::UavReference ref =
        i == 0 ? lref0
               : formation::followerReference(w0.p_world, lref0.heading_rad, lref0.pitch_rad,
                                              cfg_.formation.params.followers[static_cast<std::size_t>(i - 1)]);
    MultirotorState s0;
    s0.p_world = cfg_.uavs[static_cast<std::size_t>(i)].initial_position.value_or(ref.p_world);
    s0.heading_rad = ref.heading_rad;
    s0.pitch_rad = ref.pitch_rad;
    const double clearance = world_.field->clearance(s0.p_world);
    if (clearance < cfg_.planner.path_clearance_m) {
      std::ostringstream os;
      os << cfg_.source << ": mission.uavs[" << i << "].initial_position: (" << s0.p_world.transpose()
         << ") has clearance " << clearance << " m < planner path_clearance_m " << cfg_.planner.path_clearance_m
         << " (set an initial_position in free space)";
      return os.str();
    }
    auto u = std::make_unique<UavRuntime>(cfg_.uavs[static_cast<std::size_t>(i)], cfg_, s0, seed_, i);
    planning::ReplanConfig rc = cfg_.replan;
    rc.uav_index = i;
    rc.uav_count = n_;
    rc.worker_heading = cfg_.formation.worker_heading;
    rc.formation_limits = cfg_.formation.limits;
    rc.reach.worker_min_distance_m = cfg_.formation.limits.safety_distance_m;  // Γ_dis: the reach keeps it
    rc.home_world = s0.p_world;  // the mission starts in the air: its take-off point is where it starts
    planning::RetreatSpace space;
    space.field = world_.site != nullptr && world_.site->field(i) != nullptr ? world_.site->field(i) : world_.field;
    if (world_.map != nullptr) {
      space.bounds = world_.map->gridBounds();
      space.resolution_m = world_.map->resolution();
    } else {
      space.bounds = planning::Aabb{Eigen::Vector3d::Constant(-1e6), Eigen::Vector3d::Constant(1e6)};
    }
    space.ground_height_m = world_.ground_height_m;
    u->step = std::make_unique<planning::ReplanStep>(rc, planners_(i), space);
    u->next_plan_s = cfg_.replanning_period_s * static_cast<double>(i) / static_cast<double>(n_);
    u->received.resize(static_cast<std::size_t>(n_));
    uavs_.push_back(std::move(u));
  }
  return {};
}

void MissionRun::openLinks() {
  const auto n = static_cast<std::size_t>(n_);
  // The map-update links (mission.mapping.share; own random streams: the others' are unchanged).
  if (world_.site != nullptr) world_.site->openShareLinks(cfg_.link, seed_);
  plan_links_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    share_links_.push_back(std::make_unique<Link<LeaderShare>>(cfg_.link, makeRng(seed_, Stream::kLink, link_index_++)));
    plan_links_[i].resize(n);
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      plan_links_[i][j] = std::make_unique<Link<PlanMessage>>(cfg_.link, makeRng(seed_, Stream::kLink, link_index_++));
    }
  }
  // Follower gesture votes → the leader over the same lossy link (the ROS system: ViewObserver →
  // LcmBridge → the leader's GestureCommander). Created after the other links: their random
  // streams are unchanged.
  vote_links_.resize(n);
  for (std::size_t i = 1; follower_views_ && i < n; ++i) {
    vote_links_[i] =
        std::make_unique<Link<gesture::ViewObservation>>(cfg_.link, makeRng(seed_, Stream::kLink, link_index_++));
  }
  // The ground station's abort → every UAV, over the operator link's model. Created last: the
  // other links' random streams are unchanged.
  if (!cfg_.faults.abort) return;
  for (std::size_t i = 0; i < n; ++i) {
    abort_links_.push_back(
        std::make_unique<Link<planning::AbortCommand>>(cfg_.operator_link, makeRng(seed_, Stream::kLink, link_index_++)));
  }
  abort_record_.emplace(*cfg_.faults.abort, n_, obstacleDistance(world_));
}

void MissionRun::openHandoverLinks() {
  // Own random streams (Stream::kHandover): the other links' draws are unchanged.
  const auto next = [this] { return makeRng(seed_, Stream::kHandover, handover_link_index_++); };
  formation::LeadershipConfig lc = cfg_.leadership;
  lc.uav_count = n_;
  std::vector<std::mt19937_64> rngs;
  for (int i = 0; i < n_ * (n_ - 1); ++i) rngs.push_back(next());
  lead_ = std::make_unique<LeadershipNet>(lc, cfg_.link, std::move(rngs), cfg_.step_s);
  handover_.emplace(n_);
  acting_.assign(static_cast<std::size_t>(n_), false);
  own_seen_s_.assign(static_cast<std::size_t>(n_), -std::numeric_limits<double>::infinity());
  const auto n = static_cast<std::size_t>(n_);
  operator_links_.resize(n);
  share_from_.resize(n);
  vote_to_.resize(n);
  for (std::size_t i = 1; i < n; ++i) {
    operator_links_[i] = std::make_unique<Link<OperatorMessage>>(cfg_.operator_link, next());
    share_from_[i].resize(n);
    vote_to_[i].resize(n);
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      share_from_[i][j] = std::make_unique<Link<LeaderShare>>(cfg_.link, next());
      if (follower_views_) vote_to_[i][j] = std::make_unique<Link<gesture::ViewObservation>>(cfg_.link, next());
    }
  }
}

Link<LeaderShare>& MissionRun::shareLink(int from, int to) {
  return from == 0 ? *share_links_[static_cast<std::size_t>(to)]
                   : *share_from_[static_cast<std::size_t>(from)][static_cast<std::size_t>(to)];
}

Link<gesture::ViewObservation>* MissionRun::voteLink(int from, int to) {
  return to == 0 ? vote_links_[static_cast<std::size_t>(from)].get()
                 : vote_to_[static_cast<std::size_t>(to)][static_cast<std::size_t>(from)].get();
}

Link<OperatorMessage>& MissionRun::operatorLink(int to) {
  return to == 0 ? operator_link_ : *operator_links_[static_cast<std::size_t>(to)];
}

int MissionRun::slotOf(int i) {
  // The leader flies the leader's slot; a follower its own; UAV 0, which has none, the slot its
  // successor left (the share's sender's); −1: none yet.
  const UavRuntime& u = uav(i);
  return i == owner_ ? 0 : (i != 0 ? i : (u.share ? u.share->from : -1));
}

bool MissionRun::silentAt(int i, double t) const {
  return silenced_ == i && cfg_.faults.leader_silence && cfg_.faults.leader_silence->silentAt(t);
}

void MissionRun::stepLeadership(double t) {
  // faults.leader_silence: at its time the acting leader (else the UAV doing the leader's work) goes silent.
  const std::optional<LeaderSilence>& silence = cfg_.faults.leader_silence;
  if (silence && silenced_ < 0 && t >= silence->t_s) {
    silenced_ = owner_;
    for (int i = 0; i < n_; ++i) {
      if (acting_[static_cast<std::size_t>(i)]) silenced_ = i;
    }
    handover_->silenced(silenced_, t, *silence);
  }
  std::vector<double> age(static_cast<std::size_t>(n_), std::numeric_limits<double>::infinity());
  std::vector<bool> up(static_cast<std::size_t>(n_), true);
  for (int i = 0; i < n_; ++i) {
    const UavRuntime& u = uav(i);
    // The freshest worker evidence the UAV would lead with: the leader's own fusion; another UAV's
    // share or its own camera's last detection (its estimator fuses that camera once it leads).
    const double fused = i == owner_ ? last_fused_s_ : (u.share ? u.share->worker.fused_s : std::nan(""));
    if (std::isfinite(fused)) age[static_cast<std::size_t>(i)] = std::max(0.0, t - fused);
    const double seen = own_seen_s_[static_cast<std::size_t>(i)];
    if (i != owner_ && std::isfinite(seen)) age[static_cast<std::size_t>(i)] = std::min(age[static_cast<std::size_t>(i)], std::max(0.0, t - seen));
    up[static_cast<std::size_t>(i)] = !silentAt(i, t) && !cfg_.faults.followerOffline(i, t);
  }
  lead_->step(t, age, up);
  for (int i = 0; i < n_; ++i) acting_[static_cast<std::size_t>(i)] = lead_->acting(i, t);
  for (int i = 0; i < n_; ++i) {
    if (acting_[static_cast<std::size_t>(i)] && i != owner_) takeOver(i, t);
  }
  handover_->sample(t, acting_);
}

void MissionRun::takeOver(int k, double t) {
  // A new leader: its estimator starts from the last share it received (then fuses its own
  // camera), the parameters and their version from that share, fresh gesture frames and filter
  // that wait for the gesture in progress to be released.
  owner_ = k;
  took_over_s_ = t;
  kept_.clear();  // its predecessor's
  owner_term_ = lead_->member(k).term();
  const UavRuntime& u = uav(k);
  kf_ = estimation::HumanKalman(cfg_.estimator.filter);
  leader_knowledge_.reset();
  last_fused_s_ = -std::numeric_limits<double>::infinity();
  if (u.share) {
    const planning::WorkerKnowledge& w = u.share->worker;
    const double fused = std::isfinite(w.fused_s) ? std::min(w.fused_s, w.stamp_s) : w.stamp_s;
    if (kf_.adopt(w.stamp_s, w.p_world, w.lost ? Eigen::Vector3d::Zero() : w.v_world, Eigen::Matrix3d::Identity(), fused)) {
      last_fused_s_ = w.fused_s;
    }
    auto fs = formation::FormationState::create(u.share->params, cfg_.formation.limits, cfg_.formation.duplicates);
    if (fs) {
      fstate_ = std::move(*fs);
      params_version_ = u.share->params_version;
    }
  }
  frames_ = gesture::GestureFrames(cfg_.gesture_filter, cfg_.view_fusion, cfg_.gesture_mapping, n_, 0.0);
  frames_.awaitRelease();  // its predecessor may have fired for the performance in progress
  frame_views_.clear();
  assistance_.leaderChanged();
  modes_.push_back(ModeChange{t, k, uav(k).mode, "acting as leader (term " + std::to_string(lead_->member(k).term()) +
                                                     "): estimator, gestures, parameters and share taken over"});
}

MissionOutput MissionRun::run(double duration_s, std::chrono::steady_clock::time_point wall0) {
  const double dt = cfg_.step_s;
  const long steps = std::lround(duration_s / dt);
  StepSchedule camera_frames(1.0 / cfg_.camera.rate_hz, dt);
  StepSchedule timeline_samples(1.0 / cfg_.timeline_rate_hz, dt);
  for (long k = 0; k <= steps; ++k) {
    const double t = static_cast<double>(k) * dt;
    divertWorker(t);
    const WorkerState ws = worker_.stateAt(t);
    stepLeadership(t);
    deliverOperatorMessages(t);
    deliverAbort(t);
    updateDropouts(t);
    deliverUavMessages(t);
    // Odometry of every UAV at this step (used by sensing, planning and control).
    for (auto& u : uavs_) u->est = u->odo.measure(u->plant.state(), dt);
    if (world_.site != nullptr) {  // the unmapped obstacles' clock and the UAVs' depth frames (site_mapping.hpp)
      std::vector<MultirotorState> truth;
      std::vector<bool> offline;
      for (const auto& u : uavs_) {
        truth.push_back(u->plant.state());
        offline.push_back(u->offline);
      }
      world_.site->step(t, truth, offline);
    }
    if (camera_frames.due(k)) cameraFrame(t, ws);
    replanDue(t);
    // Safety metrics at every step (true states).
    std::vector<Eigen::Vector3d> p_true;
    for (const auto& u : uavs_) p_true.push_back(u->plant.state().p_world);
    metrics_.sampleSafety(t, p_true, ws);
    if (abort_record_) abort_record_->sample(t, p_true, ws.p_world);
    if (approach_record_) approach_record_->sample(t, p_true, ws.p_world);
    if (timeline_samples.due(k)) sampleTimeline(t, ws);
    if (k == steps) break;
    control(t, dt);
  }
  for (const auto& l : share_links_) addCounters(M_, l->counters());
  for (const auto& row : share_from_) {
    for (const auto& l : row) {
      if (l) addCounters(M_, l->counters());
    }
  }
  for (const auto& row : vote_to_) {
    for (const auto& l : row) {
      if (l) addCounters(M_, l->counters());
    }
  }
  for (const auto& l : vote_links_) {
    if (l) addCounters(M_, l->counters());
  }
  for (const auto& row : plan_links_) {
    for (const auto& l : row) {
      if (l) addCounters(M_, l->counters());
    }
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  MissionOutput out = metrics_.finish(worker_.episodes(), static_cast<double>(steps) * dt, wall_s);
  out.modes = std::move(modes_);
  out.votes = std::move(votes_);
  if (abort_record_) out.metrics.abort = abort_record_->summary();
  if (approach_record_) out.metrics.worker_approach = approach_record_->summary();
  out.metrics.assistance = assistance_.summary();
  if (world_.site != nullptr) out.metrics.site_mapping = world_.site->summary();
  std::vector<std::pair<double, bool>> operator_requests;
  for (const RequestRecord& r : out.requests) {
    if (r.source == "operator") operator_requests.emplace_back(r.t_s, r.status == "applied");
  }
  out.metrics.leadership = handover_->finish(static_cast<double>(steps) * dt, operator_requests, *lead_);
  if (const std::vector<PerceptionRecord>* records = camera_.perceptionRecords()) {
    out.perception = *records;
    out.metrics.perception = summarizePerception(*records);
  }
  return out;
}

void MissionRun::deliverOperatorMessages(double t) {
  // Operator requests → operator link → the leader's FormationState.
  // The ground station sends to every UAV; only the acting leader applies, and a new leader only
  // what was sent after it took over (older commands were its predecessor's, and the parameters
  // it took over carry those it applied).
  // The operator's acknowledgement of an assistance request reaches the leader while it acts (the
  // ground station repeats it until then).
  if (acting_[static_cast<std::size_t>(owner_)] && !uav(owner_).offline) assistance_.acknowledgeDue(t);
  // A leader whose lease lapsed keeps what reaches it meanwhile; acting again in the term in which it
  // last acted (nobody else can have acted: a new leader needs a newer term) it applies those still
  // within max_command_age_s of their sending — as the FormationPlanner's ParamsOwnership does.
  const std::uint32_t owner_term = lead_->member(owner_).term();
  if (acting_[static_cast<std::size_t>(owner_)]) {
    if (owner_term == kept_term_ && owner_term == owner_term_) {
      for (const auto& apply : kept_) apply(t);
    }
    kept_.clear();
    owner_term_ = owner_term;
  }
  for (const auto& d : schedule_.due(t)) {
    const OperatorMessage msg{metrics_.addRequest(d.record), t, d.command};
    for (int i = 0; i < n_; ++i) {
      if (!cfg_.faults.operatorLinkDown(i, t)) operatorLink(i).send(t, msg);
    }
  }
  for (int i = 0; i < n_; ++i) {
    for (const auto& msg : operatorLink(i).receive(t)) {
      if (uav(i).offline || i != owner_ || msg.sent_s < took_over_s_) continue;
      if (acting_[static_cast<std::size_t>(i)]) {
        applyOperatorMessage(msg, t);
      } else if (owner_term == owner_term_) {  // its lease lapsed in the term in which it acts
        kept_.push_back([this, msg](double now) { applyOperatorMessage(msg, now); });
        kept_term_ = owner_term;
      }
    }
  }
}

bool MissionRun::staleAt(std::size_t record, double sent_s, double t) {
  if (t - sent_s <= cfg_.faults.max_command_age_s) return false;  // never act on a command older than its age
  ++M_.commands_stale;
  RequestRecord& rec = metrics_.request(record);
  if (rec.status == "lost") rec.status = "stale";
  return true;
}

void MissionRun::applyOperatorMessage(const OperatorMessage& msg, double t) {
  if (staleAt(msg.record, msg.sent_s, t)) return;
  if (assistance_.refusal(formation::CommandSource::kOperator)) return;  // never: the operator's pass (counted)
  applyCommand(msg.record, msg.command, t);
}

void MissionRun::updateDropouts(double t) {
  // Follower dropouts: offline → nothing runs; back online → a rebooted computer with no memory.
  // The leader's silence (faults.leader_silence): the same, its radio dead both ways; it rejoins as
  // a follower that listens first (its Leadership learns the newer term from the others).
  for (int i = 0; i < n_; ++i) {
    UavRuntime& u = uav(i);
    const bool silent = silentAt(i, t);
    const bool off = cfg_.faults.followerOffline(i, t) || silent;
    if (off && !u.offline && silent) {
      setMode(i, t, "silent", "leader silence: radio dead both ways; the loaded plan is flown to its end and held");
    } else if (off && !u.offline) {
      setMode(i, t, "offline", "follower dropout: the loaded plan is flown to its end and held");
    } else if (!off && u.offline) {
      u.share.reset();
      for (auto& r : u.received) r.reset();
      u.step->restart(planners_(i));
      setMode(i, t, "rejoin", "back online: listening before it moves");
    }
    u.offline = off;
  }
}

void MissionRun::deliverUavMessages(double t) {
  // Inter-UAV messages (an offline UAV's radio drops what arrives).
  for (int i = 0; i < n_; ++i) {
    for (int from = 0; from < n_; ++from) {
      if (from == i) continue;
      for (auto& s : shareLink(from, i).receive(t)) receiveShare(i, std::move(s));
    }
  }
  for (int i = 0; i < n_; ++i) {
    UavRuntime& u = uav(i);
    for (int j = 0; j < n_; ++j) {
      if (j == i) continue;
      for (auto& m : plan_links_[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)]->receive(t)) {
        if (u.offline) continue;
        if (m.abort) receiveAbort(i, *m.abort, t);  // a relayed abort counts whatever the message's age
        if (!m.plan) continue;
        auto& slot = u.received[static_cast<std::size_t>(j)];
        if (!slot || m.plan->plan.t0_s > slot->plan.t0_s) slot = std::move(m.plan);  // duplicates and late copies ignored
      }
    }
  }
}

void MissionRun::receiveShare(int i, LeaderShare s) {
  UavRuntime& u = uav(i);
  if (u.offline) return;
  if (!u.share || s.worker.stamp_s > u.share->worker.stamp_s) u.share = std::move(s);
}

void MissionRun::cameraFrame(double t, const WorkerState& ws) {
  // Leader camera frame: box → estimator; skeleton → classifier → filter → command. The leader's
  // camera is the one of the UAV doing the leader's work (owner_; the simulator gives every UAV
  // the leader's sensors), the others' cameras vote.
  std::vector<MultirotorState> follower_states;
  std::vector<bool> online;
  std::vector<int> camera_uav{owner_};  // camera k of the frame → its UAV
  if (follower_views_) {
    for (int i = 0; i < n_; ++i) {
      if (i == owner_) continue;
      follower_states.push_back(uav(i).plant.state());
      online.push_back(!uav(i).offline);
      camera_uav.push_back(i);
    }
  }
  const LeaderCameraFrame cf = camera_.frame(t, uav(owner_).plant.state(), follower_states, online, ws, worker_, classifier_);
  if (world_.site != nullptr) {  // rendered cameras: their depth images for the live maps (site_mapping.hpp)
    for (const CameraDepth& d : cf.depth) {
      if (d.camera < camera_uav.size()) world_.site->offerDepth(camera_uav[d.camera], d);
    }
  }
  const SensorFrame& frame = cf.sensors;
  if (frame.visible()) own_seen_s_[static_cast<std::size_t>(owner_)] = t;
  for (std::size_t k = 0; k < cf.followers.size() && k + 1 < camera_uav.size(); ++k) {
    if (cf.followers[k].visible) own_seen_s_[static_cast<std::size_t>(camera_uav[k + 1])] = t;
  }
  M_.range_outliers += cf.range_outliers;
  (void)cam_model_.receive(cf.intrinsics);  // invalid intrinsics keep the model held (or none: no measurement)
  if (frame.visible() && cam_model_.model() != nullptr) {
    const UavRuntime& L = uav(owner_);
    const estimation::CameraPose est_pose = cameraPose(L.est.p_world, L.est.heading_rad, L.est.pitch_rad);
    const auto meas = estimation::makeMeasurement(*cam_model_.model(), est_pose, frame.box, frame.d_uwb_m, frame.d_stereo_m,
                                                  cfg_.estimator.human_height_m, cfg_.estimator.noise,
                                                  cfg_.estimator.max_apparent_distance_m);
    if (meas && estimation::accepted(kf_.step(t, *meas))) last_fused_s_ = t;
  }
  actOnFrames(t, aggregateViews(t, cf));
  // The estimate the system acts on (a tentative track is not published: docs/estimation.md).
  Eigen::Vector3d estimate = Eigen::Vector3d::Zero();
  if (kf_.confirmed()) estimate = kf_.predicted(t).p_world;
  metrics_.cameraFrame(frame.visible(), kf_.confirmed() ? &estimate : nullptr, ws.p_world);
}

void MissionRun::recordVote(const gesture::GestureFrame& f) {
  VoteRecord v;
  v.t_s = f.t_s;
  v.leader = owner_;
  const auto it = frame_views_.find(f.t_s);
  v.view_ids = it != frame_views_.end() ? it->second : std::vector<int>(static_cast<std::size_t>(n_), -1);
  frame_views_.erase(frame_views_.begin(), frame_views_.upper_bound(f.t_s));  // this frame and any older one
  v.fused = f.fused;
  v.dominant_id = f.filter.dominant_id;
  v.dominant_ratio = f.filter.dominant_ratio;
  v.fired = f.filter.fired;
  votes_.push_back(std::move(v));
}

gesture::ViewObservation MissionRun::observation(int uav_index, int view, double t, const gesture::Classification& c,
                                                 const gesture::CalibratedSkeleton& cal,
                                                 const std::optional<Eigen::Vector3d>& worker_est) {
  gesture::ViewObservation o;
  o.view = view;
  o.t_s = t;
  o.gesture_id = c.gesture_id;
  o.distance_m = std::nan("");
  o.elevation_deg = std::nan("");
  const UavRuntime& u = uav(uav_index);
  if (worker_est) {
    const formation::ViewGeometry g = formation::viewGeometry(u.est.p_world, *worker_est);
    o.distance_m = g.distance_m;
    o.elevation_deg = g.elevation_deg;
  }
  if (cfg_.view_fusion.usesCalibratedViews()) {
    // The camera pose as the UAV knows it: the rendering pose moved by its odometry's
    // position and heading errors.
    const MultirotorState truth = u.plant.state();
    gesture::CalibratedSkeleton known = cal;
    known.p_world_camera += u.est.p_world - truth.p_world;
    known.R_world_camera =
        Eigen::AngleAxisd(common::wrapAngle(u.est.heading_rad - truth.heading_rad), Eigen::Vector3d::UnitZ()) *
        cal.R_world_camera;
    o.calibrated = known;
  }
  return o;
}

std::vector<gesture::GestureFrame> MissionRun::aggregateViews(double t, const LeaderCameraFrame& cf) {
  // Each camera's classification → the vote (geometry from the leader's worker estimate and each
  // UAV's odometry: a view votes only inside the classifier's envelope). The leader's
  // classification and the followers' votes that arrived by now go to the frame aggregation the
  // GestureCommander nodelet runs (gesture::GestureFrames): a frame is fused once every view
  // reported it, or view_fusion.fusion_lag_s after its stamp.
  const std::optional<Eigen::Vector3d> worker_est =
      kf_.confirmed() ? std::optional<Eigen::Vector3d>(kf_.predicted(t).p_world) : std::nullopt;
  std::vector<gesture::GestureFrame> closed;
  const auto take = [&closed](std::vector<gesture::GestureFrame> frames_closed) {
    for (auto& f : frames_closed) closed.push_back(std::move(f));
  };
  // Views are numbered by UAV (one camera only: the leader's is view 0).
  const int own_view = follower_views_ ? owner_ : 0;
  const auto noteReading = [this](const gesture::ViewObservation& o) {
    auto& ids = frame_views_.try_emplace(o.t_s, static_cast<std::size_t>(n_), -1).first->second;
    if (o.view >= 0 && o.view < n_) ids[static_cast<std::size_t>(o.view)] = o.gesture_id;
  };
  if (cf.classification) {
    const gesture::ViewObservation o = observation(owner_, own_view, t, *cf.classification, cf.calibrated, worker_est);
    noteReading(o);
    take(frames_.observe(o));
  }
  for (std::size_t f = 0; f < cf.followers.size(); ++f) {
    const int i = static_cast<int>(f) < owner_ ? static_cast<int>(f) : static_cast<int>(f) + 1;  // the UAV of view f
    if (cf.followers[f].classification && !uav(i).offline) {
      voteLink(i, owner_)->send(t, observation(i, i, t, *cf.followers[f].classification, cf.followers[f].calibrated, worker_est));
    }
  }
  for (int i = 0; follower_views_ && i < n_; ++i) {
    if (i == owner_) continue;
    for (const auto& o : voteLink(i, owner_)->receive(t)) {
      if (uav(owner_).offline) continue;  // a dead radio drops what arrives
      noteReading(o);
      take(frames_.observe(o));
    }
  }
  take(frames_.closeDue(t));
  return closed;
}

void MissionRun::actOnFrames(double t, const std::vector<gesture::GestureFrame>& closed) {
  for (const gesture::GestureFrame& f : closed) {
    recordVote(f);
    last_class_ = f.fused.gesture_id;
    last_ratio_ = f.filter.dominant_ratio;
    if (!f.filter.fired) continue;
    const std::size_t record = metrics_.addRequest(firedGestureRecord(t, f.filter.dominant_id, cfg_.gesture_mapping));
    // Without a lease the leader's commands wait for it while it is still the leader of the term it
    // acts in (applied if the lease comes back in that term: kept_); after a newer term they are dropped.
    const bool acting = acting_[static_cast<std::size_t>(owner_)];
    if (!acting && lead_->member(owner_).term() != owner_term_) continue;
    const auto keepOrDo = [&](std::function<void(double)> apply) {
      if (acting) return apply(t);
      kept_.push_back(std::move(apply));
      kept_term_ = owner_term_;
    };
    if (f.action != nullptr && f.action->kind != gesture::GestureAction::Kind::kEvent) {
      keepOrDo([this, record, fired_s = t, cmd = gesture::toCommand(*f.action, ++gesture_seq_)](double now) {
        if (staleAt(record, fired_s, now)) return;
        if (assistance_.refusal(formation::CommandSource::kGesture)) {  // the views are held until acknowledged
          metrics_.requestOutcome(record, formation::toString(formation::CommandStatus::kRejected), now, 0, {});
          return;
        }
        applyCommand(record, cmd, now);
      });
    } else if (f.action != nullptr && f.action->event == gesture::GestureEvent::kAssistRequested) {
      keepOrDo([this, fired_s = t](double) { assistance_.request(fired_s); });
    } else if (f.action != nullptr && f.action->event == gesture::GestureEvent::kAbort) {
      // Every UAV acts on an abort on its own once received: sent at once, lease or not.
      receiveAbort(owner_, planning::AbortCommand{{"gesture", ++gesture_seq_}, planning::AbortSource::kGesture, t}, t);
    }
  }
}

void MissionRun::replanDue(double t) {
  // Replanning, staggered, in priority order within a step.
  for (int i = 0; i < n_; ++i) {
    UavRuntime& u = uav(i);
    if (t + 1e-9 >= u.next_plan_s) {
      u.next_plan_s += cfg_.replanning_period_s;
      replan(i, t);
    }
  }
}

void MissionRun::replan(int i, double t) {
  UavRuntime& u = uav(i);
  if (u.offline) {
    ++M_.plans_skipped;
    return;
  }
  for (const auto& o : cfg_.faults.planner_outages) {
    if (o.uav == i && t >= o.from_s && t < o.to_s) {
      ++M_.plans_skipped;
      setMode(i, t, "outage", "planner outage: the loaded plan is flown to its end and held");
      relayAbort(i, t);  // the link (the ROS LcmBridge) still relays an accepted abort
      return;
    }
  }
  // What this UAV knows: the leader its estimator's state as the WorkerEstimator publishes it
  // (only a confirmed track, the prediction to now; the last one kept while the track is
  // re-initialised), a follower the leader's last share.
  const LeaderShare* share = nullptr;
  const formation::FormationParams* params = &fstate_.params();
  std::uint64_t version = params_version_;
  const bool leads = i == owner_;  // flies the leader's slot from its own estimator
  if (leads) {
    if (kf_.confirmed()) {
      planning::WorkerKnowledge w;
      w.stamp_s = t;
      w.fused_s = last_fused_s_;
      w.p_world = kf_.predicted(t).p_world;
      w.v_world = kf_.state().tail<3>();
      w.lost = kf_.lost(t);
      leader_knowledge_ = w;
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
  in.worker = leads ? (leader_knowledge_ ? &*leader_knowledge_ : nullptr) : (share != nullptr ? &share->worker : nullptr);
  in.params = params;
  in.leader_plan = share != nullptr ? &share->plan : nullptr;
  in.leader_plan_in_share = true;  // LeaderShare.plan: listening waits for the followers' plans only
  in.received = &u.received;
  in.slot = slotOf(i);
  in.leader_index = leads ? i : (share != nullptr ? share->from : 0);
  if (share != nullptr) {  // the leader's newer plan, when its copy on the plan link is newer than the share's
    const auto& direct = u.received[static_cast<std::size_t>(share->from)];
    if (direct && direct->plan.t0_s > share->plan.t0_s) in.leader_plan = &direct->plan;
  }
  const planning::ReplanOutcome out = u.step->step(in);
  if (!out.planned()) {
    ++M_.plans_skipped;  // nothing known about the worker: the controller holds (its plan's end, or brakes)
    if (!leads) setMode(i, t, "hold", out.reason);
    relayAbort(i, t);  // an accepted abort is relayed whether or not the planner planned
    return;
  }
  if (out.holding()) ++M_.plans_hold;
  if (out.aborting()) {
    setMode(i, t, std::string("abort_") + planning::toString(out.abort_phase), out.reason);
    if (abort_record_) abort_record_->phase(i, t, out.abort_phase);
  } else {
    setMode(i, t, planning::toString(out.mode), out.holding() ? out.reason : "fresh data");
  }
  // A back-off from the worker's reach begins (or finds no goal): a row of the same mode with its reason.
  if (out.backoff_started) modes_.push_back(ModeChange{t, i, u.mode, out.backoff});
  const planning::PlanResult& res = out.result;
  if (world_.site != nullptr) world_.site->planned(i, t, res, out.reference, cfg_.replan.dt_s);  // site_mapping.hpp
  metrics_.plan(i, t, version, res.status, res.timings.total_ms, res.reason, res.qp_sparse_timeouts);
  if (res.trajectory.empty()) {
    u.ctl.clearPlan();
  } else {
    u.ctl.setPlan(res.trajectory);
  }
  sendPlan(i, t, out, *params, version);
}

void MissionRun::relayAbort(int i, double t) {
  PlanMessage msg{std::nullopt, uav(i).step->abort().command()};
  if (!msg.abort) return;
  msg.abort->sent_s = t;
  for (int j = 0; j < n_; ++j) {
    if (j != i) plan_links_[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)]->send(t, msg);
  }
}

void MissionRun::sendPlan(int i, double t, const planning::ReplanOutcome& out, const formation::FormationParams& params,
                          std::uint64_t version) {
  if (i == owner_ && acting_[static_cast<std::size_t>(i)] && leader_knowledge_) {
    LeaderShare s;
    s.worker = *leader_knowledge_;  // the estimator's state, as the WorkerEstimator's over LCM
    s.params = params;
    s.params_version = version;
    s.plan = out.result.trajectory;
    s.from = i;
    for (int j = 0; j < n_; ++j) {
      if (j != i) shareLink(i, j).send(t, s);
    }
  }
  // Every UAV's plan to every other (the leader's too, as the ROS PlannedTrajectory): after a
  // hand-over the others still know the old leader's last plan.
  PlanMessage msg{planning::ReceivedPlan{out.result.trajectory, out.fallback}, uav(i).step->abort().command()};
  if (msg.abort) msg.abort->sent_s = t;  // each relayed copy is stamped when it is sent
  for (int j = 0; j < n_; ++j) {
    if (j != i) plan_links_[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)]->send(t, msg);
  }
}

void MissionRun::sampleTimeline(double t, const WorkerState& ws) {
  // Timeline and tracking errors at the timeline rate.
  TimelineInput in;
  in.t_s = t;
  in.worker = ws;
  if (kf_.confirmed()) in.estimate_world = kf_.predicted(t).p_world;
  in.visible = camera_.lastVisibleS() > t - 0.2 ? 1 : 0;
  in.gesture_true = worker_.performingAt(t);
  in.gesture_class = last_class_;
  in.dominant_ratio = last_ratio_;
  in.params = fstate_.params();
  in.human_heading_rad = uav(owner_).step->workerHeading();
  for (int i = 0; i < n_; ++i) {
    in.acting.push_back(acting_[static_cast<std::size_t>(i)] ? 1 : 0);
    in.slots.push_back(slotOf(i));
  }
  for (const auto& u : uavs_) in.uavs.push_back(u->plant.state());
  metrics_.sampleTimeline(in);
}

void MissionRun::control(double t, double dt) {
  // Control and plant.
  const Eigen::Vector3d w = wind_.step(t, dt);
  for (auto& u : uavs_) {
    const MultirotorCommand cmd = u->ctl.update(t, dt, u->est);
    u->plant.step(dt, cmd, w, world_.ground_height_m);
    u->wind_estimate.update(w, dt);
  }
}

void MissionRun::applyCommand(std::size_t record, const formation::FormationCommand& cmd, double t) {
  const auto outcome = fstate_.apply(cmd);
  if (outcome.status == formation::CommandStatus::kDuplicate) ++M_.commands_duplicate;
  if (metrics_.request(record).status == "applied") return;  // a duplicate copy of an applied command changes nothing
  const bool applied = outcome.status == formation::CommandStatus::kApplied;
  std::vector<int> addressed;  // the UAVs flying the changed slots (a hand-over moves slots)
  for (const auto& ch : outcome.changes) {
    int flying = ch.uav;
    for (int u = 0; u < n_; ++u) {
      if (slotOf(u) == ch.uav) flying = u;
    }
    addressed.push_back(flying);
  }
  metrics_.requestOutcome(record, formation::toString(outcome.status), t, applied ? ++params_version_ : 0, addressed);
}

void MissionRun::deliverAbort(double t) {
  // The injected abort: the ground station's copies over the operator link to every UAV, or the
  // gesture accepted by the leader's pipeline at its time.
  const std::optional<AbortEvent>& event = cfg_.faults.abort;
  if (!event) return;
  if (event->source == planning::AbortSource::kGesture && t >= event->t_s && !uav(owner_).step->abort().aborting()) {
    receiveAbort(owner_, planning::AbortCommand{{"gesture", ++gesture_seq_}, planning::AbortSource::kGesture, event->t_s}, t);
  }
  for (const auto& c : abort_sender_.due(t)) {
    for (std::size_t i = 0; i < abort_links_.size(); ++i) {
      if (!cfg_.faults.operatorLinkDown(static_cast<int>(i), t)) abort_links_[i]->send(t, c);
    }
  }
  for (int i = 0; i < static_cast<int>(abort_links_.size()); ++i) {
    for (const auto& c : abort_links_[static_cast<std::size_t>(i)]->receive(t)) {
      if (!uav(i).offline) receiveAbort(i, c, t);  // an offline UAV's radio drops what arrives
    }
  }
}

void MissionRun::receiveAbort(int i, const planning::AbortCommand& command, double t) {
  UavRuntime& u = uav(i);
  if (u.step->receiveAbort(command, t) != planning::AbortAcceptance::kAccepted) return;
  if (!abort_record_) {  // an abort not injected by faults.abort (a recognised gesture): measured from here
    abort_record_.emplace(AbortEvent{t, command.source}, n_,
                          obstacleDistance(world_));
  }
  abort_record_->accepted(i, t);
  setMode(i, t, "abort_accepted", std::string("abort from ") + planning::toString(command.source) + " " + command.id.sender);
}

void MissionRun::divertWorker(double t) {
  // faults.worker_approach: at its time the worker turns towards where the UAV is then.
  const std::optional<WorkerApproach>& a = cfg_.faults.worker_approach;
  if (!a || diverted_ || t < a->t_s) return;
  diverted_ = true;
  divertTowards(worker_, t, *a, uav(a->uav).plant.state().p_world);
  approach_record_.emplace(*a, n_, cfg_.formation.limits.safety_distance_m, cfg_.faults.camera_blackouts);
}

void MissionRun::setMode(int i, double t, const std::string& mode, const std::string& reason) {
  UavRuntime& u = uav(i);
  if (u.mode == mode) return;
  u.mode = mode;
  modes_.push_back(ModeChange{t, i, mode, reason});
}

}  // namespace

common::Result<MissionOutput> runMission(const MissionConfig& cfg, const MissionWorld& world,
                                         const PlannerFactory& planners, MissionClassifier* classifier,
                                         std::uint64_t seed, double duration_s, CameraSource* camera) {
  using R = common::Result<MissionOutput>;
  if (world.field == nullptr) return R::fail("runMission: a distance field is required");
  const auto wall0 = std::chrono::steady_clock::now();
  const double duration = duration_s > 0.0 ? duration_s : cfg.duration_s;
  const int n = cfg.formation.params.uavCount();
  if (static_cast<int>(cfg.uavs.size()) != n) return R::fail("runMission: uavs and formation disagree on the UAV count");
  auto fstate = formation::FormationState::create(cfg.formation.params, cfg.formation.limits, cfg.formation.duplicates);
  if (!fstate) return R::fail(fstate.reason());
  MissionRun mission(cfg, world, planners, classifier, seed, std::move(*fstate), camera);
  const std::string bad_start = mission.addUavs();
  if (!bad_start.empty()) return R::fail(bad_start);
  mission.openLinks();
  mission.openHandoverLinks();
  return R::ok(mission.run(duration, wall0));
}

}  // namespace gesture_formation::sim

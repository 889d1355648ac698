#pragma once
/// \file
/// \brief One UAV's replanning step — the single home of what `gfctl simulate`'s UAVs and the
/// FormationPlanner nodelet do every replanning period (docs/planning.md §"The replanning step",
/// docs/safety.md §1):
///
///   1. nothing known of the worker yet → skip (the controller flies its plan to its end, then hovers);
///   2. freshness (planning::holdReason): data older than its age limit → hold;
///   3. listen before moving: from its first replanning (start-up, or a restart after a reboot)
///      a UAV holds until it has, from every other follower, a plan made since then — or for at
///      most AvoidanceRule::max_plan_age_s (a UAV not heard from by then has right of way);
///   4. the worker's prediction over the horizon: the estimate extrapolated at constant velocity
///      from its stamp to now (frozen while holding or when the estimator lost him), the
///      worker's heading from this UAV's own formation::WorkerHeading filter;
///   5. hold / search (planning::HoldPlanner), or track; while holding or searching, the
///      worker's predicted reach kept clear by Γ_dis + a margin (planning::ReachKeeper: a back-off
///      to a goal of the abort's kind along an ordinary verified plan, docs/safety.md §3);
///   6. the request (planning::buildPlanRequest: reference + the plans to avoid), with the
///      acceleration the UAV's current plan commands now as the start's acceleration (odometry
///      carries none), and the planner's verified plan or fallback.
/// Abort (planning::AbortPlanner, docs/safety.md §2.8): once the UAV accepted an abort command
/// (receiveAbort), steps 2 and 5 are replaced by the abort's sequence — stale data no longer
/// holds it, it flies to its retreat goal (then hovers, returns home or lands) around every plan
/// it has received, its plan flagged like a hold (others avoid it). Listening still comes first.
///
/// Thread safety: not thread-safe; one instance per UAV, called from its planning thread. With a
/// live map (mapping::LiveMap: the planner's map and field, and RetreatSpace::field, updated in
/// place per depth frame), a step must not overlap LiveMap::integrate(): when frames are
/// integrated on another thread, call step() under LiveMap::readLock() (docs/mapping.md §3).

#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/formation/formation_params.hpp"
#include "gesture_formation/formation/worker_heading.hpp"
#include "gesture_formation/planning/abort_mode.hpp"
#include "gesture_formation/planning/plan_request_builder.hpp"
#include "gesture_formation/planning/planned_trajectory.hpp"
#include "gesture_formation/planning/uav_planner.hpp"
#include "gesture_formation/planning/worker_reach.hpp"

namespace gesture_formation::planning {

/// \brief A UAV's planner as the replanning step calls it: UavPlanner in the product; tests and
/// fault injection may substitute their own.
class Planner {
 public:
  virtual ~Planner() = default;
  virtual PlanResult plan(const PlanRequest& request) = 0;
};

/// \brief planning::UavPlanner behind the Planner interface (owns it).
class UavPlannerAdapter final : public Planner {
 public:
  explicit UavPlannerAdapter(std::unique_ptr<UavPlanner> planner) : planner_(std::move(planner)) {}
  PlanResult plan(const PlanRequest& request) override { return planner_->plan(request); }
  UavPlanner& planner() { return *planner_; }

 private:
  std::unique_ptr<UavPlanner> planner_;
};

/// \brief What a UAV knows of the worker at one replanning: the leader from its estimator (the
/// WorkerEstimator's published state), a follower from the leader's share (received over LCM).
struct WorkerKnowledge {
  /// When position and velocity were valid: the estimate's time (leader) or when the leader sent
  /// the share (follower; its age decides hold with FreshnessLimits::max_share_age_s).
  double stamp_s = std::numeric_limits<double>::quiet_NaN();
  /// The estimate's last fused measurement (non-finite: never); its age decides hold.
  double fused_s = std::numeric_limits<double>::quiet_NaN();
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();   ///< worker position at stamp_s [m]
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();   ///< worker velocity [m/s]
  bool lost = false;  ///< the estimator no longer extrapolates (HumanKalman::lost, WorkerState.lost)
  /// \brief The position at t_s: p + (t_s − stamp_s)·v (constant velocity; p when stamp_s is not
  /// finite). The one extrapolation of a worker estimate in the product.
  Eigen::Vector3d positionAt(double t_s) const {
    return std::isfinite(stamp_s) ? Eigen::Vector3d(p_world + (t_s - stamp_s) * v_world) : p_world;
  }
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief A replanning's mode.
enum class ReplanMode {
  kSkipped,  ///< nothing known of the worker: no plan made
  kTrack,    ///< fresh data: the formation reference
  kHold,     ///< stale data or listening: the latched braking point, camera on the estimate
  kSearch,   ///< the leader lost the worker: hold point, camera sweeps (HoldPlanner)
  kAbort,    ///< an accepted abort: the AbortPlanner's phase (ReplanOutcome::abort_phase)
};
const char* toString(ReplanMode mode);

/// \brief The settings of one UAV's replanning (FormationPlanner parameters; mission file).
/// The ranges of its numbers are written once, in replanConfigFields().
struct ReplanConfig {
  int uav_index = 0;                ///< 0 = leader, i = follower i (priority order)
  int uav_count = 1;                ///< the formation's UAVs (the abort's retreat rings), > uav_index
  double dt_s = 0.2;                ///< horizon step [s]
  int steps = 40;                   ///< horizon steps
  FreshnessLimits freshness;        ///< hold on data older than these
  AvoidanceRule rule;               ///< which received plans are avoided; listening's time limit
  SearchConfig search;              ///< the leader's camera search
  double brake_accel_mps2 = 4.0;    ///< where a holding UAV stops (brakingPoint)
  formation::WorkerHeadingConfig worker_heading;  ///< the worker-heading filter (^Hφ)
  /// The formation's limits: a follower's elevation over the leader's planned pitch is kept within
  /// gamma_min_deg … gamma_max_deg (PlanRequestInputs::limits).
  formation::FormationLimits formation_limits;
  AbortConfig abort;                ///< the abort's settings (mission abort.*)
  /// The worker's reach while holding or searching (faults.reach_*; worker_min_distance_m: the
  /// formation's limits.safety_distance_m, set by the owner) — planning::ReachKeeper.
  ReachConfig reach;
  /// The take-off point (abort: return_home, the landing fallback); non-finite: the position of
  /// the first replanning.
  Eigen::Vector3d home_world = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// \brief Every number outside its range, each "<prefix><key> must be ..., got v" (keys as in
  /// replanConfigFields()); empty when valid.
  std::vector<std::string> validate(const std::string& prefix = "") const;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The one range of each replanning number, keyed as a scenario's `mission` section writes
/// it: horizon_dt_s, horizon_steps, controller.brake_accel_mps2, faults.max_share_age_s,
/// faults.max_worker_age_s, faults.max_plan_age_s, faults.search_timeout_s, faults.search_height_m,
/// faults.search_vertical_speed_mps, faults.search_period_s, faults.search_horizontal_speed_mps,
/// faults.reach_walking_speed_mps, faults.reach_base_m, faults.reach_max_m, faults.reach_margin_m.
/// The FormationPlanner nodelet's parameters of the same settings are the last segment of each
/// key (brake_accel_mps2, max_share_age_s, search_period_s, ...). (uav_index, the bool
/// rule.avoid_all_plans and worker_heading are read by their owners.)
const common::FieldTable<ReplanConfig>& replanConfigFields();

/// \brief The inputs of one replanning.
struct ReplanInputs {
  double t_s = 0.0;  ///< now
  /// The UAV's estimated state (odometry: position, velocity, camera heading and pitch; its
  /// a_world is ignored — the step takes the acceleration its current plan commands).
  UavKinematicState state;
  /// The flight stack's wind estimate (world, m/s; non-finite: none).
  Eigen::Vector3d wind_estimate_mps = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  const WorkerKnowledge* worker = nullptr;                    ///< null: nothing known yet → skipped
  const formation::FormationParams* params = nullptr;         ///< required
  const PlannedTrajectory* leader_plan = nullptr;             ///< followers: the leader's last plan (null: none)
  /// The formation slot flown (PlanRequestInputs::slot): 0 = the leader's — the UAV then plans as
  /// the leader (its own estimate's freshness, the search) —, j = follower j's; −1: its own index.
  int slot = -1;
  int leader_index = 0;  ///< whose plan leader_plan is (PlanRequestInputs::leader_index)
  /// The leader's plan travels with its share (gfctl simulate's LeaderShare.plan): listening does
  /// not wait for it on the plan link. Over ROS the share (WorkerState) carries no plan: false, and a
  /// (re)started UAV waits for the leader's plan in `received` like every other UAV's.
  bool leader_plan_in_share = false;
  /// Plans by sender (null: no listening at all); a UAV missing from a shorter table is waited for.
  const std::vector<std::optional<ReceivedPlan>>* received = nullptr;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The outcome of one replanning.
struct ReplanOutcome {
  ReplanMode mode = ReplanMode::kSkipped;
  std::string reason;      ///< skipped / hold / search: why (empty while tracking)
  /// An event worth a log line (the core never logs), e.g. listening ended at its time limit
  /// without a plan from some UAVs; empty otherwise.
  std::string note;
  PlanResult result;       ///< the planner's result (empty trajectory when skipped)
  bool fallback = false;   ///< others must avoid this plan: the planner fell back, or the UAV holds
  formation::WorkerHorizon worker;          ///< the worker prediction planned around
  formation::ReferenceTrajectory reference; ///< the stage-1 reference (or hold reference)
  AbortPhase abort_phase = AbortPhase::kRetreat;  ///< kAbort only: the abort's phase
  bool abort_phase_changed = false;               ///< kAbort only: the phase began at this replanning
  /// kHold / kSearch: the UAV backs off from the worker's reach (ReachKeeper).
  bool backing_off = false;
  bool backoff_started = false;  ///< the back-off (or the failed search for its goal) began now
  std::string backoff;           ///< backing off: where to and why; no goal found: why; empty otherwise
  bool planned() const { return mode != ReplanMode::kSkipped; }
  bool holding() const { return mode == ReplanMode::kHold || mode == ReplanMode::kSearch; }
  bool aborting() const { return mode == ReplanMode::kAbort; }
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief One UAV's replanning (see the file comment). Owns the UAV's planner, its hold/search
/// state, its worker-heading filter, its listening state and the plan it flies.
class ReplanStep {
 public:
  /// \param planner required (non-null).
  /// \param space where the abort finds its goals (the planner's map and field; they must outlive
  /// the step). Empty: an abort holds at the braking point ("no map").
  ReplanStep(const ReplanConfig& config, std::unique_ptr<Planner> planner, const RetreatSpace& space = {});

  /// \brief One replanning at in.t_s (preconditions: in.params non-null with an entry for the UAV).
  ReplanOutcome step(const ReplanInputs& in);

  /// \brief A restart (a rebooted computer): a new planner, no memory — hold, heading, the plan
  /// flown, an accepted abort (the sender repeats it) — and it listens again before it moves.
  void restart(std::unique_ptr<Planner> planner);

  /// \brief An abort command arrived at t_s (AbortPlanner::receive): accepted, a copy, stale, or
  /// from the future (another timeline).
  AbortAcceptance receiveAbort(const AbortCommand& command, double t_s) { return abort_.receive(command, t_s); }
  /// \brief The abort's state (command, phase, goals).
  const AbortPlanner& abort() const { return abort_; }

  /// \brief The plan the UAV flies now (the last result; empty before the first or when the
  /// planner returned none — the controller then brakes to hover).
  const PlannedTrajectory& flownPlan() const { return flown_; }
  /// \brief The worker heading this UAV last used [rad].
  double workerHeading() const { return heading_.heading(); }
  const ReplanConfig& config() const { return config_; }

 private:
  std::string listeningHold(const ReplanInputs& in);
  /// The other UAVs with no plan in `in.received` made at or after `since_s` (see ReplanInputs).
  std::vector<int> unheardSince(const ReplanInputs& in, double since_s) const;
  /// The hold / search or abort decision of one replanning (its reference, camera target, mode).
  struct Choice;
  Choice choose(const ReplanInputs& in, const std::string& hold, const Eigen::Vector3d& worker_p0, ReplanOutcome& out);
  /// Holding or searching: the back-off from the worker's reach replaces the hold reference.
  void keepReachClear(const ReplanInputs& in, const Eigen::Vector3d& worker_p0, Choice& c, ReplanOutcome& out);
  /// Why the planner should not fall back to its last verified plan in `mode` (verified_for_);
  /// empty: it may.
  std::string reflyRefusal(ReplanMode mode) const;

  ReplanConfig config_;
  std::unique_ptr<Planner> planner_;
  HoldPlanner hold_;
  AbortPlanner abort_;
  ReachKeeper reach_;
  RetreatSpace space_;
  formation::WorkerHeading heading_;
  PlannedTrajectory flown_;
  std::optional<Eigen::Vector3d> home_;  ///< the take-off point (ReplanConfig::home_world or the first position)
  double listen_since_s_ = std::numeric_limits<double>::quiet_NaN();  ///< the first replanning since the (re)start
  bool listening_ = true;
  /// The plan flown is a back-off's (since the last optimized plan of another mode): a UAV that no
  /// longer backs off does not fall back to it (PlanRequest::reuse_previous).
  bool flying_backoff_ = false;
  /// The mode the planner's last verified plan — the one its fallback re-flies — was optimized
  /// for; none before the first and after a verified brake plan (a stop, re-flown in any mode).
  /// A hold, search or abort prefers not to fly on a tracking plan, an abort on anything but its
  /// own (PlanRequest::reuse_previous: the planner still does when the brake plan fails
  /// verification and that plan verifies).
  std::optional<ReplanMode> verified_for_;
};

}  // namespace gesture_formation::planning

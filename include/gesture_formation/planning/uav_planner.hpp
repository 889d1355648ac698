#pragma once
/// \file
/// \brief One replanning of one UAV: the three stages of docs/design.md §4 behind one call.
///
///   stage 1  reference trajectory (formation core, given in the request)
///   stage 2  collision-free path near the reference on the map (references inside an
///            obstacle projected to the nearest free point)
///   stage 3  convex corridors along the path (CorridorBuilder) → trajectory QP (ProxQP,
///            warm-started) with hard speed/acceleration limits, time-indexed half-spaces
///            keeping Γ_dis from the higher-priority UAVs' plans and a safety distance from
///            the worker → camera heading/pitch (line of sight, rate limits) → verification.
///
/// Safety contract: `plan()` returns a trajectory only if it passed verification; otherwise
/// it returns the last verified plan (re-timed to t_now) when that is still valid, else a
/// braking-to-hover plan, with `status` and `reason` saying which and why. The planner is
/// stateful (last verified plan, QP warm start) and deterministic for the same sequence of
/// requests. Not thread-safe; one instance per UAV.
///
/// This header is the API the simulator (`sim/`), `gfctl plan` and the FormationPlanner
/// nodelet code against. Fields may be added; do not rename.

#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/planning/corridor_builder.hpp"
#include "gesture_formation/planning/planned_trajectory.hpp"
#include "gesture_formation/planning/planner_config.hpp"
#include "gesture_formation/planning/trajectory_qp.hpp"

namespace gesture_formation::planning {

class OccupancyMap;
class DistanceField;
class SeenSpace;

/// \brief Everything one replanning needs besides the map.
struct PlanRequest {
  int uav_index = 0;
  double t_now_s = 0.0;
  UavKinematicState state;  ///< current (estimated) state; sample 0 of the plan starts here
  double dt_s = 0.2;        ///< sample spacing of reference, worker horizon and output
  /// Stage-1 reference, step k at t_now_s + k·dt_s (formation::formationHorizon output).
  formation::ReferenceTrajectory reference;
  /// The worker's predicted trajectory, same steps (a moving obstacle; camera target).
  formation::WorkerHorizon worker;
  /// Where the camera looks instead, same steps (empty: at `worker`). Set while the leader searches
  /// for a worker it lost (planning::searchTargets); the keep-out still uses `worker`.
  formation::HorizonPoints camera_target;
  /// Plans of the higher-priority UAVs as last received (any stamps; older plans get a
  /// margin growing with their age).
  std::vector<PlannedTrajectory> higher_priority_plans;
  /// The flight stack's estimate of the wind at the UAV (world, m/s; e.g. mavros
  /// `wind_estimation`); non-finite: none. Feeds the wind allowance
  /// (PlannerConfig::wind_allowance_*).
  Eigen::Vector3d wind_estimate_mps = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// False: a failed request brakes to hover rather than reusing the last verified plan — set by
  /// planning::ReplanStep when that plan was made for another kind of flight (a back-off the UAV
  /// no longer needs: flying it on would carry it out of the camera's view; a tracking plan in a
  /// hold or abort), naming why in `no_reuse_reason`. Only a preference: when the brake plan fails
  /// verification and the previous plan verifies, the previous plan is flown (verified first).
  bool reuse_previous = true;
  std::string no_reuse_reason = "previous plan is a back-off no longer needed";
};

enum class PlanStatus {
  kOptimized,          ///< new verified plan from this request
  kFallbackPrevious,   ///< this request failed; last verified plan returned
  kFallbackBrake,      ///< this request failed and no usable previous plan: brake to hover
};
const char* toString(PlanStatus status);

/// \brief Wall-clock milliseconds per stage of one replanning.
struct StageTimings {
  double path_ms = 0.0;
  double corridor_ms = 0.0;
  double qp_ms = 0.0;
  /// Part of qp_ms: naming the cause of an infeasible QP (relaxed re-solves, docs/planning.md §7.1).
  double qp_diagnosis_ms = 0.0;
  double heading_ms = 0.0;
  double verify_ms = 0.0;
  double total_ms = 0.0;
};

struct PlanResult {
  PlannedTrajectory trajectory;  ///< always verified-safe (see file comment)
  PlanStatus status = PlanStatus::kFallbackBrake;
  std::string reason;            ///< why a fallback was taken (empty when kOptimized)
  StageTimings timings;
  int qp_variables = 0;
  int qp_constraints = 0;
  int qp_iterations = 0;
  /// QP solves of this replanning that were stopped: past their deadline qp.solve_timeout_s
  /// (kTimeLimit), or the sparse solver broke an invariant and the dense backend answered
  /// (TrajectoryQp, docs/safety.md §4.5).
  int qp_sparse_timeouts = 0;
  double min_obstacle_clearance_m = 0.0;  ///< verified clearance of the returned plan
  /// PlannerConfig::qp_truncate_on_infeasible: the QP over the whole horizon was primal infeasible
  /// and the plan is the truncated re-solve's — K samples ending at rest, then hovering there (0: not).
  int qp_truncated_at = 0;
  // --- added by the planner implementation (fields may be added, never renamed) ---------
  /// False only for a braking plan that itself failed verification (the last resort is
  /// returned anyway, `reason` says why), or an empty trajectory when the state is not finite.
  bool verified = false;
  double min_uav_margin_m = 0.0;       ///< min over plans/time of distance − required (m)
  double min_worker_distance_m = 0.0;  ///< min distance to the worker's prediction (m)
  std::vector<Eigen::Vector3d> path_world;  ///< stage-2 path (after merging), for display
  /// Stage-3 corridors, one per segment of path_world (polytope `A x ≤ b`, world frame, with the
  /// ellipsoid it was grown from), for display: filled when the QP stage ran (also when the QP
  /// or a later stage failed and a fallback was returned), empty otherwise. The QP keeps its
  /// samples qp.corridor_margin_m inside them.
  std::vector<SegmentCorridor> corridors;
  int corridor_count = 0;
  int projected_references = 0;  ///< reference steps moved out of obstacles / the worker zone
  int path_searches = 0;         ///< A* searches run for blocked segments
  int path_searches_failed = 0;  ///< of them, those that found no path (the path ends before it)
  int path_search_expansions = 0;  ///< A* expansions of all of them (their cost)
  /// Corridor rows moved out because the UAV's momentum carries it over them (at most the tracking
  /// allowance), and move-away rows lowered to what it can reach (docs/planning.md §6.3).
  int momentum_relaxed_rows = 0;
  /// Tracking allowance (m) this replanning added to the planning clearances
  /// (PlannerConfig::tracking_allowance_*): the largest recent deviation of the state from the
  /// plan being flown.
  double tracking_allowance_m = 0.0;
  /// The state's distance from the plan being flown at this replanning (0 without one): above
  /// tracking_allowance_m the UAV is farther off its plan than planning allowed for — the other
  /// UAVs and the clearances count on it being on it (a flight stack lagging its setpoints, wind
  /// beyond the allowance).
  double tracking_deviation_m = 0.0;
  /// The part of tracking_allowance_m's bounds due to the wind (PlannerConfig::wind_allowance_*).
  double wind_allowance_m = 0.0;
};

class TrajectoryVerifier;
class GridPathSearch;
class TrajectoryQp;
struct TrajectoryQpProblem;

/// \brief One UAV's planner: the three stages of docs/design.md §4 with verification and fallback
/// (docs/planning.md §5–§8). Construct once per UAV from the scenario's map and distance
/// field (built once per scenario and shared by every UAV's planner; they must outlive it).
/// Stateful (last verified plan, QP warm start, plan sequence); deterministic for the same
/// sequence of requests when `time_budget_ms` is 0 (otherwise only the budget fallback
/// depends on the machine's speed). Not thread-safe; one instance per UAV.
/// Live map: the map and field may instead be a mapping::LiveMap's (map(), field()), which its
/// integrate() updates in place — nothing is copied per replanning; every stage, the fallback's
/// re-verification of the previous plan included, reads the map as it is at plan(). plan() must
/// not overlap an update: on another thread than integrate(), hold LiveMap::readLock() during
/// plan() (docs/mapping.md §3).
class UavPlanner {
 public:
  /// \brief `config` must be valid; otherwise `configError()` names every bad field and
  /// every `plan()` returns a braking plan with that reason.
  /// `seen` (online mapping, may be null): the space observed so far; every plan then also
  /// passes the seen-space rule (seen_space.hpp, docs/mapping.md §3.1).
  UavPlanner(const PlannerConfig& config, std::shared_ptr<const OccupancyMap> map,
             std::shared_ptr<const DistanceField> field, std::shared_ptr<const SeenSpace> seen = nullptr);
  ~UavPlanner();
  UavPlanner(const UavPlanner&) = delete;
  UavPlanner& operator=(const UavPlanner&) = delete;
  UavPlanner(UavPlanner&&) noexcept;
  UavPlanner& operator=(UavPlanner&&) noexcept;

  const PlannerConfig& config() const { return config_; }
  const std::string& configError() const { return config_error_; }

  /// \brief One replanning (see the file comment for the safety contract).
  PlanResult plan(const PlanRequest& request);

  /// \brief The last plan that passed verification (empty before the first).
  const PlannedTrajectory& lastVerifiedPlan() const { return last_verified_; }
  /// \brief Forgets the last plan and the warm start (e.g. after a reset of the mission).
  void reset();
  /// \brief Keep a copy of each replanning's QP (for `gfctl plan --dump-qp` and tests;
  /// off by default: it costs a copy per replanning).
  void keepLastQp(bool keep) { keep_last_qp_ = keep; }
  /// \brief The last QP assembled by plan() when keepLastQp(true); nullptr otherwise.
  const TrajectoryQpProblem* lastQp() const { return last_qp_.get(); }
  /// \brief The warm start plan() gave that QP (p, v, a empty without one); nullptr as lastQp().
  const TrajectoryQpSolution* lastQpWarmStart() const { return last_qp_warm_.get(); }

 private:
  /// One replanning's working state, handed from stage to stage (defined in uav_planner.cpp).
  struct PlanContext;
  // The stages of plan(), in order (docs/planning.md §5–§8); a non-empty string is the reason
  // to fall back.
  std::string runStages(PlanContext& c, PlanResult& result);
  void projectReferences(PlanContext& c, PlanResult& result) const;
  void planPath(PlanContext& c, PlanResult& result) const;
  std::string buildCorridors(PlanContext& c) const;
  std::unique_ptr<CorridorBuilder> firstCorridorBuilder(const PlanContext& c) const;
  void setUpQp(PlanContext& c) const;
  static void guideAlongPath(PlanContext& c);
  void addCorridorRows(PlanContext& c, PlanResult& result) const;
  void addRecoveryRows(PlanContext& c, PlanResult& result) const;
  void addSeparationRows(PlanContext& c) const;
  void addBrakeEnvelopeRows(PlanContext& c, const PlannedTrajectory& other) const;
  Eigen::Vector3d linearisationPoint(const PlanContext& c, int k) const;
  std::string solveQp(PlanContext& c, PlanResult& result);
  std::string infeasibilityCause(const PlanContext& c, PlanResult& result);
  /// qp_truncate_on_infeasible: re-solves c.qp cut to K < N samples ending at rest (K = N/2, then
  /// 3N/4 or N/4: the largest that solves), warm-started from `warm` cut to K (may be null), no
  /// attempt once the time budget is spent; on success c.sol holds it, hovering from K to N.
  bool solveTruncated(PlanContext& c, const TrajectoryQpSolution* warm, PlanResult& result);
  std::string planCamera(PlanContext& c) const;
  std::string verifyAndAccept(PlanContext& c, PlanResult& result);
  PlanResult fallback(const PlanRequest& request, PlanResult result, const std::string& reason);
  /// Fallback 1: the last verified plan re-timed to t_now, if it covers enough, is near the state
  /// and verifies now (result filled, true); else false with why_not set.
  bool reusePrevious(const PlanRequest& request, PlanResult& result, std::string& why_not);
  PlannedTrajectory brakePlan(const PlanRequest& request) const;
  /// The brake plan `hold` with its stop point moved away from the other UAVs' plans and the
  /// worker's prediction it is closer to than Γ_dis / worker_safety_distance_m (+ qp buffer),
  /// after the stop at the recovery pace, if the move passes the verifier's obstacle and limit
  /// checks and comes no closer to any of them than `hold` at any time; `why` names the move.
  /// Empty: keep `hold`.
  std::optional<PlannedTrajectory> separateHoldPoint(const PlanRequest& request, const PlannedTrajectory& hold,
                                                     std::string& why) const;
  void aimCamera(const PlanRequest& request, PlannedTrajectory& trajectory) const;
  /// Reference step k turned about the worker out of the keep-out of the `silent` UAVs' plans
  /// (silent for as long as their keep-out's bound; docs/safety.md §1.2); true when it moved.
  bool aroundSilentUavs(const PlanContext& c, const std::vector<const PlannedTrajectory*>& silent, int k,
                        Eigen::Vector3d& r) const;
  void updateTrackingAllowance(const PlanRequest& request);
  /// Records request.wind_estimate_mps; returns the wind allowance (PlannerConfig::wind_allowance_*).
  double updateWindAllowance(const PlanRequest& request);

  PlannerConfig config_;
  std::string config_error_;
  std::shared_ptr<const OccupancyMap> map_;
  std::shared_ptr<const DistanceField> field_;
  std::shared_ptr<const SeenSpace> seen_;
  std::unique_ptr<TrajectoryVerifier> verifier_;
  std::unique_ptr<CorridorBuilder> corridors_;
  std::unique_ptr<GridPathSearch> search_;
  std::unique_ptr<TrajectoryQp> qp_;
  PlannedTrajectory last_verified_;
  /// aroundSilentUavs: the side (+1/-1 about the vertical) a reference turns round each silent UAV,
  /// the side of that silent UAV the UAV is on (seen from the worker) when the turn first happens,
  /// kept while that UAV stays silent.
  mutable std::map<int, double> silent_turn_side_;
  /// The brake plan being flown while replanning keeps failing (verified or not): its stop
  /// point is kept instead of braking anew from each state (empty when not braking).
  PlannedTrajectory brake_;
  /// The trajectory returned last (what the controller flies) and the tracking allowance
  /// measured against it (PlannerConfig::tracking_allowance_*), updated at allowance_t_s_.
  PlannedTrajectory flown_;
  double tracking_deviation_m_ = 0.0;
  double last_deviation_m_ = 0.0;  ///< the state's distance from flown_ at the last replanning
  double allowance_t_s_ = 0.0;
  /// Horizontal wind estimates of the last wind_window_s: their peak speed sizes the wind
  /// allowance, their mean gives the downwind direction (docs/safety.md §4.7, §4.13).
  struct WindSample {
    double t_s = 0.0;
    Eigen::Vector2d horizontal_mps = Eigen::Vector2d::Zero();
  };
  std::deque<WindSample> wind_speeds_;
  Eigen::Vector3d mean_wind_ = Eigen::Vector3d::Zero();  ///< horizontal mean of the window (z = 0)
  std::uint32_t sequence_ = 0;
  bool keep_last_qp_ = false;
  std::unique_ptr<TrajectoryQpProblem> last_qp_;
  std::unique_ptr<TrajectoryQpSolution> last_qp_warm_;
};

/// \brief Plans a formation in priority order (docs/design.md §4): planners[0] (the leader) first,
/// then followers in index order; request i gets the plans returned for 0..i−1 appended to
/// its higher_priority_plans (so each UAV avoids every higher-priority UAV's fresh plan).
/// Precondition: planners.size() == requests.size(). Deterministic.
std::vector<PlanResult> planInPriorityOrder(const std::vector<UavPlanner*>& planners, std::vector<PlanRequest> requests);

}  // namespace gesture_formation::planning

#pragma once
/// \file
/// \brief One UAV's planning request from what it knows (docs/design.md §4; docs/safety.md §1): the
/// stage-1 reference (eq. leader_ref on the worker's predicted trajectory for the leader;
/// eq. follower_ref relative to the leader's received plan — ^Lφ, ^Lξ per step — for a
/// follower; or a given hold reference) and the other UAVs' plans it plans around. Shared by
/// the simulated UAVs of `gfctl simulate` (sim::runMission) and the FormationPlanner nodelet,
/// so that both apply one avoidance rule:
/// - a follower always avoids the leader's received plan;
/// - with AvoidanceRule::avoid_all_plans (mission `faults.avoid_all_plans`, default) every
///   UAV avoids every other UAV's last received plan;
/// - otherwise (the paper's priority rule) UAV i avoids the plans of followers j < i, and
///   those flagged fallback or silent for longer than max_plan_age_s (right of way);
/// - in hold, every received plan.
/// Plans are added in the order: the leader's, then followers 1, 2, … (the planner's input).
/// Thread safety: pure function.

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/formation/formation_params.hpp"
#include "gesture_formation/planning/uav_planner.hpp"

namespace gesture_formation::planning {

/// \brief A plan received from another UAV with its sender's fallback flag (the sender's
/// planner returned its previous plan / braking, or it holds).
struct ReceivedPlan {
  PlannedTrajectory plan;
  bool fallback = false;
};

/// \brief Which received follower plans a UAV plans around (see the file comment).
struct AvoidanceRule {
  bool avoid_all_plans = true;  ///< every other UAV's plan (mission faults.avoid_all_plans)
  double max_plan_age_s = 1.0;  ///< the priority rule: a UAV not heard from for this long has right of way, > 0
};

/// \brief What one replanning of UAV `uav_index` starts from.
struct PlanRequestInputs {
  int uav_index = 0;                 ///< 0 = leader, i = follower i (priority order)
  /// The formation slot whose reference the UAV flies: 0 the leader's, j follower j's; −1: its own
  /// (uav_index). A UAV that took over the leadership flies slot 0; one that handed it over may fly
  /// the new leader's former slot (docs/safety.md §1.2).
  int slot = -1;
  /// The UAV whose plan leader_plan is (the acting leader): its entry of `received` is not avoided a
  /// second time. 0 unless the leadership changed hands.
  int leader_index = 0;
  double t_s = 0.0;                  ///< now; sample 0 of the reference
  double dt_s = 0.2;                 ///< horizon step [s]
  UavKinematicState state;  ///< the UAV's current (estimated) state
  /// The flight stack's wind estimate (world, m/s; non-finite: none) — PlanRequest::wind_estimate_mps.
  Eigen::Vector3d wind_estimate_mps = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  formation::WorkerHorizon worker;    ///< the worker's predicted trajectory (its steps = the horizon's)
  const formation::FormationParams* params = nullptr;  ///< required: the formation's parameters
  /// Followers: the leader's last received plan (null or empty: none; the reference then
  /// uses the leader's desired heading and pitch).
  const PlannedTrajectory* leader_plan = nullptr;
  /// The leader's plan shapes the reference only while t_s − its t0_s ≤ this (an older plan's
  /// heading and pitch are not the leader's now); it is avoided whatever its age (right of way).
  double leader_plan_max_age_s = std::numeric_limits<double>::infinity();
  /// The plans received from the other UAVs, indexed by sender (entries leader_index and
  /// uav_index are ignored); may be null.
  const std::vector<std::optional<ReceivedPlan>>* received = nullptr;
  /// Non-null: the UAV holds — this is its reference, and it avoids every received plan.
  const formation::ReferenceTrajectory* hold_reference = nullptr;
  /// Non-null: where the camera looks instead of the worker prediction (PlanRequest::camera_target).
  const formation::HorizonPoints* camera_target = nullptr;
  /// Non-null: every follower's elevation above the worker — its γ_i less the leader's planned
  /// pitch — is kept within limits.gamma_min_deg … gamma_max_deg by clamping that pitch (FormationState
  /// holds the rule for the leader's desired pitch −γ_L only; a leader above the worker plans down
  /// to the gimbal's −80° and would put the follower's reference over the worker's head).
  const formation::FormationLimits* limits = nullptr;
  AvoidanceRule rule;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The request (see the file comment). Preconditions: params non-null with a
/// follower entry for the slot flown; worker.steps() ≥ 1.
PlanRequest buildPlanRequest(const PlanRequestInputs& in);

// ---- hold (docs/safety.md §1 rules 2–4), shared by gfctl simulate and the FormationPlanner ----

/// \brief Age limits of the data a UAV plans from (mission `faults.*`; FormationPlanner params).
struct FreshnessLimits {
  double max_share_age_s = 2.0;   ///< a follower's leader share (worker state) since the leader sent it
  double max_worker_age_s = 3.0;  ///< the worker estimate since its last fused measurement
};

/// \brief Why UAV `uav_index` must hold at t_s (empty: it may track). The leader checks the age of
/// its estimate (worker_stamp_s = the last fused measurement); a follower first the age of the
/// leader's share (share_stamp_s = when the leader sent it), then of the estimate it carries.
/// Non-finite stamps count as infinitely old.
std::string holdReason(int uav_index, double t_s, double share_stamp_s, double worker_stamp_s,
                       const FreshnessLimits& limits);

/// \brief Where braking from velocity v at `brake_accel_mps2` ends: p + v|v|/(2a). A UAV entering
/// hold latches this point and holds it until it tracks again (docs/safety.md §1 rule 3).
Eigen::Vector3d brakingPoint(const Eigen::Vector3d& p_world, const Eigen::Vector3d& v_world, double brake_accel_mps2);

/// \brief The leader's camera search for a worker it lost (docs/safety.md §2.2): while it holds
/// because it has not seen the worker for more than max_worker_age_s, it stays at its hold point
/// (nothing moves on old data). As long as the estimator still extrapolates (constant velocity for
/// its lost_timeout_s) the camera follows that prediction, as in a plain hold; once the estimator
/// has lost him (the position is held where the model left it) the camera sweeps along the
/// vertical through that estimate, as far up and down as he could have climbed since he was last
/// seen — a worker on a tower climbs out of a camera that keeps looking where he was. With
/// horizontal_speed_mps > 0 the sweep also turns the camera left and right about the vertical
/// through the hold point, as far as a worker walking at that speed could have gone sideways
/// since he was last seen — a worker walking on the ground leaves the view sideways. Followers
/// hold as before.
struct SearchConfig {
  double timeout_s = 60.0;           ///< search for at most this long after the hold began, then look at the estimate; 0: never
  double height_m = 15.0;            ///< the sweep's largest offset above / below the estimate [m], > 0
  double vertical_speed_mps = 0.5;   ///< assumed climbing speed: the offset grows by this × the estimate's age, > 0
  double period_s = 8.0;             ///< up, back, down, back once [s], > 0
  /// Assumed walking speed for the sideways sweep [m/s], ≥ 0 (0: vertical sweep only): the
  /// camera turns ± atan(this × the estimate's age / horizontal distance to the estimate), left,
  /// back, right, back once every 2 × period_s. Default 1.5 m/s: a brisk walk.
  double horizontal_speed_mps = 1.5;
  // Ranges: planning::replanConfigFields() (faults.search_*).
};

/// \brief Whether UAV `uav_index` may search at t_s: the leader only, only for the hold reason
/// "worker not seen for more than max_worker_age_s", only until max_worker_age_s + timeout_s
/// after the last fused measurement. (HoldPlanner sweeps only once the estimator has lost him.)
bool searching(int uav_index, const std::string& hold_reason, double t_s, double worker_stamp_s,
               const FreshnessLimits& limits, const SearchConfig& config);

/// \brief The search's camera targets for steps k = 0..steps−1 at t_k = t_s + k·dt_s: the
/// estimate raised by A(t_k)·w(phase), A = min(height_m, vertical_speed × (t_k − worker_stamp_s)),
/// w a triangle wave 0 → 1 → 0 → −1 → 0 per period_s, phase 0 at sweep_begin_s (when the sweep
/// began): close to the estimate first, wider the longer he is lost. With horizontal_speed_mps > 0
/// the estimate is first turned about the vertical through `camera_world` by Θ(t_k)·w(phase / 2),
/// Θ = atan2(horizontal_speed × (t_k − worker_stamp_s), horizontal distance camera → estimate)
/// (≤ 90°; nothing turns when the camera is straight above or below the estimate).
formation::HorizonPoints searchTargets(const Eigen::Vector3d& worker_world, const Eigen::Vector3d& camera_world,
                                       double t_s, double dt_s, int steps, double worker_stamp_s, double sweep_begin_s,
                                       const SearchConfig& config);

/// \brief The hold reference: every step at `hold_world`, camera heading and pitch towards
/// `worker_world` (the worker estimate; `heading_rad` when straight above/below).
formation::ReferenceTrajectory holdReference(const Eigen::Vector3d& hold_world, const Eigen::Vector3d& worker_world,
                                             double heading_rad, int steps);

/// \brief What HoldPlanner decided.
enum class HoldMode { kTrack, kHold, kSearch };
/// \brief "track", "hold", "search".
const char* toString(HoldMode mode);

/// \brief The hold / search part of one UAV's replanning (docs/safety.md §1 rules 2–4, §2.2),
/// with its state — the latched braking point, the sweep's start. gfctl simulate's UAVs and the
/// FormationPlanner nodelet each own one and call decide() once per replanning, so both run the
/// same sequence. Not thread-safe (one per UAV, called from its planning thread).
class HoldPlanner {
 public:
  HoldPlanner() = default;
  HoldPlanner(const FreshnessLimits& limits, const SearchConfig& search, double brake_accel_mps2)
      : limits_(limits), search_(search), brake_accel_mps2_(brake_accel_mps2) {}

  /// What the UAV knows at one replanning.
  struct Situation {
    int uav_index = 0;
    double t_s = 0.0;
    double dt_s = 0.2;                  ///< horizon step [s]
    int steps = 0;                      ///< horizon steps
    std::string hold_reason;            ///< holdReason() or the caller's own rule; empty: track
    double worker_stamp_s = 0.0;        ///< the estimate's last fused measurement
    bool worker_lost = false;           ///< the estimator no longer extrapolates (HumanKalman::lost, WorkerState.lost)
    Eigen::Vector3d p_world = Eigen::Vector3d::Zero();   ///< the UAV's estimated position
    Eigen::Vector3d v_world = Eigen::Vector3d::Zero();   ///< … velocity
    double heading_rad = 0.0;                            ///< … heading
    Eigen::Vector3d worker_world = Eigen::Vector3d::Zero();  ///< the worker estimate at t_s (its prediction)
    EIGEN_MAKE_ALIGNED_OPERATOR_NEW
  };

  /// The decision: track (nothing else set), hold (reference) or search (reference + camera target).
  struct Decision {
    HoldMode mode = HoldMode::kTrack;
    formation::ReferenceTrajectory reference;  ///< hold / search: at the latched braking point, camera on worker_world
    formation::HorizonPoints camera_target;    ///< search: the sweep (steps columns); otherwise 0 columns
    bool holding() const { return mode != HoldMode::kTrack; }
  };

  /// \brief Decides (see the struct comments). Entering hold latches brakingPoint(p, v) until the
  /// UAV tracks again; the sweep's phase starts at the first replanning that searches and restarts
  /// after any replanning that does not.
  Decision decide(const Situation& s);

  /// The latched hold point (empty while tracking).
  const std::optional<Eigen::Vector3d>& holdPoint() const { return hold_p_; }

 private:
  FreshnessLimits limits_;
  SearchConfig search_;
  double brake_accel_mps2_ = 4.0;
  std::optional<Eigen::Vector3d> hold_p_;
  double sweep_begin_s_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace gesture_formation::planning

#pragma once
/// \file
/// \brief The abort mode of one UAV (docs/safety.md §2.8): once a UAV has accepted an abort
/// command it stops serving the formation and flies, along plans that pass the planner's usual
/// verification (ReplanStep; fallback: the last verified plan or braking, as always), to a retreat
/// goal of its own, then — by configuration — hovers there, returns to its take-off point, or
/// approaches a verified landing spot. Part of planning::ReplanStep, the step `gfctl simulate`'s UAVs
/// and the FormationPlanner nodelet share (in ROS the command arrives on the planner's abort_in:
/// docs/ros.md "Abort").
///
/// The retreat goal (chooseRetreatGoal) is chosen once, when the UAV first plans after accepting
/// the command, from what that UAV alone knows — its own position, the worker estimate, its index —
/// so that no UAV has to hear from another:
///   - it lies in the UAV's own *retreat layer*, the height retreat_height_m + i·layer_spacing_m
///     above the ground (z = 0, docs/conventions.md) for UAV i of n. Layers are layer_spacing_m apart
///     and layer_spacing_m ≥ Γ_dis (checked against the planner's qp.mutual_distance_m), so the
///     goals of two UAVs are at least Γ_dis apart whatever each one chose;
///   - it lies on one of the UAV's own *rings* around the worker estimate: horizontal distance
///     retreat_distance_m + (i + k·n)·layer_spacing_m, k = 0, 1, … up to max_distance_m. Two UAVs'
///     goals are then also layer_spacing_m apart horizontally (less the difference between the
///     worker estimates they chose from), so the spots straight below them — where they land —
///     keep Γ_dis too;
///   - its clearance from the map's obstacles (the planner's distance field) is ≥ goal_clearance_m,
///     and it lies inside the map's grid by that much;
///   - among the candidates — bearings from the worker out through the UAV's own position, then
///     ±bearing_step_deg, ±2·bearing_step_deg, … all round; along each, the UAV's rings — the one nearest to the UAV
///     wins (the shortest flight; it does not pick a point behind an obstacle when one beside it
///     will do); ties go to the earlier candidate of that order.
/// Thread safety: pure functions; AbortPlanner is not thread-safe (one per UAV).

#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/result.hpp"
#include "gesture_formation/formation/formation_commands.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/planning/shapes.hpp"

namespace gesture_formation::planning {

class DistanceField;

/// \brief What a UAV does once it has reached its retreat goal.
enum class AbortAfter {
  kHover,       ///< "hover": stays at the retreat goal
  kReturnHome,  ///< "return_home": flies to its take-off point and hovers there
  kLand,        ///< "land": approaches a verified landing spot (below the goal, else below home)
};
/// \brief "hover", "return_home", "land".
const char* toString(AbortAfter after);

/// \brief The abort settings (a mission's `abort.*`, read with the onboard settings:
/// onboard::OnboardSettings). Defaults documented per field; validate() names every bad key.
struct AbortConfig {
  double retreat_distance_m = 15.0;   ///< goal ≥ this horizontally from the worker estimate [m], > 0
  double retreat_height_m = 10.0;     ///< UAV 0's retreat layer above the ground [m], > 0
  double layer_spacing_m = 4.0;       ///< between the layers (height) and rings (distance) of UAV i and i+1 [m], ≥ Γ_dis
  double goal_clearance_m = 3.0;      ///< a goal's and a landing column's clearance from obstacles [m], > 0
  double max_distance_m = 45.0;       ///< goal search: farthest horizontal distance from the worker [m], ≥ retreat_distance_m
  double bearing_step_deg = 15.0;     ///< goal search: bearing step [deg], (0, 180]
  double speed_mps = 2.0;             ///< reference speed towards a goal [m/s], > 0, < the planner's max speed
  double arrival_tolerance_m = 1.0;   ///< a goal is reached within this distance … [m], > 0
  double arrival_speed_mps = 0.5;     ///< … at below this speed [m/s], > 0
  double land_height_m = 2.0;         ///< the landing approach ends this high above the spot [m], > 0
  /// An abort command older than this when it arrives is refused [s], > 0. Longer than the
  /// formation commands' max_command_age_s: a late abort is still wanted, an old replay is not.
  double max_command_age_s = 10.0;
  int repeats = 10;                   ///< the sender sends each abort command this many times, ≥ 1
  double repeat_period_s = 0.2;       ///< … this far apart [s], > 0
  /// … and then one copy this often for as long as it runs [s], [0.1, 60], ≥ repeat_period_s: a
  /// UAV out of reach for the whole burst (link outage, reboot) still receives it when it is back.
  double resend_period_s = 1.0;
  AbortAfter after = AbortAfter::kHover;  ///< `after: hover | return_home | land`

  /// \brief Every problem, each {key, "must be …, got v"} (keys as in the file, without prefix).
  std::vector<common::ConfigError> problems() const;
  /// \brief The same as lines "<key> <message>".
  std::vector<std::string> validate() const;
};

/// \brief AbortConfig's numbers with their ranges: the one place they are written.
const common::FieldTable<AbortConfig>& abortConfigFields();

/// \brief Reads an AbortConfig from `r`'s top level (a sub-reader over `abort`): every field and
/// `after`; problems recorded in `r`, each naming its key.
AbortConfig readAbortConfig(common::ConfigReader& r);

/// \brief The rules between the abort settings and the planner's: layer_spacing_m ≥ Γ_dis
/// (`mutual_distance_m`), speed_mps < `max_speed_mps`. Problems keyed under `prefix`.
std::vector<common::ConfigError> abortPlannerProblems(const AbortConfig& abort, double mutual_distance_m,
                                                      double max_speed_mps, const std::string& prefix);

/// \brief Who sent an abort.
enum class AbortSource { kOperator, kGesture };
const char* toString(AbortSource source);

/// \brief An abort command as it travels: id (sender, sequence), its source and when it was sent
/// (operator: by the ground station; gesture: when the leader's filter fired).
struct AbortCommand {
  formation::CommandId id;
  AbortSource source = AbortSource::kOperator;
  double sent_s = 0.0;
};

/// \brief What became of an abort command at one UAV.
enum class AbortAcceptance {
  kAccepted,         ///< this UAV aborts from now on
  kAlreadyAborting,  ///< a copy, a repeat or another abort: nothing changes
  kStale,            ///< older than max_command_age_s on arrival: refused (not aborting)
  /// Sent more than max_command_age_s after the time it arrived: a copy from another timeline (ROS
  /// time went back — the simulation restarted, a bag looped — while it was queued or repeated):
  /// refused (not aborting). Within that window a clock ahead of ours is tolerated: refusing a
  /// real abort costs more than honouring a copy a few seconds early.
  kFromTheFuture,
};
const char* toString(AbortAcceptance a);

/// \brief Where the abort finds its goals: the planner's distance field and the map's grid.
/// The field must outlive every user; null: no goal can be found (the UAV holds, with the reason).
struct RetreatSpace {
  const DistanceField* field = nullptr;
  Aabb bounds;                  ///< the map's grid (OccupancyMap::gridBounds)
  double resolution_m = 0.2;    ///< the map's voxel size (the field's lower-bound slack)
  double ground_height_m = 0.0;
};

/// \brief The retreat goal of UAV `uav_index` of `uav_count` (see the file comment); fails naming
/// why (no map, the layer outside the map, no free point in the search).
common::Result<Eigen::Vector3d> chooseRetreatGoal(int uav_index, int uav_count, const Eigen::Vector3d& p_uav_world,
                                                  const Eigen::Vector3d& p_worker_world, const RetreatSpace& space,
                                                  const AbortConfig& config);

/// \brief The landing approach point above the first verified spot of {below `goal_world`, below
/// `home_world` (none: the goal only)}: the column from the candidate's height down to land_height_m
/// above the ground keeps, at every 0.5 m, a clearance ≥ min(goal_clearance_m, height above the
/// ground − 2·resolution) (nothing closer beside or under it than the ground itself). Fails when
/// no candidate is clear.
common::Result<Eigen::Vector3d> chooseLandingPoint(const Eigen::Vector3d& goal_world,
                                                   const std::optional<Eigen::Vector3d>& home_world,
                                                   const RetreatSpace& space, const AbortConfig& config);

/// \brief Why the take-off point `home_world` may not be flown back to or landed below now ("" when
/// it may): it must be finite, inside the map by goal_clearance_m and ≥ retreat_distance_m
/// horizontally from the worker estimate `worker_world` — a planner restarted mid-mission takes its
/// first position, its slot beside the worker, for its take-off point.
std::string homeProblem(const Eigen::Vector3d& home_world, const Eigen::Vector3d& worker_world,
                        const RetreatSpace& space, const AbortConfig& config);

/// \brief Steps k = 0..steps−1 from `p_from_world` towards `goal_world` at `speed_mps` (dt_s per
/// step; at the goal once there), camera towards `worker_world` (heading `heading_rad` when
/// straight above or below it).
formation::ReferenceTrajectory approachReference(const Eigen::Vector3d& p_from_world, const Eigen::Vector3d& goal_world,
                                                 const Eigen::Vector3d& worker_world, double heading_rad,
                                                 double speed_mps, double dt_s, int steps);

/// \brief The abort's phases, in the order a UAV passes them.
enum class AbortPhase {
  kRetreat,     ///< "retreat": flying to the retreat goal
  kAtRetreat,   ///< "at_retreat": hovering at it (after: hover)
  kReturnHome,  ///< "return_home": flying to the take-off point
  kAtHome,      ///< "at_home": hovering there
  kLanding,     ///< "landing": flying to the landing approach point
  kLanded,      ///< "landed": at the approach point — touchdown is the flight stack's land mode
  kNoGoal,      ///< "no_goal": no retreat goal found — holds at its braking point (reason says why)
};
/// \brief The names above.
const char* toString(AbortPhase phase);
/// \brief True for the phases that end the abort's flying (at_retreat, at_home, landed, no_goal).
bool settled(AbortPhase phase);

/// \brief One UAV's abort sequence: the accepted command, the chosen goals, the phase. The
/// replanning step owns one and asks it for the reference while the UAV aborts.
class AbortPlanner {
 public:
  AbortPlanner() = default;
  AbortPlanner(int uav_index, int uav_count, const AbortConfig& config, const RetreatSpace& space)
      : uav_index_(uav_index), uav_count_(uav_count), config_(config), space_(space) {}

  /// \brief An abort command arriving at t_s (see AbortAcceptance). Repeats and copies change nothing.
  AbortAcceptance receive(const AbortCommand& command, double t_s);
  bool aborting() const { return command_.has_value(); }
  /// \brief The accepted command and when it was accepted (NaN before).
  const std::optional<AbortCommand>& command() const { return command_; }
  double acceptedAt() const { return accepted_s_; }

  /// What the UAV knows at one replanning.
  struct Situation {
    double t_s = 0.0;
    double dt_s = 0.2;
    int steps = 0;
    Eigen::Vector3d p_world = Eigen::Vector3d::Zero();       ///< estimated position
    Eigen::Vector3d v_world = Eigen::Vector3d::Zero();       ///< estimated velocity
    double heading_rad = 0.0;
    Eigen::Vector3d worker_world = Eigen::Vector3d::Zero();  ///< the worker estimate (frozen when stale)
    Eigen::Vector3d home_world = Eigen::Vector3d::Zero();    ///< the take-off point
    double brake_accel_mps2 = 4.0;                           ///< for the no-goal hold point
    EIGEN_MAKE_ALIGNED_OPERATOR_NEW
  };
  /// The decision of one replanning.
  struct Decision {
    AbortPhase phase = AbortPhase::kRetreat;
    formation::ReferenceTrajectory reference;
    std::string reason;  ///< one line: the phase and its goal, or why there is none
    bool phase_changed = false;
  };
  /// \brief Precondition: aborting(). The first call chooses the goal; each call advances the phase
  /// when its goal is reached (within arrival_tolerance_m, below arrival_speed_mps).
  Decision decide(const Situation& s);

  AbortPhase phase() const { return phase_; }
  /// The retreat goal (empty before the first decide() or without one).
  const std::optional<Eigen::Vector3d>& retreatGoal() const { return retreat_; }
  /// The goal of the current phase (empty without one).
  const std::optional<Eigen::Vector3d>& currentGoal() const { return goal_; }

 private:
  void chooseFirstGoal(const Situation& s, Decision& d);
  void advance(const Situation& s, Decision& d);

  int uav_index_ = 0;
  int uav_count_ = 1;
  AbortConfig config_;
  RetreatSpace space_;
  std::optional<AbortCommand> command_;
  double accepted_s_ = std::numeric_limits<double>::quiet_NaN();
  AbortPhase phase_ = AbortPhase::kRetreat;
  bool started_ = false;
  std::optional<Eigen::Vector3d> retreat_;
  std::optional<Eigen::Vector3d> goal_;
  std::string goal_note_;  ///< why there is no goal / the landing fallback
};

}  // namespace gesture_formation::planning

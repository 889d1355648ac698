#pragma once
/// \file
/// \brief The worker's predicted reach while a UAV holds or searches (docs/safety.md §3): where
/// an unseen worker can be by now, and the back-off that keeps every UAV clear of it. Part of
/// planning::ReplanStep, the step `gfctl simulate`'s UAVs and the FormationPlanner nodelet share.
///
/// The reach is a ball: centre the worker's position at his last fused measurement (the estimate
/// taken back along its velocity to that time while the estimator still extrapolates; the last
/// such position once it has lost him — the estimator then holds a position up to lost_timeout_s
/// of extrapolation away), radius base_m + walking_speed_mps × (t − the last fused measurement),
/// at most max_radius_m. A holding or searching UAV whose position or hold point is closer to the
/// reach than Γ_dis + margin_m (Γ_dis: the formation's limits.safety_distance_m) backs off, once
/// per hold, to a goal chosen for the *largest* reach (max_radius_m): the retreat goal of
/// planning::chooseRetreatGoal — the UAV's own height layer and rings of the abort, clear of the
/// obstacles — with the rings starting at max_radius_m + Γ_dis + margin_m from the centre. Once
/// there the reach cannot come closer than Γ_dis + margin_m however long the worker stays unseen;
/// a worker who walks further than max_radius_m from where he was last seen is kept out only by
/// the planner's worker keep-out around the (stale) estimate.
/// Thread safety: pure functions; ReachKeeper is not thread-safe (one per UAV).

#include <limits>
#include <optional>
#include <string>

#include <Eigen/Core>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/planning/abort_mode.hpp"

namespace gesture_formation::planning {

struct WorkerKnowledge;

/// \brief The reach's settings (mission `faults.reach_*`; FormationPlanner parameters of the same
/// last key segment). Ranges: planning::replanConfigFields().
struct ReachConfig {
  /// Assumed fastest walk of an unseen worker [m/s], ≥ 0 (0: the reach does not grow — the worker
  /// is assumed to stay where he was last seen, and a hold keeps its point). Default: a brisk walk.
  double walking_speed_mps = 1.5;
  double base_m = 1.0;          ///< radius at age 0: the estimate's error [m], ≥ 0
  double max_radius_m = 10.0;   ///< the reach stops growing here [m], > 0
  double margin_m = 1.0;        ///< back off when the reach comes closer than Γ_dis + this [m], ≥ 0
  /// Γ_dis to the worker [m]: the formation's limits.safety_distance_m, set by the step's owner
  /// (onboard::readOnboardSettings for a mission; the FormationPlanner from its formation config).
  double worker_min_distance_m = 2.5;
};

/// \brief Where an unseen worker can be at one time.
struct WorkerReach {
  Eigen::Vector3d centre_world = Eigen::Vector3d::Zero();  ///< his position at the last fused measurement [m]
  double radius_m = 0.0;                                   ///< [m]
  double age_s = 0.0;                                      ///< since the last fused measurement [s]
  bool capped = false;                                     ///< the radius reached max_radius_m
  /// \brief Distance from p_world to the ball (negative inside).
  double distanceTo(const Eigen::Vector3d& p_world) const { return (p_world - centre_world).norm() - radius_m; }
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The reach of a worker last fused age_s ago at centre_world (non-finite or negative age:
/// treated as infinitely old, i.e. capped).
WorkerReach workerReach(const Eigen::Vector3d& centre_world, double age_s, const ReachConfig& config);

/// \brief Whether a UAV at p_world must back off: the reach closer than Γ_dis + margin_m.
bool reachTooClose(const WorkerReach& reach, const Eigen::Vector3d& p_world, const ReachConfig& config);

/// \brief The back-off goal of UAV `uav_index` of `uav_count` (see the file comment): the abort's
/// retreat goal with its rings from max_radius_m + Γ_dis + margin_m around the reach's centre (and
/// max_distance_m extended by as much when it would be below that). Fails naming why.
common::Result<Eigen::Vector3d> chooseBackoffGoal(int uav_index, int uav_count, const Eigen::Vector3d& p_uav_world,
                                                  const WorkerReach& reach, const RetreatSpace& space,
                                                  const AbortConfig& abort, const ReachConfig& config);

/// \brief One UAV's reach keeping across the replannings of a hold: the reach's centre (kept
/// for the worker's last fused measurement once the estimator no longer extrapolates) and the
/// back-off goal, latched until the UAV tracks again or a new measurement is fused.
class ReachKeeper {
 public:
  ReachKeeper() = default;
  ReachKeeper(int uav_index, int uav_count, const ReachConfig& config, const AbortConfig& abort,
              const RetreatSpace& space)
      : uav_index_(uav_index), uav_count_(uav_count), config_(config), abort_(abort), space_(space) {}

  /// \brief Every replanning: the worker knowledge (the reach's centre; call also while tracking).
  void observe(const WorkerKnowledge& w);

  /// What a holding UAV knows at one replanning.
  struct Situation {
    double t_s = 0.0;
    Eigen::Vector3d p_world = Eigen::Vector3d::Zero();     ///< the UAV's estimated position
    Eigen::Vector3d hold_world = Eigen::Vector3d::Zero();  ///< its hold point
    double fused_s = std::numeric_limits<double>::quiet_NaN();  ///< the worker's last fused measurement
    EIGEN_MAKE_ALIGNED_OPERATOR_NEW
  };
  /// The decision: a goal to back off to (empty: keep the hold point), and a line for the log.
  struct Decision {
    std::optional<Eigen::Vector3d> goal;
    bool started = false;  ///< the back-off began at this replanning
    std::string reason;    ///< backing off: where to and why; no goal found: why (empty otherwise)
    WorkerReach reach;
  };
  /// \brief While holding or searching (see the file comment).
  Decision decide(const Situation& s);
  /// \brief The UAV tracks (or aborts): the back-off ends.
  void release() { goal_.reset(); failed_ = false; }

  /// The latched back-off goal (empty while none).
  const std::optional<Eigen::Vector3d>& goal() const { return goal_; }
  const ReachConfig& config() const { return config_; }

 private:
  int uav_index_ = 0;
  int uav_count_ = 1;
  ReachConfig config_;
  AbortConfig abort_;
  RetreatSpace space_;
  std::optional<Eigen::Vector3d> centre_;  ///< the worker at centre_fused_s_
  double centre_fused_s_ = std::numeric_limits<double>::quiet_NaN();
  std::optional<Eigen::Vector3d> goal_;
  bool failed_ = false;  ///< no goal found in this hold (not searched again until released)
  std::string fail_reason_;
};

}  // namespace gesture_formation::planning

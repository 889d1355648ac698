#pragma once
/// \file
/// \brief What the ROS simulation's world (the SimWorld nodelet) records from the running system,
/// ROS-free: the planners' plans and mode changes, the leader's parameter versions and what became
/// of each command it handled, and the mission's files at the end — the bookkeeping around
/// sim::MetricsAccumulator that `gfctl simulate` does inside its own loop (docs/ros.md "SimWorld").
/// Thread safety: none (the caller's lock).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "gesture_formation/sim/abort_drill.hpp"
#include "gesture_formation/sim/mission_metrics.hpp"
#include "gesture_formation/sim/multirotor.hpp"
#include "gesture_formation/sim/worker_approach.hpp"
#include "gesture_formation/sim/worker_model.hpp"

namespace gesture_formation::sim {

/// \brief One plan as a planner published it.
struct PlanReport {
  int uav = 0;
  double planned_at_s = 0.0;
  std::uint64_t params_version = 0;  ///< as the plan says (a follower's comes without it: 0)
  /// The parameters the plan lists (nullopt: none, or unreadable).
  std::optional<formation::FormationParams> formation;
  planning::PlanStatus status = planning::PlanStatus::kOptimized;
  double planning_ms = 0.0;
  std::string reason;
  std::string mode;         ///< track | hold | search | abort (empty: not said)
  std::string mode_reason;  ///< why (empty: fresh data)
};

/// \brief The leader's parameters as published, with the last command it handled (re-published
/// parameters repeat it).
struct ParamsReport {
  std::optional<formation::FormationParams> params;  ///< nullopt: unreadable
  std::uint64_t version = 0;
  double stamp_s = 0.0;
  std::string last_command;  ///< empty: none handled yet
  std::string last_status;   ///< applied | duplicate | rejected | …
  std::string last_source;
  double last_command_stamp_s = 0.0;
  std::vector<int> last_uavs;
};

/// \brief One UAV's abort state as its planner published it (AbortState): its phase (nullopt: not
/// aborting), when it accepted the command and from whom.
struct AbortReport {
  int uav = 0;
  double t_s = 0.0;  ///< when the state was decided
  std::optional<planning::AbortPhase> phase;
  double accepted_s = 0.0;
  planning::AbortSource source = planning::AbortSource::kOperator;
};

class WorldRecord {
 public:
  /// A command outcome goes to the earliest pending request of its source issued at the command's
  /// stamp ± this. An operator command reaches the leader stamped by the ground LcmBridge when it
  /// sent it (the envelope stamp: the world process's clock, a tick or two after the request) — by
  /// a repeated copy when the first ones were lost on the radio (LcmBridge command_repeats ×
  /// command_repeat_period_s: 0.4 s later with 5 × 0.1 s); a gesture command keeps the classifier
  /// output's stamp (the fire time).
  static constexpr double kStampToleranceS = 0.6;

  /// \brief `config` and `obstacles`' pointers must outlive the record (as MetricsAccumulator's).
  WorldRecord(const MissionConfig& config, const ObstacleDistance& obstacles, std::uint64_t seed);

  /// \brief A plan: its status and timing (metrics, with the parameter version it was made with),
  /// a hold / search replanning, and the planner's mode when it changed (modes.csv).
  void plan(const PlanReport& p);
  /// \brief The leader's parameters (the current ones, their version) and, once per (command,
  /// status), what became of its last command.
  void params(const ParamsReport& p);

  /// \brief The mission's operator requests due at t_s (in order, each once), recorded as pending
  /// ("lost" until the leader says what it did with them) and resolved with the outcomes known.
  std::vector<formation::FormationCommand> dueRequests(double t_s);
  /// \brief faults.abort by the operator: true once, at the first t_s ≥ its time — the world then asks
  /// the ground station's OperatorInterface for it (as an operator does: send_abort), and the abort
  /// is recorded from its time on (metrics.json `abort`, as `gfctl simulate`). A gesture-source
  /// faults.abort is not injected here (the worker's gesture takes the gesture path): false.
  bool abortDue(double t_s);
  /// \brief A UAV's abort state: its acceptance and phases into the abort record (an abort accepted
  /// without faults.abort, e.g. a recognised gesture, is recorded from its acceptance on).
  void abortState(const AbortReport& r);
  /// \brief A gesture the leader's filter fired at t_s (dominant id `gesture_id`), recorded and
  /// resolved like a request.
  void gestureFired(double t_s, int gesture_id, const gesture::GestureMapping& mapping);
  /// \brief faults.worker_approach at its time (once, when UAV `uav`'s truth is known): the worker
  /// turns towards that UAV (divertTowards); its unseen phase is then recorded with the safety.
  void divertWorker(double t_s, WorkerModel& worker, const std::vector<std::optional<MultirotorState>>& truths);
  /// \brief Safety at t_s from every UAV's true state (and the approach's figures): false (nothing
  /// sampled) while some UAV has not reported one yet.
  bool sampleSafety(double t_s, const std::vector<std::optional<MultirotorState>>& truths, const WorkerState& worker);

  MetricsAccumulator& metrics() { return metrics_; }
  /// \brief The leader's latest parameters (the mission's until it published).
  const formation::FormationParams& currentParams() const { return params_; }
  const std::vector<ModeChange>& modes() const { return modes_; }

  /// \brief Ends the mission: the metrics (with what the ROS system does not report listed as not
  /// measured) and every file into `dir`, metrics.json last. False with `error` set if writing
  /// failed; `warning` names command outcomes that matched no request (empty: none).
  bool finish(const std::vector<GestureEpisode>& gestures, double sim_time_s, double wall_time_s,
              const std::string& dir, std::string* error, std::string* warning);

 private:
  /// The parameter version a plan was made with: the leader's says it; a follower's is taken as the
  /// latest version the leader published with exactly the parameters the plan lists (the version it
  /// received with them over LCM; matched by parameters, as before the version travelled).
  std::uint64_t planVersion(const PlanReport& p) const;

  int n_;
  MetricsAccumulator metrics_;
  OperatorSchedule schedule_;  ///< the mission's operator requests
  ParamsVersions versions_;  ///< every parameter version the leader published (0: the mission's)
  formation::FormationParams params_;
  std::vector<std::string> plan_mode_;  ///< per UAV: the mode of its last plan
  std::vector<ModeChange> modes_;       ///< every planner mode change
  std::string last_outcome_key_;        ///< the last (command, status) counted
  const MissionConfig& config_;
  std::optional<ApproachRecorder> approach_;  ///< faults.worker_approach, once the worker turned
  ObstacleDistance obstacles_;                ///< the obstacle-distance metric (the abort's)
  bool abort_requested_ = false;              ///< faults.abort asked for
  std::optional<AbortRecorder> abort_;        ///< the abort, from its issue
};

}  // namespace gesture_formation::sim

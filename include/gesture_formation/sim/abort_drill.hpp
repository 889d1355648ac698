#pragma once
/// \file
/// \brief The simulator's side of an abort (docs/simulation.md §3, docs/safety.md §2.8): the
/// injected event (`faults.abort: {t_s, source}`, the fault profile `abort_mid_mission`), the
/// operator's repeated sending of it, and its metrics (metrics.json `abort`). What each UAV does
/// with the command is the product's planning::AbortPlanner inside planning::ReplanStep.
/// Thread safety: value types; one AbortRecorder per mission.

#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/planning/abort_mode.hpp"

namespace gesture_formation::sim {

/// \brief An abort issued at t_s by the operator (the ground station sends it to every UAV over the
/// operator link, repeated abort.repeats times abort.repeat_period_s apart) or by the worker's
/// gesture (accepted by the leader's gesture pipeline at t_s — the recognition itself is not
/// simulated by this event; a gesture mapped to {event: abort} that the pipeline recognises takes
/// the same path). Every UAV relays the abort it accepted to the others every replanning period.
struct AbortEvent {
  double t_s = 0.0;
  planning::AbortSource source = planning::AbortSource::kOperator;
};

/// \brief Reads `faults.abort` at `key` ({t_s ≥ 0 (required), source: operator | gesture}); absent:
/// leaves `out` empty. Problems recorded in `r`, each naming its key.
void readAbortEvent(common::ConfigReader& r, const std::string& key, std::optional<AbortEvent>& out);

/// \brief The operator's copies of the abort as they fall due: one command (id "operator-abort" #1),
/// sent `repeats` times `period_s` apart from the event's time, then once every `resend_period_s`
/// for the rest of the mission (a UAV out of reach for the whole burst still receives it).
class AbortSender {
 public:
  AbortSender(const std::optional<AbortEvent>& event, int repeats, double period_s, double resend_period_s)
      : event_(event), repeats_(repeats), period_s_(period_s), resend_period_s_(resend_period_s) {}
  /// \brief The copies due at or before t_s not returned before (each copy the same command,
  /// stamped when it falls due).
  std::vector<planning::AbortCommand> due(double t_s);
  /// \brief The command (no copy sent yet: still the same).
  planning::AbortCommand command() const;

 private:
  /// When copy k (0-based) falls due.
  double dueAt(int k) const;
  std::optional<AbortEvent> event_;
  int repeats_ = 1;
  double period_s_ = 0.2;
  double resend_period_s_ = 1.0;
  int sent_ = 0;
};

/// \brief One UAV's abort, as measured.
struct UavAbortRecord {
  double accepted_s = std::numeric_limits<double>::quiet_NaN();  ///< when it accepted the command
  /// When it reached its retreat goal (left `retreat`; NaN: never).
  double retreat_reached_s = std::numeric_limits<double>::quiet_NaN();
  /// When it settled (at_retreat / at_home / landed / no_goal; NaN: never).
  double settled_s = std::numeric_limits<double>::quiet_NaN();
  std::string phase = "none";  ///< its last phase
  // From the abort's issue to the end of the mission (true positions):
  double min_worker_distance_m = std::numeric_limits<double>::infinity();    ///< to the worker's position
  double min_obstacle_distance_m = std::numeric_limits<double>::infinity();  ///< the obstacle-distance metric
  double min_uav_distance_m = std::numeric_limits<double>::infinity();       ///< to any other UAV
};

/// \brief The abort of one mission (metrics.json `abort`).
struct AbortSummary {
  double issued_s = 0.0;
  std::string source;
  std::vector<UavAbortRecord> uavs;
  /// The largest settled_s − issued_s over the UAVs (NaN when one never settled).
  double time_to_settle_max_s() const;
};

/// \brief Accumulates an AbortSummary (see UavAbortRecord).
class AbortRecorder {
 public:
  /// \param obstacle_distance the mission's obstacle-distance metric.
  AbortRecorder(const AbortEvent& event, int uav_count, std::function<double(const Eigen::Vector3d&)> obstacle_distance);
  void accepted(int uav, double t_s);
  void phase(int uav, double t_s, planning::AbortPhase phase);
  /// \brief True positions at t_s (from the issue on).
  void sample(double t_s, const std::vector<Eigen::Vector3d>& p_world, const Eigen::Vector3d& worker_world);
  const AbortSummary& summary() const { return summary_; }

 private:
  AbortSummary summary_;
  std::function<double(const Eigen::Vector3d&)> obstacle_distance_;
};

/// \brief The summary as a JSON object (keys per UavAbortRecord; non-finite → null), indented by `indent`.
std::string abortJson(const AbortSummary& summary, int indent);

}  // namespace gesture_formation::sim

#pragma once
/// \file
/// \brief The leader hand-over in `gfctl simulate` (docs/safety.md §1.2, docs/simulation.md §3):
/// every UAV runs a formation::Leadership (settings `mission.leadership.*`), whose messages cross
/// the inter-UAV link model all-to-all (LeadershipNet: one link per direction and pair, the fault
/// model of the shares — loss, delay, jitter, duplication, reordering — and dropped while a UAV's
/// radio is down); the fault `faults.leader_silence` silences the UAV leading at its time
/// (profiles leader_dropout_5s / _60s / _for_good), and HandoverRecorder measures who acts as
/// leader at every step, how long the formation had none, and whether two ever acted at once.
///
/// The simulator's clocks are the mission time for every UAV (no drift: ρ is still used for the
/// promise, as configured). Before the mission (t < 0) the network runs for kWarmupS, so the
/// designated leader (UAV 0, term 1) holds its lease from t = 0 — the election a formation runs
/// on the ground before take-off.
/// Thread safety: none (one mission, one thread).

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/formation/leadership.hpp"
#include "gesture_formation/sim/link.hpp"

namespace gesture_formation::sim {

/// \brief `faults.leader_silence: {t_s, duration_s}`: at t_s the UAV acting as leader then (UAV
/// 0 when none acts) goes silent — its radio dead both ways: it neither sends nor receives
/// (shares, plans, votes, leadership messages, operator and abort copies) and does not replan
/// (nothing it could verify against the others' plans): its flight controller flies the last
/// loaded, verified plan to its end and holds (hovers at) its last point. After duration_s it
/// hears again: it rejoins like a rebooted follower (listening first) and learns the newer term
/// from the others' messages. Without duration_s it is silent for good: it hovers at its last
/// plan's end for the rest of the mission (it does not land: a landing plan nobody knows of is
/// not verified against the others).
struct LeaderSilence {
  double t_s = 0.0;                                               ///< [s], ≥ 0 (required)
  double duration_s = std::numeric_limits<double>::infinity();  ///< [s], > 0; +inf: for good
  bool forGood() const { return !(duration_s < std::numeric_limits<double>::infinity()); }
  bool silentAt(double t) const { return t >= t_s && (forGood() || t < t_s + duration_s); }
};

/// \brief Reads `faults.leader_silence` at `key` (t_s required; duration_s absent: for good).
/// Problems recorded in `r`, each naming its key and value.
void readLeaderSilence(common::ConfigReader& r, const std::string& key, std::optional<LeaderSilence>& out);

/// \brief Reads `<mission>leadership.*` (formation::leadershipFields(); uav_count is the
/// mission's — an explicit different one is an error) and records every problem in `r`.
void readLeadership(common::ConfigReader& r, const std::string& mission_prefix, int uav_count,
                    formation::LeadershipConfig& out);

/// \brief Every UAV's Leadership and the links between them (see the file comment).
class LeadershipNet {
 public:
  static constexpr double kWarmupS = 2.0;  ///< the network runs this long before t = 0

  /// \param rngs one RNG per directed pair (from, to), from ≠ to, in the order (0,1), (0,2), …,
  /// (1,0), (1,2), … — uav_count·(uav_count − 1) of them. Runs the warm-up at `step_s`.
  LeadershipNet(const formation::LeadershipConfig& config, const LinkConfig& link, std::vector<std::mt19937_64> rngs,
                double step_s);

  /// \brief At t_s: delivers what arrived (to the UAVs whose radio is up), answers, ticks every
  /// UAV (a UAV whose radio is down keeps its timers, its messages are lost).
  /// `estimate_age_s[i]`: UAV i's worker estimate age (+inf: none).
  void step(double t_s, const std::vector<double>& estimate_age_s, const std::vector<bool>& radio_up);

  bool acting(int uav, double t_s) const { return members_[static_cast<std::size_t>(uav)]->acting(t_s); }
  const formation::Leadership& member(int uav) const { return *members_[static_cast<std::size_t>(uav)]; }
  int count() const { return static_cast<int>(members_.size()); }
  LinkCounters counters() const;

 private:
  void send(double t_s, int from, const std::vector<formation::LeadershipMessage>& out, const std::vector<bool>& radio_up);
  Link<formation::LeadershipMessage>& link(int from, int to);

  std::vector<std::unique_ptr<formation::Leadership>> members_;
  std::vector<std::unique_ptr<Link<formation::LeadershipMessage>>> links_;  ///< see the constructor
};

/// \brief One interval during which `uav` acted as leader (−1: none acted).
struct LeaderInterval {
  double from_s = 0.0, to_s = 0.0;
  int uav = -1;
};

/// \brief metrics.json `leadership`.
struct HandoverSummary {
  std::vector<LeaderInterval> leaders;  ///< who acted, over the whole mission (−1: nobody)
  int max_acting = 0;                   ///< most UAVs acting at one step (≤ 1 required)
  int steps_two_acting = 0;             ///< steps at which more than one acted
  std::uint64_t elections_won = 0;      ///< over the UAVs (the designated leader's term 1 is not one)
  std::uint64_t leadership_messages_sent = 0, leadership_messages_lost = 0;
  // The silence (faults.leader_silence); NaN / −1 without one.
  int silenced_uav = -1;
  double silent_from_s = std::numeric_limits<double>::quiet_NaN();
  double silent_to_s = std::numeric_limits<double>::quiet_NaN();  ///< +inf: for good
  double silenced_last_acting_s = std::numeric_limits<double>::quiet_NaN();  ///< its lease's end as seen
  int new_leader = -1;  ///< the first other UAV to act after silent_from_s
  double new_leader_s = std::numeric_limits<double>::quiet_NaN();
  /// new_leader_s − silent_from_s: the time to a new acting leader [s].
  double handover_s = std::numeric_limits<double>::quiet_NaN();
  int requests_after = 0;          ///< operator requests sent from new_leader_s on
  int requests_after_applied = 0;  ///< … of which applied
};

/// \brief Accumulates a HandoverSummary from every step's acting flags.
class HandoverRecorder {
 public:
  explicit HandoverRecorder(int uav_count) : acting_(static_cast<std::size_t>(uav_count), false) {}
  /// \brief The acting flags at t_s (one per UAV).
  void sample(double t_s, const std::vector<bool>& acting);
  /// \brief The silence began at t_s, silencing `uav`.
  void silenced(int uav, double t_s, const LeaderSilence& silence);
  /// \brief Closes the last interval at t_end_s; `requests`: (sent_s, applied) of every operator request.
  HandoverSummary finish(double t_end_s, const std::vector<std::pair<double, bool>>& requests,
                         const LeadershipNet& net) const;

 private:
  HandoverSummary s_;
  std::vector<bool> acting_;
  int current_ = -2;  ///< the acting UAV of the open interval (−1 none, −2 before the first sample)
};

/// \brief The summary as a JSON object (non-finite → null; +inf silent_to_s → "for_good"),
/// indented by `indent`.
std::string handoverJson(const HandoverSummary& summary, int indent);

}  // namespace gesture_formation::sim

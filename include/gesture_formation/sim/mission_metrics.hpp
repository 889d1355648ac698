#pragma once
/// \file
/// \brief The mission's metrics (docs/design.md §8.4; docs/simulation.md §4 defines each), measured
/// the same way by `gfctl simulate` (sim::runMission) and by the ROS simulation (the SimWorld
/// nodelet): an accumulator fed with true UAV states, the worker's truth, the leader's
/// parameters, camera frames, plans and requests; its finish() gives the metrics struct, the
/// timeline and the request records; the writers produce metrics.json, timeline.csv,
/// events.csv and modes.csv.
///
/// What the callers feed (the sampling rates are theirs; docs/simulation.md §4):
/// - sampleSafety(): every plant step (gfctl simulate: 10 ms) — true positions;
/// - sampleTimeline(): at the timeline rate (mission.timeline_rate_hz) — true states,
///   the leader's current parameters and ^Hφ;
/// - cameraFrame(): every leader camera frame — visibility and the worker estimate
///   predicted to the frame time;
/// - plan(): every replanning of every UAV, with the parameter version it used;
/// - addRequest() / requestOutcome(): every operator request (sent) and fired gesture, and
///   what the leader's FormationState did with its command.
/// Gesture matching and adaptation starts are computed in finish() from what was fed, so the
/// order in which a caller learns of plans and outcomes does not matter (ROS: they arrive on
/// different connections).
///
/// Thread safety: none (one accumulator per mission; the caller serialises).

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/formation/formation_commands.hpp"
#include "gesture_formation/formation/formation_params.hpp"
#include "gesture_formation/gesture/gesture_mapping.hpp"
#include "gesture_formation/gesture/view_fusion.hpp"
#include "gesture_formation/planning/shapes.hpp"
#include "gesture_formation/planning/uav_planner.hpp"
#include "gesture_formation/sim/assistance_drill.hpp"
#include "gesture_formation/sim/mission_config.hpp"
#include "gesture_formation/sim/multirotor.hpp"
#include "gesture_formation/sim/perception_truth.hpp"
#include "gesture_formation/sim/site_metrics.hpp"
#include "gesture_formation/sim/worker_model.hpp"

namespace gesture_formation::planning {
class DistanceField;
}  // namespace gesture_formation::planning

namespace gesture_formation::sim {

/// \brief docs/design.md §8.4 metrics (docs/simulation.md §4 defines each) plus diagnostics.
struct MissionMetrics {
  double min_mutual_distance_m = 0.0;
  double min_obstacle_distance_m = 0.0;
  int min_obstacle_uav = -1;            ///< which UAV (0 = leader) and when (s): diagnostics
  double min_obstacle_t_s = 0.0;
  double min_human_distance_m = 0.0;
  int collisions = 0;
  double distance_error_rms_m = 0.0;
  double angle_error_rms_deg = 0.0;
  int requests_applied = 0;
  double gesture_success_rate = 0.0;   ///< NaN when no gesture was performed
  double gesture_mean_latency_s = 0.0;  ///< NaN when no gesture was matched
  int false_adaptations = 0;
  double planning_ms_median = 0.0;     ///< wall clock
  double planning_ms_p99 = 0.0;        ///< wall clock
  double planning_ms_max = 0.0;        ///< wall clock: the slowest replanning (a failed one names its cause: ≤ 4 solves)
  double human_estimate_error_rms_m = 0.0;
  // diagnostics
  int requests_total = 0;              ///< operator requests + gestures performed
  int operator_requests_applied = 0;
  int gesture_requests_applied = 0;
  int gestures_performed = 0;
  int gestures_successful = 0;
  int plans = 0, plans_fallback_previous = 0, plans_fallback_brake = 0, plans_skipped = 0;
  int qp_sparse_timeouts = 0;  ///< QP solves stopped (deadline, or the sparse solver broke an invariant), docs/safety.md §4.5
  int plans_hold = 0;          ///< replannings in hold mode (stale data, docs/safety.md)
  int commands_stale = 0;      ///< operator commands older than faults.max_command_age_s on arrival (rejected)
  int commands_duplicate = 0;  ///< duplicate command copies (ignored by the FormationState)
  int range_outliers = 0;      ///< injected gross range errors (faults.range_outliers)
  long messages_sent = 0, messages_lost = 0, messages_duplicated = 0, messages_reordered = 0;  ///< inter-UAV links
  /// Why replannings failed: the planner's first reason with numbers replaced by '#' → count.
  std::map<std::string, int> plan_failure_reasons;
  double visible_fraction = 0.0;       ///< camera frames with a detection
  double sim_time_s = 0.0;
  double wall_time_s = 0.0;
  double real_time_factor = 0.0;       ///< sim / wall
  std::uint64_t seed = 0;
  /// Diagnostic keys the producer cannot observe (the ROS simulation: e.g. `plans_hold`,
  /// `messages_sent`): written as null and listed in metrics.json `not_measured_keys`.
  /// Empty for gfctl simulate.
  std::vector<std::string> not_measured;
  /// The rendered camera's perception against the truth (docs/simulation.md §8); absent for the
  /// synthetic camera (metrics.json then has no `perception` key).
  std::optional<PerceptionSummary> perception;
  /// The abort of the mission (faults.abort; docs/safety.md §2.8); absent without one
  /// (metrics.json then has no `abort` key).
  std::optional<AbortSummary> abort;
  /// The worker's walk towards a UAV (faults.worker_approach; docs/safety.md §3); absent without
  /// one (metrics.json then has no `worker_approach` key).
  std::optional<ApproachSummary> worker_approach;
  /// The unmapped obstacles and the UAVs' online mapping (site_mapping.hpp); absent when the
  /// scenario has no unmapped obstacles and mapping is off (metrics.json then has no
  /// `site_mapping` key).
  std::optional<SiteMappingSummary> site_mapping;
  /// Who acted as leader when, and the hand-over after faults.leader_silence (docs/safety.md
  /// §1.2); absent where not measured (the ROS simulation: metrics.json then has no `leadership`).
  std::optional<HandoverSummary> leadership;
  /// The worker's assistance requests and the operator's acknowledgements (docs/safety.md §2.10);
  /// absent when the mission had neither (metrics.json then has no `assistance` key).
  std::optional<AssistanceSummary> assistance;
};

/// \brief One UAV's part of a timeline sample (docs/design.md §8.4 timeline.csv).
struct UavSample {
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();
  double d_t = 0, d_ref = 0, d_o = 0;        ///< worker distance, its reference, obstacle clearance [m]
  double phi_deg = 0, phi_ref_deg = 0;       ///< observation angle (azimuth UAV → worker) and reference
  double elev_deg = 0, elev_ref_deg = 0;     ///< elevation of the UAV above the worker and reference
  double heading_deg = 0, pitch_deg = 0;     ///< camera
  double speed_mps = 0;
  int plan_status = -1;                      ///< last planner status (PlanStatus as int; −1 none)
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};
/// \brief One timeline sample.
struct TimelineRow {
  double t_s = 0.0;
  Eigen::Vector3d worker_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d estimate_world = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  int visible = 0;
  int gesture_true = 0;        ///< gesture being performed (0 none)
  int gesture_class = -1;      ///< last classifier output (−1 none)
  double dominant_ratio = 0.0;  ///< gesture filter f_d
  std::vector<UavSample> uavs;
  std::vector<double> mutual_m;  ///< pairs (0,1), (0,2), …, (1,2), …
  std::vector<int> acting;       ///< per UAV: 1 while it acts as leader (empty: not recorded)
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief A request (operator or fired gesture) and what became of it.
struct RequestRecord {
  double t_s = 0.0;            ///< operator: sent; gesture: fired
  std::string source;          ///< "operator" | "gesture"
  std::string description;     ///< e.g. "all.beta_deg +30"
  std::string status;          ///< applied | duplicate | rejected | lost | stale | event | unmapped
  double applied_s = std::numeric_limits<double>::quiet_NaN();
  double adaptation_start_s = std::numeric_limits<double>::quiet_NaN();  ///< first plan with the new parameters
  int gesture_id = 0;
  int matched_episode = -1;    ///< gesture: index into worker episodes, −1 unmatched (false adaptation)
  std::vector<int> uavs;       ///< addressed UAVs
  std::uint64_t params_version = 0;
};

/// \brief A UAV's safety mode changed (docs/safety.md): track (fresh data, formation
/// reference) | hold (stale or missing data: stop and keep position, avoid everyone) |
/// outage (planner not running: loaded plan to its end) | offline (follower dropout) |
/// rejoin (back online, listening before it moves).
struct ModeChange {
  double t_s = 0.0;
  int uav = 0;
  std::string mode;
  std::string reason;
};

/// \brief One replanning of one UAV (plans.csv): what became of it and why.
struct PlanRecord {
  double t_s = 0.0;
  int uav = 0;
  std::uint64_t params_version = 0;
  planning::PlanStatus status = planning::PlanStatus::kOptimized;
  double planning_ms = 0.0;  ///< wall clock: the one column that differs between two runs of a seed
  std::string reason;        ///< empty when optimised
};

/// \brief One gesture frame the acting leader's vote closed (votes.csv): what each camera read for
/// it, the vote and the filter — why a gesture fired or did not (docs/simulation.md §3).
struct VoteRecord {
  double t_s = 0.0;            ///< the frame's stamp
  int leader = 0;              ///< the UAV whose vote it is
  std::vector<int> view_ids;   ///< per UAV: the gesture id its camera read for the frame (−1: none reached the vote)
  gesture::FusedGesture fused;  ///< the vote (the id that went to the filter, views, 3-D check)
  int dominant_id = -1;        ///< gesture::GestureFilterOutput
  double dominant_ratio = 0.0;
  bool fired = false;
};

/// \brief Everything a mission produces (the files of docs/simulation.md §3).
struct MissionOutput {
  MissionMetrics metrics;
  std::vector<ModeChange> modes;
  std::vector<PlanRecord> plans;  ///< every replanning, in the order fed (plans.csv)
  std::vector<TimelineRow> timeline;
  std::vector<RequestRecord> requests;
  std::vector<GestureEpisode> gestures;  ///< performed by the worker
  std::vector<PerceptionRecord> perception;  ///< rendered camera: per frame and UAV (perception.csv)
  std::vector<VoteRecord> votes;             ///< every gesture frame the vote closed (votes.csv)
};

/// \brief The obstacle-distance metric (docs/simulation.md §4): within
/// kExactWithinM of an obstacle (by the distance field) the exact distance from the point to
/// `solids` and to the ground plane at `ground_height_m`; farther, the field's value. Without
/// solids, the field's value everywhere (distance to occupied voxel centres).
struct ObstacleDistance {
  static constexpr double kExactWithinM = 2.5;
  const planning::DistanceField* field = nullptr;  ///< required; must outlive this
  const planning::PrimitiveSet* solids = nullptr;  ///< may be null; must outlive this
  double ground_height_m = 0.0;                    ///< used with solids (−1e9: no ground)
  /// Obstacles besides the mapped ones (the unmapped obstacles at the mission's clock,
  /// SiteMapping::withUnmapped): the distance is the least of both. Empty: none.
  std::function<double(const Eigen::Vector3d&)> extra = nullptr;
  /// \brief [m] from `p_world` (world frame).
  double operator()(const Eigen::Vector3d& p_world) const;
};

/// \brief What sampleTimeline() needs at one timeline instant.
struct TimelineInput {
  double t_s = 0.0;
  WorkerState worker;                  ///< truth
  /// The leader's worker estimate predicted to t_s (NaN: none yet).
  Eigen::Vector3d estimate_world = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  int visible = 0;                     ///< the leader saw the worker within the last 0.2 s
  int gesture_true = 0;                ///< gesture being performed (0 none)
  int gesture_class = -1;              ///< last classifier output (−1 none)
  double dominant_ratio = 0.0;         ///< gesture filter f_d
  formation::FormationParams params;   ///< the leader's current parameters
  double human_heading_rad = 0.0;      ///< ^Hφ the leader uses
  std::vector<MultirotorState> uavs;   ///< true states, uavs[0] the leader
  std::vector<int> acting;             ///< per UAV: 1 while it acts as leader (empty: not recorded)
  /// Per UAV: the formation slot it flies (0 the leader's; −1: none — its references are NaN and it
  /// adds no tracking error; empty: every UAV its own index) — the references of d_ref, phi_ref,
  /// elev_ref and the tracking errors.
  std::vector<int> slots;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief "all.beta_deg +30" / "followers.distance_m = 8": a command as events.csv shows it.
std::string describeCommand(const formation::FormationCommand& command, const std::string& target_text);

/// \brief The mission's operator requests as they fall due: each becomes a FormationCommand
/// (id {id_source, 1, 2, …} in schedule order) and the request record the metrics track
/// (status "lost" until an outcome). Used by gfctl simulate and the ROS SimWorld.
class OperatorSchedule {
 public:
  struct Due {
    formation::FormationCommand command;
    RequestRecord record;
  };
  OperatorSchedule(std::vector<OperatorRequest> requests, std::string id_source)
      : requests_(std::move(requests)), id_source_(std::move(id_source)) {}
  /// \brief The requests with t_s ≤ `t_s` not returned before, in order.
  std::vector<Due> due(double t_s);

 private:
  std::vector<OperatorRequest> requests_;
  std::string id_source_;
  std::size_t next_ = 0;
};

/// \brief The record of a gesture fired at `t_s` with dominant id `gesture_id`, described and
/// with its status from `mapping`: "unmapped" (no action), "event" (an event action), else
/// "lost" until requestOutcome() says what the FormationState did with its command.
RequestRecord firedGestureRecord(double t_s, int gesture_id, const gesture::GestureMapping& mapping);

/// \brief What the leader's FormationState did with a command, as a distributed system reports
/// it: by the command's stamp rather than by request index (MetricsAccumulator::commandOutcome).
struct CommandOutcome {
  std::string source;         ///< operator | gesture
  std::string status;         ///< formation::toString(CommandStatus)
  double issued_s = 0.0;      ///< the command's stamp (operator: sent by the ground; gesture: fired)
  double t_s = 0.0;           ///< when the leader handled it
  std::uint64_t version = 0;  ///< applied: the parameter version it created
  std::vector<int> uavs;      ///< applied: the UAVs it addressed (0 = leader)
};

/// \brief The parameter versions the leader published, to tell which one a follower planned
/// with from the parameters its plan lists.
class ParamsVersions {
 public:
  explicit ParamsVersions(const formation::FormationParams& initial) { versions_.emplace_back(0, initial); }
  /// \brief Records `params` as `version` if it is newer than every recorded one.
  void published(std::uint64_t version, const formation::FormationParams& params);
  /// \brief The latest version published with exactly `used` (β, γ, d of every UAV); nullopt
  /// if none (or another UAV count).
  std::optional<std::uint64_t> versionOf(const formation::FormationParams& used) const;

 private:
  std::vector<std::pair<std::uint64_t, formation::FormationParams>> versions_;
};

/// \brief The accumulator (see the file comment).
class MetricsAccumulator {
 public:
  /// \brief `config` gives the UAV count, body radii, the worker's height, the requests and
  /// the gesture match window; it must outlive the accumulator, as must `obstacles`' pointers.
  MetricsAccumulator(const MissionConfig& config, const ObstacleDistance& obstacles, std::uint64_t seed);

  /// \brief Safety at one instant: `p_world[i]` the true position of UAV i (size = UAV
  /// count), `worker` the worker's truth. Minimum distances, collision onsets.
  void sampleSafety(double t_s, const std::vector<Eigen::Vector3d>& p_world, const WorkerState& worker);
  /// \brief One timeline row and the tracking errors (distance, observation angle).
  void sampleTimeline(const TimelineInput& in);
  /// \brief One leader camera frame: whether the worker was detected; `estimate_world` the
  /// leader's estimate predicted to the frame time (null before the estimator's first fix).
  void cameraFrame(bool visible, const Eigen::Vector3d* estimate_world, const Eigen::Vector3d& worker_world);
  /// \brief UAV `uav` replanned at `t_s` with formation parameters `params_version`.
  void plan(int uav, double t_s, std::uint64_t params_version, planning::PlanStatus status, double total_ms,
            const std::string& reason, int qp_sparse_timeouts = 0);
  /// \brief The last plan status of `uav` (PlanStatus as int; −1 none).
  int lastPlanStatus(int uav) const;

  /// \brief Adds a request record (operator: sent, status "lost" until an outcome; gesture:
  /// firedGestureRecord()). Returns its index.
  std::size_t addRequest(const RequestRecord& record);
  RequestRecord& request(std::size_t index) { return requests_.at(index); }
  const std::vector<RequestRecord>& requests() const { return requests_; }
  /// \brief The earliest request of `source` issued at `issued_s` (± tolerance_s) whose
  /// command has no outcome yet (status "lost"); nullopt if none.
  std::optional<std::size_t> findPending(const std::string& source, double issued_s, double tolerance_s = 1e-6) const;
  /// \brief What the FormationState did with request `index`'s command at `t_s`: `status`
  /// (formation::toString(CommandStatus)); applied: the parameter version it created and the
  /// UAVs it addressed. A copy of an already applied command changes nothing.
  void requestOutcome(std::size_t index, const std::string& status, double t_s, std::uint64_t params_version,
                      const std::vector<int>& uavs);
  /// \brief An outcome reported by the leader with the command's stamp, not the request's index
  /// (the ROS system: FormationParams.last_command_*). It goes to the earliest pending request
  /// of its source issued within `tolerance_s` of the stamp; one whose request is not known yet
  /// (the messages travel on different connections) waits, and every later call retries it.
  void commandOutcome(const CommandOutcome& outcome, double tolerance_s);
  /// \brief Retries the waiting outcomes (after addRequest()).
  void resolveOutcomes(double tolerance_s);
  /// \brief Outcomes that matched no request so far.
  const std::vector<CommandOutcome>& unmatchedOutcomes() const { return unmatched_; }

  /// \brief Diagnostic counters the caller counts itself: plans_skipped, plans_hold,
  /// commands_stale, commands_duplicate, range_outliers, messages_*.
  MissionMetrics& counters() { return m_; }

  /// \brief Gesture matching (fired → performed `gestures`), adaptation starts, rates and
  /// percentiles. `sim_time_s`, `wall_time_s` as measured by the caller. Call once.
  MissionOutput finish(const std::vector<GestureEpisode>& gestures, double sim_time_s, double wall_time_s);

 private:
  struct PlanEvent {
    int uav;
    double t_s;
    std::uint64_t version;
  };
  const MissionConfig& cfg_;
  ObstacleDistance obstacles_;
  int n_ = 0;
  MissionMetrics m_;
  std::vector<TimelineRow> timeline_;
  std::vector<RequestRecord> requests_;
  std::vector<CommandOutcome> unmatched_;
  std::vector<PlanEvent> plan_events_;
  std::vector<PlanRecord> plan_log_;
  std::vector<double> plan_ms_;
  std::vector<int> last_status_;
  std::vector<bool> in_obstacle_, in_worker_;
  std::vector<std::vector<bool>> pair_collision_;
  double dist_sq_ = 0.0, angle_sq_ = 0.0, est_sq_ = 0.0;
  long dist_n_ = 0, est_n_ = 0, frames_ = 0, visible_frames_ = 0;
};

/// \brief metrics.json text (keys of docs/design.md §8.4 first; NaN → null; `not_measured` → null).
std::string metricsJson(const MissionMetrics& m);
/// \brief Writes timeline.csv (header documented in docs/simulation.md §4).
bool writeTimelineCsv(const std::string& path, const MissionOutput& out, int uav_count, std::string* error);
/// \brief Writes events.csv: one row per request, then every performed gesture that fired nothing.
bool writeEventsCsv(const std::string& path, const MissionOutput& out, std::string* error);
/// \brief Writes modes.csv: `t,uav,mode,reason`, one row per ModeChange.
bool writeModesCsv(const std::string& path, const MissionOutput& out, std::string* error);
/// \brief Writes plans.csv: `t,uav,status,params_version,planning_ms,reason`, one row per
/// replanning (commas in the reason become ';').
bool writePlansCsv(const std::string& path, const MissionOutput& out, std::string* error);
/// \brief Writes votes.csv: one row per VoteRecord (columns: docs/simulation.md §3).
bool writeVotesCsv(const std::string& path, const MissionOutput& out, int uav_count, std::string* error);
/// \brief Writes a mission's files into `dir`: timeline.csv, events.csv, modes.csv (if
/// `with_modes`), plans.csv, votes.csv (when there are votes) and metrics.json last, atomically (written to a temporary name, then renamed:
/// its appearance tells a watching script that the files are complete).
bool writeMissionFiles(const std::string& dir, const MissionOutput& out, int uav_count, bool with_modes,
                       std::string* error);

}  // namespace gesture_formation::sim

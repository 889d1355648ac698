#pragma once
/// \file
/// \brief The closed-loop mission (DESIGN §5, issue 7; docs/simulation.md): worker, sensors,
/// the real estimator (HumanKalman), the real gesture pipeline (classifier → GestureFilter →
/// mapping → FormationState), operator requests, the real formation core, one planner per UAV
/// called through the UavPlanner API in priority order with the plans each UAV has received,
/// inter-UAV messages through delayed links, and the plant tracking each UAV's plan.
///
/// Data flow per UAV (DESIGN §1): the leader estimates the worker, owns the FormationState
/// (commands from the operator link and the gesture filter), and every replanning shares
/// {worker estimate, ^Hφ, parameters, its plan}; follower i plans from the last share it
/// received (if not older than faults.max_share_age_s) and around the plans received from the
/// other UAVs; it sends its own plan to every UAV. With faults.avoid_all_plans (default) every
/// UAV plans around every other UAV's last plan; without it only around higher-priority ones
/// and those flagged as fallback/hold or silent for faults.max_plan_age_s (right of way).
/// Stale data → hold (docs/safety.md). Replanning is staggered: UAV i plans at
/// k·period + i·period/n. A plan is executed only as returned by the planner (verified); a UAV
/// without a plan brakes to hover (TrackingController).
///
/// Determinism: every random draw comes from a stream seeded by (seed, component); the
/// metrics that measure wall-clock time (planning_ms_*, real_time_factor) are the only ones
/// that vary between runs of one seed.
/// Thread safety: one mission per thread.

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <map>
#include <string>
#include <vector>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/gesture/gesture_classifier.hpp"
#include "gesture_formation/planning/shapes.hpp"
#include "gesture_formation/planning/uav_planner.hpp"
#include "gesture_formation/sim/mission_config.hpp"

namespace gesture_formation::planning {
class OccupancyMap;
class DistanceField;
}  // namespace gesture_formation::planning

namespace gesture_formation::sim {

/// \brief One UAV's planner as the mission calls it (planning::UavPlanner in the product;
/// tests may substitute their own).
class MissionPlanner {
 public:
  virtual ~MissionPlanner() = default;
  virtual planning::PlanResult plan(const planning::PlanRequest& request) = 0;
};
/// \brief Creates the planner of UAV `uav_index`.
using PlannerFactory = std::function<std::unique_ptr<MissionPlanner>(int uav_index)>;

/// \brief The planner of the product: planning::UavPlanner over the shared map and field.
PlannerFactory uavPlannerFactory(const planning::PlannerConfig& config,
                                 std::shared_ptr<const planning::OccupancyMap> map,
                                 std::shared_ptr<const planning::DistanceField> field);

/// \brief The gesture classifier as the mission calls it (the ONNX LSTM in the product).
class MissionClassifier {
 public:
  virtual ~MissionClassifier() = default;
  virtual common::Result<gesture::Classification> classify(const gesture::SkeletonWindow& window) = 0;
};
/// \brief Loads the ONNX LSTM (gesture::GestureClassifier).
common::Result<std::unique_ptr<MissionClassifier>> loadOnnxClassifier(const std::string& onnx_path);

/// \brief DESIGN §8.4 metrics (docs/simulation.md §4 defines each) plus diagnostics.
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
  double human_estimate_error_rms_m = 0.0;
  // diagnostics
  int requests_total = 0;              ///< operator requests + gestures performed
  int operator_requests_applied = 0;
  int gesture_requests_applied = 0;
  int gestures_performed = 0;
  int gestures_successful = 0;
  int plans = 0, plans_fallback_previous = 0, plans_fallback_brake = 0, plans_skipped = 0;
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
};

/// \brief One timeline sample (DESIGN §8.4 timeline.csv).
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
};

/// \brief A request (operator or fired gesture) and what became of it.
struct RequestRecord {
  double t_s = 0.0;            ///< operator: sent; gesture: fired
  std::string source;          ///< "operator" | "gesture"
  std::string description;     ///< e.g. "all.beta_deg +30"
  std::string status;          ///< applied | duplicate | rejected | lost | event | unmapped
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

struct MissionOutput {
  MissionMetrics metrics;
  std::vector<ModeChange> modes;
  std::vector<TimelineRow> timeline;
  std::vector<RequestRecord> requests;
  std::vector<GestureEpisode> gestures;  ///< performed by the worker
};

/// \brief Everything a mission needs besides its config. The map and field must outlive the run.
struct MissionWorld {
  const planning::OccupancyMap* map = nullptr;     ///< occlusion ray casts (may be null: none)
  const planning::DistanceField* field = nullptr;  ///< obstacle clearance metrics (required)
  double ground_height_m = 0.0;
  /// Exact obstacle geometry for the obstacle-distance metrics (d_o, min_obstacle_distance_m):
  /// within 2.5 m of an obstacle the distance to these solids and the ground, farther the
  /// field's value. Null: the field's value everywhere (distance to occupied voxel centres,
  /// quantised to the voxel size).
  const planning::PrimitiveSet* solids = nullptr;
};

/// \brief Runs one mission. `classifier` may be null (no gesture pipeline: gestures are not
/// recognised). `duration_s` ≤ 0 → the config's. Fails (with a reason) only for a setup
/// problem (e.g. an initial position inside an obstacle).
common::Result<MissionOutput> runMission(const MissionConfig& config, const MissionWorld& world,
                                         const PlannerFactory& planners, MissionClassifier* classifier,
                                         std::uint64_t seed, double duration_s = 0.0);

/// \brief Where braking from the estimated velocity at `brake_accel_mps2` ends: p + v|v|/(2a).
/// A UAV entering hold latches this point and holds it until it tracks again (docs/safety.md §1).
Eigen::Vector3d brakingPoint(const EstimatedState& est, double brake_accel_mps2);
/// \brief The hold reference: every step at `hold_world`, camera heading and pitch towards
/// `worker_world` (the last known worker position; `heading_rad` when straight above/below).
formation::ReferenceTrajectory holdReference(const Eigen::Vector3d& hold_world, const Eigen::Vector3d& worker_world,
                                             double heading_rad, int steps);

/// \brief metrics.json text (keys of DESIGN §8.4 first; NaN → null).
std::string metricsJson(const MissionMetrics& m);
/// \brief Writes timeline.csv (header documented in docs/simulation.md §5).
bool writeTimelineCsv(const std::string& path, const MissionOutput& out, int uav_count, std::string* error);
/// \brief Writes events.csv: one row per request.
bool writeEventsCsv(const std::string& path, const MissionOutput& out, std::string* error);
/// \brief Writes modes.csv: `t,uav,mode,reason`, one row per ModeChange.
bool writeModesCsv(const std::string& path, const MissionOutput& out, std::string* error);

}  // namespace gesture_formation::sim

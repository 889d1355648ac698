#pragma once
/// \file
/// \brief The closed-loop mission (design.md §5, issue 7; docs/simulation.md): worker, sensors,
/// the real estimator (HumanKalman), the real gesture pipeline (classifier → GestureFilter →
/// mapping → FormationState), operator requests, the real formation core, one planner per UAV
/// called through the UavPlanner API in priority order with the plans each UAV has received,
/// inter-UAV messages through delayed links, and the plant tracking each UAV's plan.
///
/// Data flow per UAV (docs/design.md §1): the leader estimates the worker, owns the FormationState
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
/// "The leader" is the UAV acting as leader (formation::Leadership on every UAV, its messages over
/// the inter-UAV links; leader_handover.hpp, docs/safety.md §1.2): UAV 0 from the start; after a
/// leader's silence (faults.leader_silence) the UAV elected in its place, which takes the estimator
/// over from the last share it received and flies the leader's slot.
///
/// The parts the ROS simulation (SimWorld, FormationPlanner nodelets) runs too: the metrics
/// (MetricsAccumulator, mission_metrics.hpp), the leader's camera (LeaderCamera,
/// leader_camera.hpp) and the planning request (buildPlanRequest, planning/plan_request_builder.hpp).
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
#include "gesture_formation/planning/replan_step.hpp"
#include "gesture_formation/planning/uav_planner.hpp"
#include "gesture_formation/sim/camera_source.hpp"
#include "gesture_formation/sim/leader_camera.hpp"
#include "gesture_formation/sim/mission_config.hpp"
#include "gesture_formation/sim/mission_metrics.hpp"

namespace gesture_formation::planning {
class OccupancyMap;
class DistanceField;
}  // namespace gesture_formation::planning

namespace gesture_formation::sim {

class SiteMapping;  // site_mapping.hpp

/// \brief One UAV's planner as the mission calls it (planning::UavPlanner in the product;
/// tests may substitute their own): the replanning step's planner interface.
using MissionPlanner = planning::Planner;

/// \brief Creates the planner of UAV `uav_index`.
using PlannerFactory = std::function<std::unique_ptr<MissionPlanner>(int uav_index)>;

/// \brief The planner of the product: planning::UavPlanner over the shared map and field.
PlannerFactory uavPlannerFactory(const planning::PlannerConfig& config,
                                 std::shared_ptr<const planning::OccupancyMap> map,
                                 std::shared_ptr<const planning::DistanceField> field);

// MissionMetrics, TimelineRow, RequestRecord, ModeChange, MissionOutput and the writers of
// metrics.json, timeline.csv, events.csv, modes.csv: mission_metrics.hpp.

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
  /// The unmapped obstacles and the UAVs' live maps (site_mapping.hpp; its planners:
  /// SiteMapping::plannerFactory). Null: none (the world is the scenario's mapped obstacles, every
  /// UAV plans on the prior map). Must outlive the run; one run per instance.
  SiteMapping* site = nullptr;
};

/// \brief Runs one mission. `classifier` may be null (no gesture pipeline: gestures are not
/// recognised). `duration_s` ≤ 0 → the config's. `camera`: the formation's cameras (e.g. a
/// RenderedCamera, which must outlive the run); null → the synthetic camera (LeaderCamera for
/// `config`, `world.map` and `seed`). A camera with perception records adds them to the output
/// (perception.csv, metrics.json `perception`). Fails (with a reason) only for a setup problem
/// (e.g. an initial position inside an obstacle).
common::Result<MissionOutput> runMission(const MissionConfig& config, const MissionWorld& world,
                                         const PlannerFactory& planners, MissionClassifier* classifier,
                                         std::uint64_t seed, double duration_s = 0.0, CameraSource* camera = nullptr);

}  // namespace gesture_formation::sim

#pragma once
/// \file
/// \brief The `mission:` section of a scenario file (config/scenarios/*.yaml;
/// docs/simulation.md §2): worker route and gestures, UAVs with their plant parameters,
/// controller, odometry, wind, sensors, links, formation, gesture filter and mapping, planner,
/// estimator, operator requests and fault injection. The world sections (map, towers, …) are
/// the planning loader's (planning/scenario.hpp); this loader reads only `mission`.
///
/// Loading collects every problem at once, each as "file: key: message" naming the field and
/// value (common::ConfigReader), and refuses the mission if there is any. Plant limits have no
/// silent defaults: every key of `uavs[i].plant` is required. Other sections take the
/// documented defaults when absent. Thread safety: value types.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/estimation/estimator_config.hpp"
#include "gesture_formation/formation/formation_commands.hpp"
#include "gesture_formation/formation/formation_config.hpp"
#include "gesture_formation/gesture/gesture_filter.hpp"
#include "gesture_formation/gesture/gesture_mapping.hpp"
#include "gesture_formation/planning/planner_config.hpp"
#include "gesture_formation/sim/link.hpp"
#include "gesture_formation/sim/multirotor.hpp"
#include "gesture_formation/sim/odometry.hpp"
#include "gesture_formation/sim/synthetic_sensors.hpp"
#include "gesture_formation/sim/tracking_controller.hpp"
#include "gesture_formation/sim/wind.hpp"
#include "gesture_formation/sim/worker_model.hpp"

namespace gesture_formation::sim {

/// \brief One simulated UAV (index 0 = leader, i = follower i).
struct UavConfig {
  std::string name;
  MultirotorParams plant;
  /// Start position; absent → the formation reference around the worker's start.
  std::optional<Eigen::Vector3d> initial_position;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief A scheduled operator request (DESIGN §4 command).
struct OperatorRequest {
  double t_s = 0.0;
  std::string target_text;  ///< as written (for the timeline)
  formation::CommandTarget target;
  formation::Parameter parameter = formation::Parameter::kBeta;
  formation::CommandKind kind = formation::CommandKind::kIncrement;
  double amount = 0.0;
};

/// \brief A time window during which UAV `uav`'s planner is not run (fault injection).
struct PlannerOutage {
  int uav = 0;
  double from_s = 0.0, to_s = 0.0;
};

struct FaultConfig {
  std::vector<std::pair<double, double>> camera_blackouts;  ///< [from, to] s: the leader sees no worker
  std::vector<PlannerOutage> planner_outages;
  double max_share_age_s = 2.0;  ///< followers do not plan from a leader message older than this, > 0
  std::vector<std::string> validate(const std::string& prefix = "") const;
};

struct MissionConfig {
  std::string source;             ///< scenario file
  double duration_s = 0.0;        ///< > 0; default: the worker's route duration
  double step_s = 0.01;           ///< plant/controller step, (0, 0.05]
  double replanning_period_s = 0.4;  ///< per UAV, staggered by period·i/n, > 0
  double horizon_dt_s = 0.2;      ///< > 0
  int horizon_steps = 40;         ///< [2, 128]
  double timeline_rate_hz = 10.0;  ///< > 0
  double gesture_match_window_s = 20.0;  ///< a fired gesture matches a performed one started at most this long before
  std::string gesture_model;      ///< ONNX path (resolved against the scenario's folder); empty: no gesture pipeline

  WorkerConfig worker;
  std::vector<UavConfig> uavs;    ///< uavs[0] leader; count = 1 + followers
  ControllerConfig controller;
  OdometryConfig odometry;
  WindConfig wind;
  CameraSensorConfig camera;
  RangeSensorConfig stereo{0.3, 15.0, 0.05};
  RangeSensorConfig uwb{0.1, 40.0, 0.05};
  LinkConfig link;                ///< between UAVs
  LinkConfig operator_link{0.1, 0.0, 0.0, 0.0};
  FaultConfig faults;
  formation::FormationConfig formation;
  gesture::GestureFilterConfig gesture_filter;
  gesture::GestureMapping gesture_mapping = gesture::GestureMapping::paperDefault();
  planning::PlannerConfig planner;
  estimation::EstimatorConfig estimator;
  std::vector<OperatorRequest> requests;  ///< ascending t_s
};

/// \brief Reads `mission` of a scenario file. Fails listing every problem (file: key: message).
common::Result<MissionConfig> loadMissionConfig(const std::string& scenario_path);
/// \brief As loadMissionConfig, from YAML text (`source_name` in messages; relative paths
/// resolve against `base_dir`).
common::Result<MissionConfig> parseMissionConfig(const std::string& yaml, const std::string& source_name,
                                                 const std::string& base_dir);

/// \brief Parses a request target: all | leader | followers | follower<i> | a list of UAV
/// indices [0, 2] (0 = leader).
common::Result<formation::CommandTarget> parseTarget(const std::string& text);

}  // namespace gesture_formation::sim

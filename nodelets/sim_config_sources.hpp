#pragma once
// The whole mission of a scenario file for the simulation nodelets (SimUav, SimWorld); the
// nodelets that fly read only its product settings (config_sources.hpp, loadOnboard).
#include <string>

#include "config_sources.hpp"
#include "gesture_formation/sim/mission_config.hpp"
#include "gesture_formation/sim/mission_metrics.hpp"
#include "gesture_formation/sim/unmapped_obstacles.hpp"

namespace gesture_formation::nodelets {

/// Loads the mission of `mission_file` (every problem into `params`), with the fault profile of
/// the optional ~faults_file merged in (as `gfctl simulate --faults FILE`; every nodelet of a
/// simulation gets the same pair).
inline bool loadMission(const std::string& mission_file, ParamLoader& params, sim::MissionConfig& out) {
  std::string faults_file;
  params.loadOptional("faults_file", faults_file, "");
  auto m = faults_file.empty() ? sim::loadMissionConfig(mission_file) : sim::loadMissionConfig(mission_file, faults_file);
  if (!m) {
    params.addError((faults_file.empty() ? "mission_file: " : "mission_file + faults_file: ") + m.reason());
    return false;
  }
  out = std::move(*m);
  return true;
}

/// The scenario's unmapped obstacles (`unmapped_obstacles:`, docs/simulation.md §2): in the simulated
/// world — SimCamera draws them, SimWorld's obstacle distance and collisions count them — but not in
/// the prior map the planners get.
struct SiteObstacles {
  std::vector<sim::UnmappedObstacle> unmapped;
  /// Every problem into `params` (naming the obstacle and key).
  void load(const std::string& mission_file, ParamLoader& params) {
    auto u = sim::loadUnmappedObstacles(mission_file);
    if (u) unmapped = std::move(*u);
    else params.addError("mission_file: " + u.reason());
  }
  /// The world's obstacle distance: the mapped world's, and the unmapped obstacles where they are at
  /// *clock_s (the simulation time; must outlive the result).
  sim::ObstacleDistance distance(const WorldMap& w, const double* clock_s) const {
    sim::ObstacleDistance d{w.field.get(), w.solids.get(), w.ground_height_m};
    if (!unmapped.empty()) d.extra = [this, clock_s](const Eigen::Vector3d& p) { return sim::unmappedDistance(unmapped, p, *clock_s); };
    return d;
  }
};

/// The SimWorld nodelet's own parameters (docs/ros.md "SimWorld"); every problem into `params`.
struct SimWorldSettings {
  std::string mission_file, output_dir, world_frame, camera_frame;
  int seed = 0;
  double real_time_factor = 1.0, clock_step_s = 0.01, duration_s = 0.0;  ///< duration ≤ 0: the mission's
  bool rendered = false;  ///< ~camera rendered (default synthetic)
  bool leadership = false;  ///< ~leadership (optional): the leader's work follows the acting UAV
};
inline void loadSimWorldSettings(ParamLoader& params, SimWorldSettings& s) {
  params.load("mission_file", s.mission_file);
  params.load("seed", s.seed, 0, 1 << 30);
  params.load("real_time_factor", s.real_time_factor, 0.05, 100.0);
  params.load("clock_step_s", s.clock_step_s, 0.001, 0.1);
  params.load("duration_s", s.duration_s, -1.0, 1e5);
  params.load("output_dir", s.output_dir);
  params.load("world_frame", s.world_frame);
  params.load("leader_camera_frame", s.camera_frame);
  std::string camera_mode;
  params.loadOptional("camera", camera_mode, "synthetic");
  if (camera_mode != "synthetic" && camera_mode != "rendered") {
    params.addError("camera: must be synthetic or rendered, got '" + camera_mode + "'");
  }
  s.rendered = camera_mode == "rendered";
  params.loadOptional("leadership", s.leadership, false);
  if (s.leadership && s.rendered) params.addError("leadership: true needs camera synthetic (rendered cameras: UAV 0's Perception is the leader's)");
  if (s.leadership && s.camera_frame.rfind("uav0/", 0) != 0) {
    params.addError("leader_camera_frame: with leadership it must start with uav0/ (UAV k's camera is uav<k>/...), got '" + s.camera_frame + "'");
  }
}

/// SimWorld's inputs: its parameters, then the mission of ~mission_file, the map of its scenario
/// and the unmapped obstacles; every problem into `params`.
inline void loadSimWorld(ParamLoader& params, SimWorldSettings& set, sim::MissionConfig& mission, WorldMap& world,
                         SiteObstacles& site) {
  loadSimWorldSettings(params, set);
  if (set.mission_file.empty() || !loadMission(set.mission_file, params, mission)) return;
  loadWorldMap(set.mission_file, params, world);
  site.load(set.mission_file, params);
}

}  // namespace gesture_formation::nodelets

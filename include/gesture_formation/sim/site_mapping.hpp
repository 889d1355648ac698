#pragma once
/// \file
/// \brief The UAVs discover the site (issue 35 items 1–2; docs/mapping.md §7, docs/simulation.md
/// §"Mapping the site"): the world's unmapped obstacles (sim::UnmappedObstacle — in the world,
/// not in the prior map) and, with `mission.mapping.enabled`, one mapping::LiveMap per UAV fed by
/// that UAV's depth frames, on which its planner (UavPlanner) and its abort's RetreatSpace plan.
///
/// What the mission runner calls (a few hook lines in mission_runner.cpp):
///   - field(i): UAV i's planning field (the live map's, or null: the world's prior field);
///   - step(t, true states) every plant step: the clock of the unmapped obstacles' motion, the
///     depth frames that fall due (`mission.mapping.rate_hz` per UAV, staggered), and the
///     least distance of each UAV to each unmapped obstacle;
///   - planned(i, t, result) after every replanning: the time from first sight to avoidance;
///   - summary() at the end (metrics.json `site_mapping`).
///   - openShareLinks(link, seed) once before the first step: with `mission.mapping.share.enabled`
///     every UAV sends its own map changes (comm::MapUpdate, encoded as on the wire) to every other
///     UAV over a Link with the inter-UAV fault model, `share.rate_hz` times a second (staggered),
///     within `share.max_bytes_per_s`; each receiver decodes, checks and merges them
///     (mapping::LiveMap::merge). A UAV offline (dropout) neither sends nor receives.
/// The planners come from plannerFactory() (UavPlanner over UAV i's live map and field).
///
/// Depth frames: `--camera synthetic` (default) renders them analytically (DepthRaycaster) from
/// each UAV's **true** camera pose (heading, gimbal pitch; perfect localisation: the frame's pose
/// is the true one) with the mission camera's intrinsics, against the scenario's solids, the
/// unmapped obstacles present at the frame's time and the ground.
///
/// Determinism: no random draws; the mission's random streams are untouched. The wall-clock
/// timings of the summary vary between runs.
/// Thread safety: none; the mission's thread.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/estimation/camera_model.hpp"
#include "gesture_formation/mapping/live_map.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/sim/camera_source.hpp"
#include "gesture_formation/sim/depth_raycaster.hpp"
#include "gesture_formation/sim/link.hpp"
#include "gesture_formation/sim/mission_config.hpp"
#include "gesture_formation/sim/mission_metrics.hpp"
#include "gesture_formation/sim/mission_runner.hpp"
#include "gesture_formation/sim/multirotor.hpp"
#include "gesture_formation/sim/site_metrics.hpp"
#include "gesture_formation/sim/unmapped_obstacles.hpp"

namespace gesture_formation::sim {

class SiteMapping {
 public:
  /// \brief The site of one mission run: `mission` (mapping settings, the camera's intrinsics, the
  /// UAV count, planner.obstacle_clearance_m), the planners' grid `grid` and prior map `prior` (the
  /// scenario's mapped obstacles), the exact mapped `solids` and the ground (non-finite: none),
  /// and the unmapped obstacles. Fails naming a bad setting (mission.mapping.*).
  static common::Result<std::unique_ptr<SiteMapping>> create(const MissionConfig& mission, const planning::MapConfig& grid,
                                                             std::shared_ptr<const planning::OccupancyMap> prior,
                                                             const planning::PrimitiveSet& solids, double ground_height_m,
                                                             std::vector<UnmappedObstacle> unmapped);
  SiteMapping(const SiteMapping&) = delete;
  SiteMapping& operator=(const SiteMapping&) = delete;

  /// \brief The UAVs keep live maps (mission.mapping.enabled).
  bool mapping() const { return !live_.empty(); }
  /// \brief UAV i's planning field (live, updated in place), null without mapping.
  const planning::DistanceField* field(int uav) const;
  /// \brief UAV i's live map, null without mapping.
  const mapping::LiveMap* liveMap(int uav) const {
    return uav >= 0 && uav < static_cast<int>(live_.size()) ? live_[static_cast<std::size_t>(uav)].get() : nullptr;
  }
  /// \brief UavPlanner over UAV i's live map (mapping), else over `prior_map`/`prior_field`.
  PlannerFactory plannerFactory(const planning::PlannerConfig& config, std::shared_ptr<const planning::OccupancyMap> prior_map,
                                std::shared_ptr<const planning::DistanceField> prior_field) const;
  /// \brief `base` (the mapped world) plus the unmapped obstacles at this object's clock.
  ObstacleDistance withUnmapped(ObstacleDistance base) const;

  /// \brief The map-update links (share enabled; no-op otherwise): UAV i → j for every i ≠ j, each
  /// with `link`'s faults and its own random stream (Stream::kMapShare of `seed`: the mission's
  /// other streams are untouched).
  void openShareLinks(const LinkConfig& link, std::uint64_t seed);
  /// \brief Every plant step, before the safety sample: the clock, due depth frames, distances,
  /// and map updates sent and received; `offline[i]` (optional): UAV i's radio is down.
  void step(double t_s, const std::vector<MultirotorState>& uavs, const std::vector<bool>& offline = {});
  /// \brief From now on UAV i's depth frames are the images its camera rendered (offerDepth; `gfctl
  /// simulate --camera rendered`) instead of ray-cast ones: each frame that falls due integrates
  /// the newest offered image not integrated yet — with that image's own pose and time, at most one
  /// camera period old — and none when there is none (a blackout, a UAV without a rendered view).
  /// The travel camera (travel_camera_hfov_deg) stays ray-cast: no such camera is rendered.
  void useOfferedDepth();
  /// \brief UAV i's camera image of `depth` (see useOfferedDepth; ignored before it is called).
  void offerDepth(int uav, const CameraDepth& depth);
  /// \brief After UAV i's replanning at t_s; `reference` (stage 1, steps of `reference_dt_s` from
  /// t_s) gives the travel camera its direction.
  void planned(int uav, double t_s, const planning::PlanResult& result, const formation::ReferenceTrajectory& reference = {},
               double reference_dt_s = 0.0);
  SiteMappingSummary summary() const;
  /// \brief The sharing part of summary().
  MapShareSummary shareSummary() const;

  /// \brief Distance (m) from p to the nearest unmapped obstacle at the clock (+inf: none).
  double unmappedDistanceNow(const Eigen::Vector3d& p_world) const { return unmappedDistance(unmapped_, p_world, clock_s_); }
  const std::vector<UnmappedObstacle>& unmapped() const { return unmapped_; }

 private:
  SiteMapping(const MissionConfig& mission, const planning::PrimitiveSet& solids, double ground_height_m,
              std::vector<UnmappedObstacle> unmapped);
  void depthFrame(int uav, double t_s, const MultirotorState& state);
  /// One frame of UAV i's camera at `T_world_camera` with `intrinsics` into its live map.
  void integrateFrame(int uav, double t_s, const Eigen::Isometry3d& T_world_camera, const estimation::CameraIntrinsics& intrinsics);
  /// A depth image (REP 118) of UAV i's camera into its live map.
  void integrateDepth(int uav, double t_s, const Eigen::Isometry3d& T_world_camera, const estimation::CameraIntrinsics& intrinsics,
                      cv::Mat depth_m);
  /// The travel camera's heading and pitch for UAV i now (travel_camera_hfov_deg).
  std::pair<double, double> travelDirection(int uav, const MultirotorState& state);
  /// Marks what UAV i's live map now holds of the obstacles near `p_world`.
  void recordSightings(int uav, double t_s, const Eigen::Vector3d& p_world);
  void surfaceVoxels(const planning::MapConfig& grid);
  /// UAV i's due map update: its pending changes within the budget, encoded, to every other UAV.
  void sendUpdate(int uav, double t_s, const Eigen::Vector3d& p_world);
  /// Every update that reached UAV i by t_s: decoded, checked and merged (dropped when offline).
  void receiveUpdates(int uav, double t_s, bool offline);

  SiteMappingConfig config_;
  estimation::CameraIntrinsics intrinsics_;
  double clearance_m_ = 0.8;
  int n_ = 0;
  std::vector<UnmappedObstacle> unmapped_;
  DepthRaycaster raycaster_;
  std::vector<std::unique_ptr<mapping::LiveMap>> live_;  ///< per UAV (empty: no mapping)
  std::vector<double> next_frame_s_;
  estimation::CameraIntrinsics travel_intrinsics_;
  std::vector<Eigen::Vector3d> travel_target_;  ///< per UAV: its reference travel_lookahead_s ahead (NaN: none)
  std::vector<std::pair<double, double>> travel_dir_;  ///< per UAV: the last travel heading, pitch (rad)
  double clock_s_ = 0.0;
  /// Per obstacle: its surface voxels' centres at the listed pose and whether any UAV saw each.
  std::vector<std::vector<Eigen::Vector3d>> surface_;
  std::vector<std::vector<bool>> surface_seen_;
  std::vector<std::vector<double>> seen_s_, avoided_s_;  ///< [uav][obstacle]
  std::vector<UnmappedObstacleRecord> records_;
  std::vector<double> depth_ms_, integrate_ms_;
  bool offered_depth_ = false;                     ///< useOfferedDepth()
  std::vector<std::optional<CameraDepth>> held_;   ///< per UAV: the newest offered image not integrated yet
  // Sharing (openShareLinks):
  using ShareLink = Link<std::vector<std::uint8_t>>;
  std::vector<std::vector<std::unique_ptr<ShareLink>>> share_links_;  ///< [from][to]
  std::vector<double> next_share_s_;
  std::vector<std::uint32_t> share_sequence_;
  std::vector<std::vector<double>> bytes_by_second_;  ///< [uav][whole mission second]
  std::vector<double> share_age_s_, merge_ms_;
  MapShareSummary share_;
};

}  // namespace gesture_formation::sim

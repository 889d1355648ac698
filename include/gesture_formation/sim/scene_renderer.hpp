#pragma once
/// \file
/// \brief The mission's world as the rendered cameras see it (docs/simulation.md §8,
/// docs/ros.md "Rendered cameras"): one render::Renderer holding the scenario's world (the
/// planner's obstacle geometry, the ground), the worker mesh posed every frame from the worker
/// model's own 3-D body (WorkerModel::bodyAt) and dressed from the mission's seed, and the UAVs'
/// bodies; it renders any UAV's camera at that UAV's camera pose (heading φ, gimbal pitch ξ,
/// docs/conventions.md) with the mission's camera intrinsics, distortion 0 (the rectified image).
///
/// The one home of "a UAV's rendered camera frame": sim::RenderedCamera (`gfctl simulate --camera
/// rendered`) and the SimCamera nodelet (`simulation.launch camera:=rendered`) both render through it.
/// Library gesture_formation_sim_render; the onboard nodelets never link it.
/// Thread safety: none; one thread at a time (the GL context is made current at each call).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/estimation/camera_model.hpp"
#include "gesture_formation/gesture/skeleton_synth.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/render/renderer.hpp"
#include "gesture_formation/sim/mission_config.hpp"
#include "gesture_formation/sim/multirotor.hpp"
#include "gesture_formation/sim/unmapped_obstacles.hpp"

namespace gesture_formation::sim {

/// \brief The mission's camera as it is rendered: its intrinsics with zero distortion.
estimation::CameraIntrinsics renderedIntrinsics(const MissionConfig& mission);

/// \brief The unmapped obstacles present at t_s, where their motion puts them, as one mesh in
/// render::kSiteObstacleColour (for render::Renderer::setSiteObstacles).
render::TriangleMesh unmappedObstaclesMesh(const std::vector<UnmappedObstacle>& obstacles, double t_s);

class SceneRenderer {
 public:
  using Poses = std::vector<Eigen::Isometry3d, Eigen::aligned_allocator<Eigen::Isometry3d>>;

  /// \brief Opens the renderer (EGL + `models_root`/mannequin/wooden_mannequin.glb), uploads
  /// `scenario`'s world and dresses the worker from `seed` (render::Appearance::fromSeed, the
  /// same outfit for every camera of a run). Fails naming what is missing and how to get it.
  static common::Result<std::unique_ptr<SceneRenderer>> create(const std::string& models_root,
                                                               const planning::Scenario& scenario, std::uint64_t seed);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  /// \brief The site's obstacles that the prior map lacks (scenario `unmapped_obstacles:`): drawn
  /// from the next setScene on, each where its motion puts it at that scene's time and gone after
  /// its `gone_after_s` (colour: render::kSiteObstacleColour). An empty list removes them (fails
  /// only when the GL context cannot be made current).
  common::Result<bool> setUnmappedObstacles(std::vector<UnmappedObstacle> obstacles);
  /// \brief The scene of one instant: the worker's body (body frame, WorkerModel::bodyAt) with its
  /// feet at `feet_world` facing `heading_rad`, `height_m` tall; the UAVs' true states (element i:
  /// UAV i; their bodies are drawn, their cameras are the ones render() renders). On failure (the
  /// worker mesh) the UAVs and the obstacles are set, the worker is the previous one.
  /// `t_s`: the mission time (poses the unmapped obstacles).
  common::Result<bool> setScene(const gesture::Body3D& body, const Eigen::Vector3d& feet_world, double heading_rad,
                                double height_m, const std::vector<MultirotorState>& uavs, double t_s);
  /// \brief UAV `uav`'s camera (of the last setScene; `uav` < its UAV count) with `intrinsics`
  /// (distortion must be zero): colour (RGB), depth [m along the optical axis, NaN = nothing],
  /// classes, the worker's truth. Its own UAV is not drawn.
  common::Result<render::RenderedFrame> render(std::size_t uav, const estimation::CameraIntrinsics& intrinsics);
  /// \brief UAV `uav`'s optical-frame pose of the last setScene.
  const Eigen::Isometry3d& cameraPose(std::size_t uav) const { return cameras_.at(uav); }
  /// \brief The GL renderer in use (e.g. "llvmpipe (LLVM 15.0.6, 256 bits)").
  std::string glRenderer() const;

 private:
  SceneRenderer() = default;
  std::unique_ptr<render::Renderer> renderer_;
  render::Appearance appearance_;
  Poses cameras_;  ///< optical frames of the last setScene's UAVs
  std::vector<UnmappedObstacle> unmapped_;
  std::vector<double> site_key_;  ///< what the drawn obstacles were made of (presence, offset), to upload only changes
};

}  // namespace gesture_formation::sim

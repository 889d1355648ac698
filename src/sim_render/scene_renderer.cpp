#include "gesture_formation/sim/scene_renderer.hpp"

#include "gesture_formation/render/mesh.hpp"

namespace gesture_formation::sim {

estimation::CameraIntrinsics renderedIntrinsics(const MissionConfig& mission) {
  estimation::CameraIntrinsics k = mission.estimator.camera;
  k.distortion.fill(0.0);  // the rendered image is the rectified one
  return k;
}

render::TriangleMesh unmappedObstaclesMesh(const std::vector<UnmappedObstacle>& obstacles, double t_s) {
  render::TriangleMesh mesh;
  for (const UnmappedObstacle& o : obstacles) {
    const planning::PrimitiveSet now = o.primitivesAt(t_s);  // empty when gone
    for (const auto& b : now.boxes) mesh.append(render::boxMesh(b, render::kSiteObstacleColour));
    for (const auto& c : now.cylinders) mesh.append(render::cylinderMesh(c, render::kSiteObstacleColour));
  }
  return mesh;
}

SceneRenderer::~SceneRenderer() = default;

common::Result<bool> SceneRenderer::setUnmappedObstacles(std::vector<UnmappedObstacle> obstacles) {
  unmapped_ = std::move(obstacles);
  site_key_.clear();
  if (unmapped_.empty()) return renderer_->setSiteObstacles(render::TriangleMesh());
  return common::Result<bool>::ok(true);
}

common::Result<std::unique_ptr<SceneRenderer>> SceneRenderer::create(const std::string& models_root,
                                                                     const planning::Scenario& scenario,
                                                                     std::uint64_t seed) {
  using R = common::Result<std::unique_ptr<SceneRenderer>>;
  std::unique_ptr<SceneRenderer> s(new SceneRenderer());
  render::RendererConfig rc;
  rc.worker_asset_path = models_root + "/mannequin/wooden_mannequin.glb";
  auto renderer = render::Renderer::create(rc);
  if (!renderer) return R::fail(renderer.reason());
  s->renderer_ = std::move(*renderer);
  auto world = s->renderer_->setWorld(scenario);
  if (!world) return R::fail("the world: " + world.reason());
  s->appearance_ = render::Appearance::fromSeed(seed);
  return R::ok(std::move(s));
}

common::Result<bool> SceneRenderer::setScene(const gesture::Body3D& body, const Eigen::Vector3d& feet_world,
                                             double heading_rad, double height_m,
                                             const std::vector<MultirotorState>& uavs, double t_s) {
  Poses bodies;
  cameras_.clear();
  for (const MultirotorState& s : uavs) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = s.p_world;
    T.linear() = Eigen::AngleAxisd(s.heading_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    bodies.push_back(T);
    cameras_.push_back(render::cameraPoseFromHeadingPitch(s.p_world, s.heading_rad, s.pitch_rad));
  }
  renderer_->setUavs(bodies);
  if (!unmapped_.empty()) {
    std::vector<double> key;
    for (const UnmappedObstacle& o : unmapped_) {
      const Eigen::Vector3d d = o.motion.offsetAt(t_s);
      key.insert(key.end(), {o.presentAt(t_s) ? 1.0 : 0.0, d.x(), d.y(), d.z()});
    }
    if (key != site_key_) {
      auto set = renderer_->setSiteObstacles(unmappedObstaclesMesh(unmapped_, t_s));
      if (!set) return common::Result<bool>::fail("the unmapped obstacles: " + set.reason());
      site_key_ = std::move(key);
    }
  }
  auto posed = renderer_->setWorker(render::WorkerJoints::fromBody(body, feet_world, heading_rad), height_m, appearance_);
  if (!posed) return common::Result<bool>::fail("the worker mesh: " + posed.reason());
  return common::Result<bool>::ok(true);
}

common::Result<render::RenderedFrame> SceneRenderer::render(std::size_t uav, const estimation::CameraIntrinsics& intrinsics) {
  if (uav >= cameras_.size()) {
    return common::Result<render::RenderedFrame>::fail("uav " + std::to_string(uav) + ": the scene has " +
                                                       std::to_string(cameras_.size()) + " UAVs");
  }
  render::CameraView view;
  view.intrinsics = intrinsics;
  view.T_world_camera = cameras_[uav];
  return renderer_->render(view, uav);
}

std::string SceneRenderer::glRenderer() const { return renderer_->glRenderer(); }

}  // namespace gesture_formation::sim

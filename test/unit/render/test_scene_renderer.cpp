// sim::SceneRenderer (docs/simulation.md §8, docs/ros.md "Rendered cameras"): the one renderer of
// a UAV's camera frame that gfctl simulate's RenderedCamera and the SimCamera nodelet share.
// Each UAV's camera is rendered at that UAV's heading / pitch (the worker's projected mid-body
// lies in his visible box, the depth there is his), the same seed gives the same images (every
// process of the ROS simulation dresses the worker alike), a UAV the scene does not hold is refused.
#include <gtest/gtest.h>

#include <cmath>

#include "gesture_formation/estimation/camera_model.hpp"
#include "gesture_formation/planning/scenario.hpp"
#include "gesture_formation/sim/mission_config.hpp"
#include "gesture_formation/sim/scene_renderer.hpp"
#include "gesture_formation/sim/worker_model.hpp"

namespace {

namespace gf = gesture_formation;
using Eigen::Vector3d;

class SceneRendererTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string file = std::string(GF_SOURCE_DIR) + "/config/scenarios/power_towers.yaml";
    auto sc = gf::planning::loadScenario(file);
    ASSERT_TRUE(sc) << sc.reason();
    scenario_ = *sc;
    auto m = gf::sim::loadMissionConfig(file);
    ASSERT_TRUE(m) << m.reason();
    mission_ = *m;
    auto s = gf::sim::SceneRenderer::create(std::string(GF_SOURCE_DIR) + "/third_party_models", scenario_, 1);
    if (!s) GTEST_SKIP() << "no EGL/OpenGL 3.3 here: " << s.reason();
    scene_ = std::move(*s);
    // The worker at the mission's start; two cameras 9 m from him, level, in the open (west of
    // him looking east, north of him looking south).
    gf::sim::WorkerModel worker(mission_.worker, 11);
    ws_ = worker.stateAt(0.0);
    std::vector<Vector3d> cams;
    uavs_.resize(2);
    uavs_[0].p_world = ws_.p_world + Vector3d(-9.0, 0.0, 0.0);
    uavs_[0].heading_rad = 0.0;
    uavs_[1].p_world = ws_.p_world + Vector3d(0.0, 9.0, 0.0);
    uavs_[1].heading_rad = -M_PI / 2.0;
    for (const auto& u : uavs_) cams.push_back(u.p_world);
    worker.skeletonsAt(0.0, cams);
    body_ = worker.bodyAt(0.0);
  }

  gf::planning::Scenario scenario_;
  gf::sim::MissionConfig mission_;
  std::unique_ptr<gf::sim::SceneRenderer> scene_;
  gf::sim::WorkerState ws_;
  std::vector<gf::sim::MultirotorState> uavs_;
  gf::gesture::Body3D body_;
};

TEST_F(SceneRendererTest, EachUavsCameraSeesTheWorkerWhereHeIs) {
  ASSERT_TRUE(scene_->setScene(body_, ws_.feet_world, ws_.heading_rad, mission_.worker.height_m, uavs_));
  const gf::estimation::CameraIntrinsics k = gf::sim::renderedIntrinsics(mission_);
  for (double d : k.distortion) EXPECT_EQ(d, 0.0);
  for (std::size_t i = 0; i < uavs_.size(); ++i) {
    const Eigen::Isometry3d T = scene_->cameraPose(i);
    const Eigen::Isometry3d expected =
        gf::render::cameraPoseFromHeadingPitch(uavs_[i].p_world, uavs_[i].heading_rad, uavs_[i].pitch_rad);
    EXPECT_TRUE(T.isApprox(expected, 1e-12)) << "uav " << i;
    auto f = scene_->render(i, k);
    ASSERT_TRUE(f) << f.reason();
    ASSERT_EQ(f->rgb.cols, k.width_px);
    ASSERT_EQ(f->depth_m.rows, k.height_px);
    ASSERT_GT(f->worker.visible_pixels, 500) << "uav " << i << ": the image centre sees class "
                                             << static_cast<int>(f->classes.at<std::uint8_t>(k.height_px / 2, k.width_px / 2))
                                             << " at " << f->depth_m.at<float>(k.height_px / 2, k.width_px / 2) << " m";
    const Vector3d p_camera = T.inverse() * ws_.p_world;
    const auto uv = gf::estimation::CameraModel(k).project(p_camera);
    ASSERT_TRUE(uv) << "uav " << i;
    const cv::Point px(static_cast<int>(std::lround(uv->x())), static_cast<int>(std::lround(uv->y())));
    EXPECT_TRUE(f->worker.visible_box_px.contains(px)) << "uav " << i << ": mid-body at " << px;
    const float z = f->depth_m.at<float>(px);
    ASSERT_TRUE(std::isfinite(z)) << "uav " << i;
    // the surface in front of the mid-body: nearer than it by less than the body's half depth
    EXPECT_LT(z, p_camera.z() + 0.05) << "uav " << i;
    EXPECT_GT(z, p_camera.z() - 0.4) << "uav " << i;
  }
}

TEST_F(SceneRendererTest, TheSameSeedGivesTheSameImages) {
  auto other = gf::sim::SceneRenderer::create(std::string(GF_SOURCE_DIR) + "/third_party_models", scenario_, 1);
  ASSERT_TRUE(other) << other.reason();
  const gf::estimation::CameraIntrinsics k = gf::sim::renderedIntrinsics(mission_);
  for (auto* s : {scene_.get(), other->get()}) {
    ASSERT_TRUE(s->setScene(body_, ws_.feet_world, ws_.heading_rad, mission_.worker.height_m, uavs_));
  }
  auto a = scene_->render(0, k);
  auto b = (*other)->render(0, k);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(cv::norm(a->rgb, b->rgb, cv::NORM_INF), 0.0);
}

TEST_F(SceneRendererTest, AUavTheSceneDoesNotHoldIsRefused) {
  ASSERT_TRUE(scene_->setScene(body_, ws_.feet_world, ws_.heading_rad, mission_.worker.height_m, uavs_));
  const auto f = scene_->render(2, gf::sim::renderedIntrinsics(mission_));
  ASSERT_FALSE(f);
  EXPECT_NE(f.reason().find("uav 2"), std::string::npos) << f.reason();
}

}  // namespace

// sim::SceneRenderer (docs/simulation.md §8, docs/ros.md "Rendered cameras"): the one renderer of
// a UAV's camera frame that gfctl simulate's RenderedCamera and the SimCamera nodelet share.
// Each UAV's camera is rendered at that UAV's heading / pitch (the worker's projected mid-body
// lies in his visible box, the depth there is his), the same seed gives the same images (every
// process of the ROS simulation dresses the worker alike), a UAV the scene does not hold is refused,
// and the site's unmapped obstacles are drawn where their motion puts them at the scene's time.
#include <gtest/gtest.h>

#include <cmath>
#include <tuple>
#include <utility>

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
  ASSERT_TRUE(scene_->setScene(body_, ws_.feet_world, ws_.heading_rad, mission_.worker.height_m, uavs_, 0.0));
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
    ASSERT_TRUE(s->setScene(body_, ws_.feet_world, ws_.heading_rad, mission_.worker.height_m, uavs_, 0.0));
  }
  auto a = scene_->render(0, k);
  auto b = (*other)->render(0, k);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(cv::norm(a->rgb, b->rgb, cv::NORM_INF), 0.0);
}

// A 0.5 x 2 x 2.5 m box 4 m in front of UAV 0's camera, between it and the worker: at t = 0 the
// worker's mid-body pixel sees the box (class obstacle, its near face 3.75 m away); the box moves
// 10 m north between 1 and 2 s, so at 3 s the pixel sees the worker again; a second box, parked in
// the same line of sight, hides him until it is gone (gone_after_s 4); an empty list removes them.
TEST_F(SceneRendererTest, UnmappedObstaclesAreDrawnWhereTheyAreAtTheScenesTime) {
  const gf::estimation::CameraIntrinsics k = gf::sim::renderedIntrinsics(mission_);
  gf::sim::UnmappedObstacle moving;
  moving.name = "crane_arm";
  moving.box.center_world = ws_.p_world + Vector3d(-5.0, 0.0, 0.0);
  moving.box.size_m = Vector3d(0.5, 2.0, 2.5);
  moving.motion.from_s = 1.0;
  moving.motion.to_s = 2.0;
  moving.motion.velocity_mps = Vector3d(0.0, 10.0, 0.0);
  gf::sim::UnmappedObstacle parked = moving;
  parked.name = "truck";
  parked.motion = gf::sim::ObstacleMotion();
  parked.motion.gone_after_s = 4.0;
  const Vector3d p_camera = gf::render::cameraPoseFromHeadingPitch(uavs_[0].p_world, 0.0, 0.0).inverse() * ws_.p_world;
  const auto uv = gf::estimation::CameraModel(k).project(p_camera);
  ASSERT_TRUE(uv);
  const cv::Point px(static_cast<int>(std::lround(uv->x())), static_cast<int>(std::lround(uv->y())));
  const auto seen = [&](double t_s) {  // class and depth at the worker's mid-body pixel
    EXPECT_TRUE(scene_->setScene(body_, ws_.feet_world, ws_.heading_rad, mission_.worker.height_m, uavs_, t_s));
    auto f = scene_->render(0, k);
    EXPECT_TRUE(f) << f.reason();
    return std::make_pair(static_cast<int>(f->classes.at<std::uint8_t>(px)), f->depth_m.at<float>(px));
  };
  const int obstacle = static_cast<int>(gf::render::PixelClass::kObstacle), worker = static_cast<int>(gf::render::PixelClass::kWorker);
  ASSERT_TRUE(scene_->setUnmappedObstacles({moving}));
  auto [cls, z] = seen(0.0);
  EXPECT_EQ(cls, obstacle);
  EXPECT_NEAR(z, 3.75, 0.01);
  std::tie(cls, z) = seen(3.0);
  EXPECT_EQ(cls, worker) << "the box moved out of the line of sight";
  ASSERT_TRUE(scene_->setUnmappedObstacles({moving, parked}));
  std::tie(cls, z) = seen(3.0);
  EXPECT_EQ(cls, obstacle) << "the parked box hides the worker";
  EXPECT_NEAR(z, 3.75, 0.01);
  std::tie(cls, z) = seen(4.5);
  EXPECT_EQ(cls, worker) << "the parked box is gone";
  std::tie(cls, z) = seen(3.0);
  EXPECT_EQ(cls, obstacle) << "back in time: the parked box is there again";
  ASSERT_TRUE(scene_->setUnmappedObstacles({}));
  std::tie(cls, z) = seen(0.0);
  EXPECT_EQ(cls, worker) << "an empty list removes them";
}

TEST_F(SceneRendererTest, AUavTheSceneDoesNotHoldIsRefused) {
  ASSERT_TRUE(scene_->setScene(body_, ws_.feet_world, ws_.heading_rad, mission_.worker.height_m, uavs_, 0.0));
  const auto f = scene_->render(2, gf::sim::renderedIntrinsics(mission_));
  ASSERT_FALSE(f);
  EXPECT_NE(f.reason().find("uav 2"), std::string::npos) << f.reason();
}

}  // namespace

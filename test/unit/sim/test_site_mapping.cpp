// sim::SiteMapping (docs/mapping.md §7): a UAV whose camera looks at an unmapped box maps it at
// its depth frames' rate, its live field sees the box, the world's obstacle distance counts it, a
// plan through the box is not "avoiding" it and one clear of it is; without mapping nothing is seen;
// with the cameras' own depth images (rendered cameras) the frames integrate those, not ray casts.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "gesture_formation/planning/trajectory_verifier.hpp"
#include "gesture_formation/planning/uav_planner.hpp"
#include "gesture_formation/sim/site_mapping.hpp"
#include "sim_test_support.hpp"

namespace gf = gesture_formation;

namespace {

std::vector<gf::sim::UnmappedObstacle> wallAhead() {
  gf::sim::UnmappedObstacle o;
  o.name = "wall";
  o.box.center_world = Eigen::Vector3d(6.0, 0.0, 3.0);
  o.box.size_m = Eigen::Vector3d(0.8, 6.0, 4.0);
  return {o};
}

gf::planning::MapConfig grid() {
  gf::planning::MapConfig mc;
  mc.resolution_m = 0.4;
  mc.bounds = gf::planning::Aabb{Eigen::Vector3d(-30, -30, 0), Eigen::Vector3d(30, 30, 20)};
  return mc;
}

/// UAV i at (0, −10 + 10i, 3), level, looking along +x: only UAV 1 has the wall in view.
std::vector<gf::sim::MultirotorState> uavsLookingEast(int n) {
  std::vector<gf::sim::MultirotorState> s(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    s[static_cast<std::size_t>(i)].p_world = Eigen::Vector3d(0.0, -10.0 + 10.0 * i, 3.0);
    s[static_cast<std::size_t>(i)].heading_rad = 0.0;
  }
  return s;
}

gf::planning::PlanResult straightPlan(double t0, const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  gf::planning::PlanResult r;
  r.status = gf::planning::PlanStatus::kOptimized;
  r.verified = true;
  r.trajectory.t0_s = t0;
  r.trajectory.dt_s = 0.2;
  for (int k = 0; k <= 10; ++k) {
    gf::planning::TrajectorySample s;
    s.p_world = from + (to - from) * (k / 10.0);
    r.trajectory.samples.push_back(s);
  }
  return r;
}

}  // namespace

TEST(SiteMappingTest, DiscoversAndMeasuresAvoidance) {
  const gf::sim::test::EmptyWorld w;
  gf::sim::MissionConfig cfg = gf::sim::test::openFieldWithoutRequests();
  cfg.mapping.enabled = true;
  cfg.mapping.rate_hz = 5.0;
  auto prior = std::make_shared<const gf::planning::OccupancyMap>(w.map);
  auto site = gf::sim::SiteMapping::create(cfg, grid(), prior, gf::planning::PrimitiveSet{}, 0.0, wallAhead());
  ASSERT_TRUE(static_cast<bool>(site)) << site.reason();
  gf::sim::SiteMapping& s = **site;
  ASSERT_TRUE(s.mapping());
  const int n = static_cast<int>(cfg.uavs.size());
  ASSERT_NE(s.field(1), nullptr);
  // UAV 1 (at y = 0) faces the wall; for UAVs 0 and 2 (y = ∓10) it is outside their ±27.5° view.
  const Eigen::Vector3d before_wall(5.2, 0.0, 3.0);  // 0.4 m in front of the wall, on UAV 1's line
  EXPECT_GT(s.field(1)->clearance(before_wall), 2.0);  // not in the prior map: free for the planner
  // The world's obstacle distance counts the wall.
  const gf::sim::ObstacleDistance d = s.withUnmapped(gf::sim::ObstacleDistance{&w.field, nullptr, 0.0});
  EXPECT_NEAR(d(before_wall), 0.4, 1e-9);
  // A plan through the wall made before anyone saw it: not counted (nothing seen yet).
  s.planned(1, 0.0, straightPlan(0.0, Eigen::Vector3d(0, 0, 3), Eigen::Vector3d(10, 0, 3)));
  // One second of steps at 100 Hz: 5 frames per UAV.
  for (int k = 0; k <= 100; ++k) s.step(k * 0.01, uavsLookingEast(n));
  EXPECT_LT(s.field(1)->clearance(before_wall), 0.5);  // now it is in UAV 1's live field
  EXPECT_GT(s.field(0)->clearance(before_wall), 2.0);  // not in UAV 0's: it never saw it
  const gf::sim::SiteMappingSummary before = s.summary();
  EXPECT_EQ(before.depth_frames, 5 * n + 1);  // UAV i at (k + i/n)/5 s: UAV 0 also at 1.0 s
  ASSERT_EQ(before.obstacles.size(), 1u);
  EXPECT_EQ(before.obstacles[0].first_seen_uav, 1);
  EXPECT_NEAR(before.obstacles[0].first_seen_s, 0.07, 1e-9);  // UAV 1's first frame: the step at 1/15 s
  EXPECT_GT(before.coverage, 0.05);  // its west face (of six) seen
  EXPECT_LT(before.coverage, 0.6);
  EXPECT_TRUE(std::isnan(before.obstacles[0].avoided_s));
  // A plan through the wall is not avoiding it, nor one ending 0.7 m before it (< the clearance
  // planner.obstacle_clearance_m 0.8); one that stays 2 m before it is.
  s.planned(1, 1.0, straightPlan(1.0, Eigen::Vector3d(0, 0, 3), Eigen::Vector3d(10, 0, 3)));
  s.planned(1, 1.2, straightPlan(1.2, Eigen::Vector3d(0, 0, 3), Eigen::Vector3d(4.9, 0, 3)));
  EXPECT_TRUE(std::isnan(s.summary().obstacles[0].avoided_s));
  s.planned(0, 1.3, straightPlan(1.3, Eigen::Vector3d(0, -10, 3), Eigen::Vector3d(3.6, -10, 3)));  // not the UAV that saw it
  EXPECT_TRUE(std::isnan(s.summary().obstacles[0].avoided_s));
  s.planned(1, 1.4, straightPlan(1.4, Eigen::Vector3d(0, 0, 3), Eigen::Vector3d(3.6, 0, 3)));
  const gf::sim::SiteMappingSummary after = s.summary();
  EXPECT_DOUBLE_EQ(after.obstacles[0].avoided_s, 1.4);
  EXPECT_NEAR(after.obstacles[0].sight_to_avoidance_s, 1.4 - after.obstacles[0].first_seen_s, 1e-12);
  EXPECT_NEAR(after.obstacles[0].min_distance_m, 5.6, 1e-9);  // UAV 1 at x = 0, the wall's face at 5.6
}

TEST(SiteMappingTest, WithoutMappingNothingIsSeenAndBadSettingsAreRefused) {
  const gf::sim::test::EmptyWorld w;
  gf::sim::MissionConfig cfg = gf::sim::test::openFieldWithoutRequests();
  auto prior = std::make_shared<const gf::planning::OccupancyMap>(w.map);
  auto site = gf::sim::SiteMapping::create(cfg, grid(), prior, gf::planning::PrimitiveSet{}, 0.0, wallAhead());
  ASSERT_TRUE(static_cast<bool>(site)) << site.reason();
  EXPECT_FALSE((*site)->mapping());
  EXPECT_EQ((*site)->field(0), nullptr);
  for (int k = 0; k <= 100; ++k) (*site)->step(k * 0.01, uavsLookingEast(static_cast<int>(cfg.uavs.size())));
  const auto s = (*site)->summary();
  EXPECT_EQ(s.depth_frames, 0);
  EXPECT_EQ(s.coverage, 0.0);
  EXPECT_TRUE(std::isnan(s.obstacles[0].first_seen_s));
  cfg.mapping.enabled = true;
  cfg.mapping.rate_hz = -1.0;
  const auto bad = gf::sim::SiteMapping::create(cfg, grid(), prior, gf::planning::PrimitiveSet{}, 0.0, wallAhead());
  ASSERT_FALSE(static_cast<bool>(bad));
  EXPECT_NE(bad.reason().find("mission.mapping.rate_hz"), std::string::npos) << bad.reason();
  EXPECT_NE(bad.reason().find("-1"), std::string::npos) << bad.reason();
}

// useOfferedDepth (gfctl simulate --camera rendered): the due frames integrate the offered images,
// each once, with their own pose and time — never a ray cast. UAV 1 faces the wall but is offered
// nothing: its map stays empty; UAV 0 (whose view misses the wall) is offered an image of a plane
// 5 m ahead that the world does not hold: its map gets that plane.
TEST(SiteMappingTest, OfferedDepthImagesReplaceTheRayCastFrames) {
  const gf::sim::test::EmptyWorld w;
  gf::sim::MissionConfig cfg = gf::sim::test::openFieldWithoutRequests();
  cfg.mapping.enabled = true;
  cfg.mapping.rate_hz = 5.0;
  cfg.mapping.travel_camera_hfov_deg = 0.0;
  auto prior = std::make_shared<const gf::planning::OccupancyMap>(w.map);
  auto site = gf::sim::SiteMapping::create(cfg, grid(), prior, gf::planning::PrimitiveSet{}, 0.0, wallAhead());
  ASSERT_TRUE(static_cast<bool>(site)) << site.reason();
  gf::sim::SiteMapping& s = **site;
  s.useOfferedDepth();
  const int n = static_cast<int>(cfg.uavs.size());
  for (int k = 0; k <= 100; ++k) s.step(k * 0.01, uavsLookingEast(n));
  EXPECT_EQ(s.summary().depth_frames, 0) << "frames fell due but no image was offered";
  EXPECT_EQ(s.summary().camera, "rendered");
  const Eigen::Vector3d before_wall(5.2, 0.0, 3.0), ahead_of_uav0(5.0, -10.0, 3.0);
  EXPECT_GT(s.field(1)->clearance(before_wall), 2.0);
  gf::sim::CameraDepth image;
  image.t_s = 1.05;
  image.intrinsics = cfg.estimator.camera;
  image.intrinsics.distortion.fill(0.0);
  image.T_world_camera = gf::sim::opticalPoseFromHeadingPitch(uavsLookingEast(n)[0].p_world, 0.0, 0.0);
  image.depth_m = cv::Mat(image.intrinsics.height_px, image.intrinsics.width_px, CV_32FC1, cv::Scalar(5.0));
  s.offerDepth(0, image);
  for (int k = 101; k <= 120; ++k) s.step(k * 0.01, uavsLookingEast(n));  // UAV 0's frame at 1.2 s
  EXPECT_EQ(s.summary().depth_frames, 1);
  EXPECT_LT(s.field(0)->clearance(ahead_of_uav0), 0.5) << "the offered plane is in UAV 0's map";
  EXPECT_GT(s.field(1)->clearance(before_wall), 2.0) << "UAV 1 was offered nothing";
  for (int k = 121; k <= 160; ++k) s.step(k * 0.01, uavsLookingEast(n));  // UAV 0's frame at 1.4 s: nothing new
  EXPECT_EQ(s.summary().depth_frames, 1) << "an offered image is integrated once";
}

// The travel camera (mission.mapping.travel_camera_hfov_deg): UAV 0 looks north (its worker
// camera) but its reference lies east, where the wall is: only with the travel camera does its
// live map hold the wall.
TEST(SiteMappingTest, TravelCameraLooksWhereTheReferenceLeads) {
  const gf::sim::test::EmptyWorld w;
  auto prior = std::make_shared<const gf::planning::OccupancyMap>(w.map);
  for (const double hfov : {0.0, 87.0}) {
    gf::sim::MissionConfig cfg = gf::sim::test::openFieldWithoutRequests();
    cfg.mapping.enabled = true;
    cfg.mapping.travel_camera_hfov_deg = hfov;
    auto site = gf::sim::SiteMapping::create(cfg, grid(), prior, gf::planning::PrimitiveSet{}, 0.0, wallAhead());
    ASSERT_TRUE(static_cast<bool>(site)) << site.reason();
    gf::sim::SiteMapping& s = **site;
    const int n = static_cast<int>(cfg.uavs.size());
    std::vector<gf::sim::MultirotorState> uavs = uavsLookingEast(n);
    uavs[0].p_world = Eigen::Vector3d(0.0, 0.0, 3.0);  // in front of the wall, camera north
    uavs[0].heading_rad = M_PI / 2;
    gf::formation::ReferenceTrajectory ref;
    ref.resize(11);
    for (int k = 0; k <= 10; ++k) {
      ref.p_world.col(k) = Eigen::Vector3d(0.5 * k, 0.0, 3.0);
      ref.heading_rad(k) = M_PI / 2;
      ref.pitch_rad(k) = 0.0;
    }
    s.planned(0, 0.0, gf::planning::PlanResult{}, ref, 0.2);
    for (int k = 0; k <= 100; ++k) s.step(k * 0.01, uavs);
    const Eigen::Vector3d before_wall(5.2, 0.0, 3.0);
    if (hfov > 0.0) {
      EXPECT_LT(s.field(0)->clearance(before_wall), 0.5) << "the travel camera must see the wall";
      EXPECT_EQ(s.summary().obstacles[0].first_seen_uav, 0);
    } else {
      EXPECT_GT(s.field(0)->clearance(before_wall), 2.0) << "the worker camera looks north: no wall";
    }
  }
  gf::sim::MissionConfig bad = gf::sim::test::openFieldWithoutRequests();
  bad.mapping.enabled = true;
  bad.mapping.travel_camera_hfov_deg = 150.0;
  const auto refused = gf::sim::SiteMapping::create(bad, grid(), prior, gf::planning::PrimitiveSet{}, 0.0, wallAhead());
  ASSERT_FALSE(static_cast<bool>(refused));
  EXPECT_NE(refused.reason().find("mission.mapping.travel_camera_hfov_deg"), std::string::npos) << refused.reason();
}

// Map sharing (mission.mapping.share; docs/mapping.md §8). Only UAV 1 sees the wall (UAVs 0 and 2
// look east from y = ∓10, the wall outside their view). UAV 0's planner, asked to fly through the
// wall's place, plans through it without sharing — the control, which must fail — and around it,
// clear of the real wall, with sharing, on a budget the updates respect.
namespace {

struct ShareRun {
  gf::planning::PlanResult plan;
  double least_wall_distance_m = 0.0;  // the plan (dense in time) to the real wall
  gf::sim::MapShareSummary share;
  double b_field_at_wall = 0.0;
};

ShareRun flyUav0ThroughTheWall(bool share, const gf::sim::LinkConfig& link, double max_bytes_per_s = 50000.0,
                              bool uav0_offline = false) {
  const gf::sim::test::EmptyWorld w;
  gf::sim::MissionConfig cfg = gf::sim::test::openFieldWithoutRequests();
  cfg.mapping.enabled = true;
  cfg.mapping.live.share.enabled = share;
  cfg.mapping.live.share.max_bytes_per_s = max_bytes_per_s;
  auto prior = std::make_shared<const gf::planning::OccupancyMap>(w.map);
  auto site = gf::sim::SiteMapping::create(cfg, grid(), prior, gf::planning::PrimitiveSet{}, 0.0, wallAhead());
  EXPECT_TRUE(static_cast<bool>(site)) << site.reason();
  gf::sim::SiteMapping& s = **site;
  s.openShareLinks(link, 11);
  const int n = static_cast<int>(cfg.uavs.size());
  std::vector<bool> offline(static_cast<std::size_t>(n), false);
  offline[0] = uav0_offline;
  for (int k = 0; k <= 200; ++k) s.step(k * 0.01, uavsLookingEast(n), offline);  // 2 s
  ShareRun out;
  out.share = s.summary().share;
  const gf::mapping::LiveMap& b = *s.liveMap(0);
  out.b_field_at_wall = b.field()->clearance(Eigen::Vector3d(5.4, 0.0, 3.0));
  gf::planning::PlannerConfig pc = cfg.planner;
  pc.time_budget_ms = 0.0;  // deterministic under load
  gf::planning::UavPlanner planner(pc, b.map(), b.field());  // the map's content is what is tested here
  gf::planning::PlanRequest r;
  r.t_now_s = 2.0;
  r.state.t_s = 2.0;
  r.state.p_world = Eigen::Vector3d(1.0, 0.0, 3.0);
  r.dt_s = 0.2;
  const int steps = 41;
  r.reference.resize(steps);
  r.worker.p_world.resize(3, steps);
  r.worker.heading_rad.resize(1, steps);
  for (int k = 0; k < steps; ++k) {
    r.reference.p_world.col(k) = Eigen::Vector3d(std::min(1.0 + 0.6 * k, 11.0), 0.0, 3.0);  // through x = 6
    r.reference.heading_rad(k) = 0.0;
    r.reference.pitch_rad(k) = 0.0;
    r.worker.p_world.col(k) = Eigen::Vector3d(-4.0, 8.0, 0.0);
    r.worker.heading_rad(k) = 0.0;
  }
  out.plan = planner.plan(r);
  out.least_wall_distance_m = std::numeric_limits<double>::infinity();
  if (out.plan.verified && !out.plan.trajectory.empty()) {
    const gf::planning::PlannedTrajectory& t = out.plan.trajectory;
    for (double ts = t.t0_s; ts <= t.tEnd() + 1e-9; ts += t.dt_s / 8) {
      out.least_wall_distance_m = std::min(out.least_wall_distance_m, s.unmappedDistanceNow(gf::planning::evaluateTrajectory(t, ts).p));
    }
  }
  return out;
}

}  // namespace

TEST(SiteMappingShareTest, AUavAvoidsAWallOnlyAnotherSawBecauseOfTheShare) {
  const gf::sim::LinkConfig clean;
  const ShareRun without = flyUav0ThroughTheWall(false, clean);
  ASSERT_TRUE(without.plan.verified) << without.plan.reason;
  EXPECT_GT(without.b_field_at_wall, 2.0) << "UAV 0 must not see the wall itself";
  EXPECT_LT(without.least_wall_distance_m, 0.2) << "the control: without sharing UAV 0 plans into the wall";
  EXPECT_FALSE(without.share.enabled);
  EXPECT_EQ(without.share.updates_sent, 0);

  const ShareRun with = flyUav0ThroughTheWall(true, clean);
  ASSERT_TRUE(with.plan.verified) << with.plan.reason;
  EXPECT_LT(with.b_field_at_wall, 0.5) << "UAV 1's wall is in UAV 0's field";
  EXPECT_GT(with.least_wall_distance_m, 0.5) << "with sharing UAV 0 plans around the wall";
  EXPECT_TRUE(with.share.enabled);
  EXPECT_GT(with.share.updates_sent, 0);
  EXPECT_EQ(with.share.updates_merged, with.share.updates_sent * 2);  // each to the 2 others, clean link
  EXPECT_EQ(with.share.updates_lost + with.share.updates_refused, 0);
  EXPECT_LE(with.share.age_s_max, 0.5 + 0.02 + 1e-9);  // at most one share period (2 Hz) + the link delay
  EXPECT_GT(with.share.bytes_per_s_max, 0.0);
}

TEST(SiteMappingShareTest, UpdatesKeepTheByteBudgetAndSufferTheLinkAndDropouts) {
  // A budget of 1 000 B/s at 2 Hz: 500 B per update, 63 voxels; the wall's face (15 × 10 voxels of
  // 0.4 m) takes UAV 1 three updates, nearest first — all within the 2 s.
  const ShareRun tight = flyUav0ThroughTheWall(true, gf::sim::LinkConfig{}, 1000.0);
  EXPECT_LE(tight.share.bytes_per_s_max, 1000.0);
  EXPECT_GT(tight.share.changes_deferred, 0);
  EXPECT_GE(tight.share.updates_sent, 3);
  EXPECT_EQ(tight.share.changes_dropped, 0);
  EXPECT_LT(tight.b_field_at_wall, 0.5) << "the wall arrives, later";
  // A link that loses everything: sent, never merged; UAV 0 plans into the wall as without sharing.
  gf::sim::LinkConfig lossy;
  lossy.loss_probability = 1.0;
  const ShareRun lost = flyUav0ThroughTheWall(true, lossy);
  EXPECT_GT(lost.share.updates_sent, 0);
  EXPECT_EQ(lost.share.updates_merged, 0);
  EXPECT_EQ(lost.share.updates_lost, lost.share.updates_sent * 2);
  EXPECT_GT(lost.b_field_at_wall, 2.0);
  // UAV 0 offline (a dropout): what reaches it is lost, nothing merged into its map.
  const ShareRun dropout = flyUav0ThroughTheWall(true, gf::sim::LinkConfig{}, 50000.0, true);
  EXPECT_GT(dropout.b_field_at_wall, 2.0);
  EXPECT_GT(dropout.share.updates_lost, 0);
}

// The planner on the live map: a UavPlanner built once on LiveMap::map() / field() (shared, never
// copied) plans straight through space it has not seen; after one depth frame of a wall across
// that path, its next plan keeps the verification clearance from every occupied voxel centre of
// the wall (brute force), and the previous plan no longer would.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "gesture_formation/mapping/live_map.hpp"
#include "gesture_formation/planning/trajectory_verifier.hpp"
#include "gesture_formation/planning/uav_planner.hpp"

using namespace gesture_formation;
using namespace gesture_formation::planning;

namespace {

/// A camera at p looking along world +x, 640×480, f = 400 px; the depth of an axis-aligned box
/// (slab method per pixel), +Inf elsewhere.
mapping::DepthFrame wallFrame(const Eigen::Vector3d& p, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  mapping::DepthFrame f;
  f.intrinsics = mapping::PinholeIntrinsics{400.0, 400.0, 319.5, 239.5};
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // columns: optical x = −y, y = −z, z = +x (world)
  f.T_world_camera.linear() = R;
  f.T_world_camera.translation() = p;
  f.depth_m = cv::Mat(480, 640, CV_32FC1);
  for (int v = 0; v < 480; ++v) {
    for (int u = 0; u < 640; ++u) {
      const Eigen::Vector3d d = R * Eigen::Vector3d((u - 319.5) / 400.0, (v - 239.5) / 400.0, 1.0);
      double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
      for (int i = 0; i < 3; ++i) {
        if (std::abs(d(i)) < 1e-12) {
          if (p(i) < lo(i) || p(i) > hi(i)) t0 = std::numeric_limits<double>::infinity();
          continue;
        }
        double a = (lo(i) - p(i)) / d(i), b = (hi(i) - p(i)) / d(i);
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
      }
      f.depth_m.at<float>(v, u) = t0 <= t1 ? static_cast<float>(t0) : std::numeric_limits<float>::infinity();
    }
  }
  return f;
}

PlanRequest straightRequest(double t, const UavKinematicState& state, const Eigen::Vector3d& from, const Eigen::Vector3d& to,
                            double speed, const Eigen::Vector3d& worker) {
  PlanRequest r;
  r.t_now_s = t;
  r.state = state;
  r.dt_s = 0.2;
  const int steps = 41;
  r.reference.resize(steps);
  r.worker.p_world.resize(3, steps);
  r.worker.heading_rad.resize(1, steps);
  const double len = (to - from).norm();
  for (int k = 0; k < steps; ++k) {
    const double s = std::min(1.0, speed * (t + k * r.dt_s) / len);
    r.reference.p_world.col(k) = from + s * (to - from);
    r.reference.heading_rad(k) = 0.0;
    r.reference.pitch_rad(k) = 0.0;
    r.worker.p_world.col(k) = worker;
    r.worker.heading_rad(k) = 0.0;
  }
  return r;
}

/// Smallest distance from the plan (dense in time) to the occupied voxel centres (brute force).
double planClearance(const PlannedTrajectory& plan, const OccupancyMap& map) {
  const std::vector<Eigen::Vector3d> centres = map.occupiedCenters();
  double d = std::numeric_limits<double>::infinity();
  for (double t = plan.t0_s; t <= plan.tEnd() + 1e-9; t += plan.dt_s / 8) {
    const Eigen::Vector3d p = evaluateTrajectory(plan, t).p;
    for (const auto& c : centres) d = std::min(d, (c - p).norm());
  }
  return d;
}

}  // namespace

TEST(LiveMapPlannerTest, PlannerOnTheLiveMapAvoidsAWallSeenAfterItsFirstPlan) {
  MapConfig grid;
  grid.resolution_m = 0.2;
  grid.bounds = Aabb{Eigen::Vector3d(-2.0, -8.0, -1.0), Eigen::Vector3d(30.0, 8.0, 9.0)};
  auto live = mapping::LiveMap::create(mapping::MappingConfig{}, grid);
  ASSERT_TRUE(live) << live.reason();
  PlannerConfig cfg;
  cfg.time_budget_ms = 0.0;  // deterministic under load
  UavPlanner planner(cfg, (*live)->map(), (*live)->field());
  ASSERT_TRUE(planner.configError().empty()) << planner.configError();

  const Eigen::Vector3d start(0.0, 0.0, 4.0), goal(24.0, 0.0, 4.0), worker(-1.0, 7.0, 0.0);
  UavKinematicState state;
  state.p_world = start;
  const PlanResult first = planner.plan(straightRequest(0.0, state, start, goal, 3.0, worker));
  ASSERT_EQ(first.status, PlanStatus::kOptimized) << first.reason;
  EXPECT_EQ((*live)->map()->occupiedCount(), 0u);

  // A wall across the route, 8.1 m ahead: x ∈ [8.1, 8.9], y ∈ [−2.1, 2.1], z ∈ [2.1, 5.9].
  const Eigen::Vector3d lo(8.1, -2.1, 2.1), hi(8.9, 2.1, 5.9);
  const auto seen = (*live)->integrate(wallFrame(start, lo, hi));
  ASSERT_TRUE(seen) << seen.reason();
  ASSERT_GT((*live)->map()->occupiedCount(), 300u);  // the wall's front face, 21 × 19 voxels
  const double rho = OccupancyMap::rasterInflation(grid.resolution_m);
  EXPECT_LT(planClearance(first.trajectory, *(*live)->map()), cfg.verify_clearance_m + rho)
      << "the first plan must run into the wall, or this test shows nothing";

  const TrajectoryPoint now = evaluateTrajectory(first.trajectory, 0.2);
  state.t_s = 0.2;
  state.p_world = now.p;
  state.v_world = now.v;
  const PlanResult second = planner.plan(straightRequest(0.2, state, start, goal, 3.0, worker));
  ASSERT_TRUE(second.verified) << second.reason;
  EXPECT_NE(second.status, PlanStatus::kFallbackPrevious) << "the previous plan crosses the wall: " << second.reason;
  EXPECT_GE(planClearance(second.trajectory, *(*live)->map()), cfg.verify_clearance_m + rho - 1e-6);
  EXPECT_EQ(second.status, PlanStatus::kOptimized) << second.reason;
}

// The seen-space rule (planning/seen_space.hpp): a planner given the live map's SeenSpace does not
// fly off into space no depth frame has covered; one frame along the route (nothing within range:
// free space up to depth.max_range_m) lets it go, and its plan's braking paths stay in that view.
TEST(LiveMapPlannerTest, SeenSpaceRuleKeepsThePlannerInsideWhatItsCameraHasSeen) {
  MapConfig grid;
  grid.resolution_m = 0.2;
  grid.bounds = Aabb{Eigen::Vector3d(-2.0, -8.0, -1.0), Eigen::Vector3d(30.0, 8.0, 9.0)};
  auto live = mapping::LiveMap::create(mapping::MappingConfig{}, grid);
  ASSERT_TRUE(live) << live.reason();
  PlannerConfig cfg;
  cfg.time_budget_ms = 0.0;
  UavPlanner blind(cfg, (*live)->map(), (*live)->field());
  UavPlanner planner(cfg, (*live)->map(), (*live)->field(), (*live)->seen());
  const Eigen::Vector3d start(0.0, 0.0, 4.0), goal(24.0, 0.0, 4.0), worker(-1.0, 7.0, 0.0);
  UavKinematicState state;
  state.p_world = start;
  const PlanRequest request = straightRequest(0.0, state, start, goal, 3.0, worker);
  ASSERT_EQ(blind.plan(request).status, PlanStatus::kOptimized) << "without the rule the same request must be planned";
  const PlanResult first = planner.plan(request);
  EXPECT_NE(first.status, PlanStatus::kOptimized) << "nothing seen: the plan must not be flown";
  EXPECT_NE(first.reason.find("unobserved"), std::string::npos) << first.reason;

  // One frame looking along +x from the start (the box behind the camera: every pixel +Inf).
  ASSERT_TRUE((*live)->integrate(wallFrame(start, Eigen::Vector3d(-2.0, -1.0, 3.0), Eigen::Vector3d(-1.5, 1.0, 5.0))));
  const PlanResult second = planner.plan(straightRequest(0.0, state, start, goal, 3.0, worker));
  ASSERT_EQ(second.status, PlanStatus::kOptimized) << second.reason;
  const planning::SeenSpace& seen = *(*live)->seen();
  for (double t = 0.0; t <= cfg.limits.max_speed_mps && t <= 1.0; t += 0.05) {
    const TrajectoryPoint x = evaluateTrajectory(second.trajectory, t);
    EXPECT_TRUE(seen.seen(brakeStop(x.p, x.v, cfg.limits, 0.2))) << "braking from t=" << t << " ends unseen";
  }
}

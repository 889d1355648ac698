// The seen-space rule (planning/seen_space.hpp, docs/mapping.md §3.1): a plan passes verification
// only if, from every point within the rule's horizon, the braking path runs through observed
// voxels (within the margin), the plan's start exempt. Each test first shows the plan passes
// when everything is seen, so a failure is the rule's and nothing else's.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/seen_space.hpp"
#include "gesture_formation/planning/trajectory_verifier.hpp"

using namespace gesture_formation::planning;

namespace {

OccupancyMap emptyMap() {
  MapConfig grid;
  grid.resolution_m = 0.2;
  grid.bounds = Aabb{Eigen::Vector3d(-4.0, -4.0, 0.0), Eigen::Vector3d(12.0, 4.0, 6.0)};
  return OccupancyMap::fromPrimitives(grid, PrimitiveSet{}, GroundSpec{});
}

/// Constant velocity v along +x from (0, 0, 3), 2 s at dt 0.2.
PlannedTrajectory cruise(double v_mps) {
  PlannedTrajectory tr;
  tr.t0_s = 0.0;
  tr.dt_s = 0.2;
  for (int k = 0; k <= 10; ++k) {
    TrajectorySample s;
    s.p_world = Eigen::Vector3d(v_mps * 0.2 * k, 0.0, 3.0);
    s.v_world = Eigen::Vector3d(v_mps, 0.0, 0.0);
    tr.samples.push_back(s);
  }
  return tr;
}

/// Marks every voxel of the grid seen except those whose centres satisfy `hole`.
template <class Hole>
void markAllBut(SeenSpace& seen, const OccupancyMap& map, Hole hole) {
  const VoxelIndex n = map.gridSize();
  for (int k = 0; k < n.z(); ++k) {
    for (int j = 0; j < n.y(); ++j) {
      for (int i = 0; i < n.x(); ++i) {
        const Eigen::Vector3d c = map.centerOf(map.gridOrigin() + VoxelIndex(i, j, k));
        if (hole(c)) continue;
        seen.markLinear(static_cast<std::size_t>(i) + static_cast<std::size_t>(n.x()) *
                                                          (static_cast<std::size_t>(j) + static_cast<std::size_t>(n.y()) * k));
      }
    }
  }
}

struct Fixture {
  OccupancyMap map = emptyMap();
  DistanceField field{map};
  PlannerConfig config;
  SeenRule rule;
  SeenSpace seen{map, rule};
  VerificationReport verify(const PlannedTrajectory& tr) {
    TrajectoryVerifier v(map, field, config, &seen);
    return v.verify(tr, tr.t0_s, {}, {}, 0.0, 0.2);
  }
};

}  // namespace

TEST(SeenSpaceTest, NothingSeenFailsAMovingPlanAndPassesAHover) {
  Fixture f;
  const VerificationReport moving = f.verify(cruise(2.0));
  EXPECT_FALSE(moving.ok);
  EXPECT_NE(moving.reason.find("unobserved"), std::string::npos) << moving.reason;
  // A hover: every braking path is the start itself, exempt within the margin (the UAV is there).
  const VerificationReport hover = f.verify(cruise(0.0));
  EXPECT_TRUE(hover.ok) << hover.reason;
  // The same verifier without a SeenSpace: no rule.
  TrajectoryVerifier plain(f.map, f.field, f.config);
  EXPECT_TRUE(plain.verify(cruise(2.0), 0.0, {}, {}, 0.0, 0.2).ok);
}

TEST(SeenSpaceTest, AnUnseenVoxelWithinTheMarginOfABrakingPathFails) {
  Fixture f;
  markAllBut(f.seen, f.map, [](const Eigen::Vector3d&) { return false; });
  ASSERT_TRUE(f.verify(cruise(2.0)).ok) << "all seen: the plan must pass, or this test shows nothing";
  // At 2 m/s the point at t = 1 s (x = 2) brakes to x = 2 + 4/(2·3) ≈ 2.67 (on the 0.2 s grid: 2.8).
  // One unseen voxel at x ≈ 2.5, 0.1 m beside the path: the rule must fail and name it.
  Fixture g;
  markAllBut(g.seen, g.map, [](const Eigen::Vector3d& c) {
    return std::abs(c.x() - 2.5) < 0.01 && std::abs(c.y() - 0.1) < 0.01 && std::abs(c.z() - 3.1) < 0.01;
  });
  const VerificationReport r = g.verify(cruise(2.0));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.reason.find("2.5 0.1 3.1"), std::string::npos) << r.reason;
  // The same voxel moved beyond the margin (0.5 m beside the path): passes.
  Fixture h;
  markAllBut(h.seen, h.map, [](const Eigen::Vector3d& c) {
    return std::abs(c.x() - 2.5) < 0.01 && std::abs(c.y() - 0.5) < 0.01 && std::abs(c.z() - 3.1) < 0.01;
  });
  EXPECT_TRUE(h.verify(cruise(2.0)).ok);
}

TEST(SeenSpaceTest, OnlyPointsWithinTheHorizonAndTheirBrakingPathsCount) {
  // Unseen beyond x = 3.2: the 1 s horizon's last braking path (from x = 2 at 2 m/s) stops
  // short of it (≤ 2.8 + margin 0.3 ≤ 3.1), although the plan itself flies on to x = 4.
  Fixture f;
  markAllBut(f.seen, f.map, [](const Eigen::Vector3d& c) { return c.x() > 3.2; });
  EXPECT_TRUE(f.verify(cruise(2.0)).ok) << f.verify(cruise(2.0)).reason;
  // A longer horizon reaches it.
  Fixture g;
  g.rule.horizon_s = 1.6;
  g.seen = SeenSpace(g.map, g.rule);
  markAllBut(g.seen, g.map, [](const Eigen::Vector3d& c) { return c.x() > 3.2; });
  EXPECT_FALSE(g.verify(cruise(2.0)).ok);
  // Faster: the braking path from t = 1 s (x = 3, 3 m/s → stop at x ≈ 4.5) reaches it too.
  EXPECT_FALSE(f.verify(cruise(3.0)).ok);
}

TEST(SeenSpaceTest, PriorOccupiedVoxelsCountAsSeenAndOutsideTheGridDoesNot) {
  MapConfig grid;
  grid.resolution_m = 0.2;
  grid.bounds = Aabb{Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(4.0, 4.0, 4.0)};
  PrimitiveSet solids;
  OrientedBox box;
  box.center_world = Eigen::Vector3d(2.0, 2.0, 2.0);
  box.size_m = Eigen::Vector3d(1.0, 1.0, 1.0);
  solids.boxes.push_back(box);
  const OccupancyMap map = OccupancyMap::fromPrimitives(grid, solids, GroundSpec{});
  SeenSpace seen(map, SeenRule{});
  EXPECT_FALSE(seen.seen(Eigen::Vector3d(2.0, 2.0, 2.0)));
  seen.markOccupied(map);
  EXPECT_TRUE(seen.seen(Eigen::Vector3d(2.0, 2.0, 2.0)));
  EXPECT_FALSE(seen.seen(Eigen::Vector3d(0.5, 0.5, 0.5)));
  EXPECT_EQ(seen.seenCount(), map.occupiedCount());
  EXPECT_FALSE(seen.seen(Eigen::Vector3d(-1.0, 2.0, 2.0)));
}

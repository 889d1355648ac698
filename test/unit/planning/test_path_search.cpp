// GridPathSearch (stage 2): a goal in a closed pocket fails after the pocket check, not after
// the whole expansion budget; a goal behind a large wall with a gap is still found after the
// check ran (it must not refuse a reachable goal).
#include <gtest/gtest.h>

#include <string>

#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/path_search.hpp"

using namespace gesture_formation::planning;

namespace {

MapConfig mapConfig() {
  MapConfig m;
  m.resolution_m = 0.2;
  m.bounds = Aabb{Eigen::Vector3d(-10, -10, -10), Eigen::Vector3d(10, 10, 10)};
  return m;
}

OrientedBox box(const Eigen::Vector3d& c, const Eigen::Vector3d& size) {
  OrientedBox b;
  b.center_world = c;
  b.size_m = size;
  return b;
}

/// A hollow cube around the origin: 4 m outside, 0.4 m walls (inside 3.2 m across), closed.
PrimitiveSet closedShell() {
  PrimitiveSet s;
  for (int axis = 0; axis < 3; ++axis) {
    for (double side : {-1.8, 1.8}) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero(), size = Eigen::Vector3d::Constant(4.0);
      c(axis) = side;
      size(axis) = 0.4;
      s.boxes.push_back(box(c, size));
    }
  }
  return s;
}

}  // namespace

TEST(GridPathSearchTest, GoalInAClosedPocketFailsAfterThePocketCheck) {
  const OccupancyMap map = OccupancyMap::fromPrimitives(mapConfig(), closedShell(), GroundSpec{});
  const DistanceField field(map);
  const GridPathSearch search(map, field);
  GridPathSearch::Stats stats;
  const auto r = search.search(Eigen::Vector3d(8, 0, 0), Eigen::Vector3d(0, 0, 0), 0.3, 0.3, 9.0, 200'000, &stats);
  ASSERT_FALSE(r.has_value());
  EXPECT_NE(r.reason().find("closed pocket"), std::string::npos) << r.reason();
  EXPECT_EQ(stats.expansions, GridPathSearch::kPocketCheckAfter) << "the budget of 200000 was not spent";
  // The same goal from inside the pocket is reachable (the check does not refuse it).
  const auto inside = search.search(Eigen::Vector3d(0.8, 0.8, 0.8), Eigen::Vector3d(0, 0, 0), 0.3, 0.3, 9.0, 200'000);
  ASSERT_TRUE(inside.has_value()) << inside.reason();
}

TEST(GridPathSearchTest, GoalBehindALargeWallWithAGapIsFoundAfterThePocketCheck) {
  PrimitiveSet s;
  // A 0.4 m wall across x = 0 through the whole map (to ±11 m, past its ±10 m bounds) except a
  // 1.8 m square gap at y, z in [7.1, 8.9].
  s.boxes.push_back(box(Eigen::Vector3d(0, -1.95, 0), Eigen::Vector3d(0.4, 18.2, 22.0)));   // y ≤ 7.1
  s.boxes.push_back(box(Eigen::Vector3d(0, 8.0, -1.95), Eigen::Vector3d(0.4, 1.8, 18.2)));  // the gap's column, z ≤ 7.1
  s.boxes.push_back(box(Eigen::Vector3d(0, 9.95, 0), Eigen::Vector3d(0.4, 2.1, 22.0)));     // y ≥ 8.9
  s.boxes.push_back(box(Eigen::Vector3d(0, 8.0, 9.95), Eigen::Vector3d(0.4, 1.8, 2.1)));    // the gap's column, z ≥ 8.9
  const OccupancyMap map = OccupancyMap::fromPrimitives(mapConfig(), s, GroundSpec{});
  const DistanceField field(map);
  const GridPathSearch search(map, field);
  GridPathSearch::Stats stats;
  const Eigen::Vector3d a(2, 2, 2), b(-2, 2, 2);
  const auto r = search.search(a, b, 0.3, 0.3, 16.0, 1'000'000, &stats);
  ASSERT_TRUE(r.has_value()) << r.reason();
  EXPECT_GT(stats.expansions, GridPathSearch::kPocketCheckAfter) << "the check must have run on this search";
  const auto& path = r.value();
  EXPECT_EQ(path.front(), a);
  EXPECT_EQ(path.back(), b);
  bool through_gap = false;
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    if (i > 0) {
      EXPECT_GE(field.clearance(path[i]), 0.3) << "waypoint " << i;  // voxel centres ≥ the clearance
    }
    if ((path[i].x() > 0) != (path[i + 1].x() > 0)) {
      const Eigen::Vector3d mid = 0.5 * (path[i] + path[i + 1]);
      through_gap = mid.y() > 7.0 && mid.z() > 7.0;
    }
  }
  EXPECT_TRUE(through_gap) << "the path crosses x = 0 through the gap";
}

// GridPathSearch (stage 2): a goal in a closed pocket fails after the pocket check, not after
// the whole expansion budget; a goal behind a large wall with a gap is still found after the
// check ran (it must not refuse a reachable goal).
#include <gtest/gtest.h>

#include <array>
#include <limits>
#include <string>

#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/path_search.hpp"
#include "gesture_formation/planning/shapes.hpp"

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

TEST(GridPathSearchTest, GoalStillInThePocketAtTheNextSearchFailsBeforeExpanding) {
  const OccupancyMap map = OccupancyMap::fromPrimitives(mapConfig(), closedShell(), GroundSpec{});
  const DistanceField field(map);
  const GridPathSearch search(map, field);
  const Eigen::Vector3d outside(8, 0, 0), in_pocket(0, 0, 0), also_inside(0.8, 0.8, 0.8);
  GridPathSearch::Stats first, again, from_inside, after;
  ASSERT_FALSE(search.search(outside, in_pocket, 0.3, 0.3, 9.0, 200'000, &first).has_value());
  EXPECT_EQ(first.expansions, GridPathSearch::kPocketCheckAfter);
  // The next search to the pocket: the flood runs first, the same answer without expansions.
  const auto r = search.search(outside + Eigen::Vector3d(0, 0.4, 0), in_pocket, 0.3, 0.3, 9.0, 200'000, &again);
  ASSERT_FALSE(r.has_value());
  EXPECT_NE(r.reason().find("closed pocket"), std::string::npos) << r.reason();
  EXPECT_EQ(again.expansions, 0);
  // A reachable goal right after (the start inside the pocket): the early flood reaches the start
  // and the search runs as usual.
  const auto inside = search.search(also_inside, in_pocket, 0.3, 0.3, 9.0, 200'000, &from_inside);
  ASSERT_TRUE(inside.has_value()) << inside.reason();
  EXPECT_GT(from_inside.expansions, 0);
  // That success clears the memory: the next pocket search expands until the regular check.
  ASSERT_FALSE(search.search(outside, in_pocket, 0.3, 0.3, 9.0, 200'000, &after).has_value());
  EXPECT_EQ(after.expansions, GridPathSearch::kPocketCheckAfter);
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

TEST(GridPathSearchTest, KeepOutTubeIsGoneAroundAndNeverEntered) {
  // Free space (no obstacles): a → b straight through the tube. Without it the path is the
  // straight segment; with it, every piece of the path stays outside the tube.
  const OccupancyMap map = OccupancyMap::fromPrimitives(mapConfig(), PrimitiveSet{}, GroundSpec{});
  const DistanceField field(map);
  const GridPathSearch search(map, field);
  const Eigen::Vector3d a(-6, 0.1, 0.1), b(6, 0.1, 0.1);
  KeepOutTube tube;
  tube.polyline_world = {Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(0, 0, 1)};  // a vertical piece
  tube.radius_m = 3.15;
  EXPECT_FALSE(tube.segmentOutside(a, b));
  EXPECT_NEAR(tube.distance(a, b), 0.1, 1e-12);
  const auto straight = search.search(a, b, 0.3, 0.3, 6.0, 200'000);
  ASSERT_TRUE(straight.has_value()) << straight.reason();
  EXPECT_EQ(straight.value().size(), 2u);
  const auto around = search.search(a, b, 0.3, 0.3, 6.0, 200'000, nullptr, tube);
  ASSERT_TRUE(around.has_value()) << around.reason();
  const auto& path = around.value();
  EXPECT_EQ(path.front(), a);
  EXPECT_EQ(path.back(), b);
  ASSERT_GE(path.size(), 3u);
  for (std::size_t i = 0; i + 1 < path.size(); ++i) {
    EXPECT_GE(tube.distance(path[i], path[i + 1]), tube.radius_m)
        << "piece " << i << ": " << path[i].transpose() << " → " << path[i + 1].transpose();
  }
  // A tube the search cannot get around inside its box: no path (not one through the tube).
  KeepOutTube wall = tube;
  wall.radius_m = 5.5;
  const auto blocked =
      search.search(Eigen::Vector3d(-5.9, 0, 0), Eigen::Vector3d(5.9, 0, 0), 0.3, 0.3, 0.4, 200'000, nullptr, wall);
  EXPECT_FALSE(blocked.has_value());
}

TEST(SegmentGeometryTest, SegmentDistancesAgainstBruteForce) {
  // Exact segment–segment distance against dense sampling of both segments, in every
  // configuration (crossing, parallel, collinear, skew, degenerate to points).
  const std::vector<std::array<Eigen::Vector3d, 4>> cases = {
      {Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(0, -1, 1), Eigen::Vector3d(0, 1, 1)},
      {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(1, 1, 0), Eigen::Vector3d(3, 1, 0)},
      {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(3, 0, 0)},
      {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, -1, 2), Eigen::Vector3d(-2, 3, 0.5)},
      {Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(1, 1, 1), Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 0, 0)},
      {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(5, 0, 0), Eigen::Vector3d(6, 1, 0), Eigen::Vector3d(9, 4, 0)},
  };
  for (std::size_t n = 0; n < cases.size(); ++n) {
    const auto& [a, b, c, d] = cases[n];
    double brute = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 400; ++i) {
      for (int j = 0; j <= 400; ++j) {
        brute = std::min(brute, ((a + (b - a) * (i / 400.0)) - (c + (d - c) * (j / 400.0))).norm());
      }
    }
    const double exact = segmentSegmentDistance(a, b, c, d);
    EXPECT_LE(exact, brute + 1e-12) << "case " << n;
    EXPECT_NEAR(exact, brute, 0.02) << "case " << n;
    EXPECT_NEAR(segmentSegmentDistance(c, d, a, b), exact, 1e-12) << "case " << n << " (symmetric)";
  }
}

TEST(SegmentGeometryTest, SimplifiedPolylineDropsStandingAndStraightPoints) {
  const std::vector<Eigen::Vector3d> standing(41, Eigen::Vector3d(1, 2, 3));
  const auto still = simplifyPolyline(standing, 0.05);
  ASSERT_EQ(still.size(), 2u);
  EXPECT_EQ(still.front(), still.back());
  std::vector<Eigen::Vector3d> walk, turn;
  for (int k = 0; k <= 40; ++k) walk.push_back(Eigen::Vector3d(0.22 * k, 0, 1));
  EXPECT_EQ(simplifyPolyline(walk, 0.05).size(), 2u);
  // Walks 20 steps east, then 20 north: three points, the corner kept; every input point within
  // the tolerance of the simplified polyline.
  for (int k = 0; k <= 20; ++k) turn.push_back(Eigen::Vector3d(0.2 * k, 0, 1));
  for (int k = 1; k <= 20; ++k) turn.push_back(Eigen::Vector3d(4, 0.2 * k, 1));
  KeepOutTube tube;
  tube.polyline_world = simplifyPolyline(turn, 0.05);
  EXPECT_EQ(tube.polyline_world.size(), 3u);
  for (const auto& p : turn) EXPECT_LE(tube.distance(p), 0.05 + 1e-12) << p.transpose();
  // Standing, then walking away: the start and the end, the standing points merged.
  std::vector<Eigen::Vector3d> start_walk(10, Eigen::Vector3d::Zero());
  for (int k = 1; k <= 10; ++k) start_walk.push_back(Eigen::Vector3d(0, 0.2 * k, 0));
  EXPECT_EQ(simplifyPolyline(start_walk, 0.05).size(), 2u);
  // A single point is a polyline too: the distances are to that point.
  tube.polyline_world = {Eigen::Vector3d(0, 0, 0)};
  EXPECT_DOUBLE_EQ(tube.distance(Eigen::Vector3d(3, 4, 0)), 5.0);
  EXPECT_DOUBLE_EQ(tube.distance(Eigen::Vector3d(-1, 2, 0), Eigen::Vector3d(1, 2, 0)), 2.0);
}

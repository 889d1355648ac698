// Corridor properties (conventions.md, code style 7): each polytope contains its segment, excludes
// every obstacle point of the whole map (not only the local ones), keeps its achieved
// clearance, overlaps its neighbour at the shared waypoint; correct with no obstacles, with
// obstacles touching the segment, and in 3-D. 100 random worlds with fixed seeds.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/planning/corridor_builder.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"

using namespace gesture_formation::planning;

namespace {

double bruteDistance(const std::vector<Eigen::Vector3d>& pts, const Eigen::Vector3d& p) {
  double d = std::numeric_limits<double>::infinity();
  for (const auto& q : pts) d = std::min(d, (q - p).norm());
  return d;
}

/// Every guarantee of corridor_builder.hpp, checked against all obstacle points `pts`.
void checkCorridor(const SegmentCorridor& c, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                   const std::vector<Eigen::Vector3d>& pts, const CorridorConfig& cfg, std::mt19937& rng) {
  const Polytope& P = c.polytope;
  ASSERT_EQ(P.A.rows(), P.b.size());
  ASSERT_GE(P.rows(), 6);
  for (int r = 0; r < P.rows(); ++r) ASSERT_NEAR(P.A.row(r).norm(), 1.0, 1e-12) << "row " << r;
  EXPECT_EQ(c.seed_begin_world, p0);
  EXPECT_EQ(c.seed_end_world, p1);
  // Contains the segment, both ends with the margin.
  EXPECT_LE(P.violation(p0), -cfg.seed_margin_m + 1e-12);
  EXPECT_LE(P.violation(p1), -cfg.seed_margin_m + 1e-12);
  for (int i = 0; i <= 20; ++i) EXPECT_LE(P.violation(p0 + (p1 - p0) * (i / 20.0)), 0.0);
  // The last six rows are the local box: x_i ≤ max_i, −x_i ≤ −min_i on every axis, and the
  // box holds the segment with the configured margin on every side.
  for (int i = 0; i < 3; ++i) {
    const int r = P.rows() - 6 + 2 * i;
    EXPECT_EQ(P.A.row(r), Eigen::RowVector3d::Unit(i));
    EXPECT_EQ(P.A.row(r + 1), -Eigen::RowVector3d::Unit(i));
    EXPECT_NEAR(P.b(r), std::max(p0(i), p1(i)) + cfg.local_box_margin_m(i), 1e-12);
    EXPECT_NEAR(-P.b(r + 1), std::min(p0(i), p1(i)) - cfg.local_box_margin_m(i), 1e-12);
  }
  // Excludes every obstacle point of the world, by at least min_exclusion_m.
  for (const auto& o : pts) ASSERT_GE(P.violation(o), cfg.min_exclusion_m - 1e-12) << o.transpose();
  // Achieved clearance: no point of the polytope is closer than it to an obstacle point.
  EXPECT_LE(c.clearance_m, cfg.clearance_m);
  EXPECT_GE(c.clearance_m, std::min(cfg.clearance_m, cfg.min_exclusion_m) - 1e-12);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  int accepted = 0;
  for (int trial = 0; trial < 400 && accepted < 60; ++trial) {
    const Eigen::Vector3d x = c.local_box.min_world +
                              (c.local_box.max_world - c.local_box.min_world).cwiseProduct(Eigen::Vector3d(U(rng), U(rng), U(rng)));
    if (!P.contains(x)) continue;
    ++accepted;
    ASSERT_GE(bruteDistance(pts, x), c.clearance_m - 1e-9) << "inside point " << x.transpose();
  }
}

/// A random world of boxes, cylinders and thin wires in [-8, 8]³ at 0.2 m.
OccupancyMap randomWorld(std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-7.0, 7.0), S(0.2, 3.0), A(-M_PI, M_PI), R(0.05, 1.0);
  PrimitiveSet set;
  const int n = std::uniform_int_distribution<int>(3, 12)(rng);
  for (int i = 0; i < n; ++i) {
    switch (i % 3) {
      case 0: {
        OrientedBox b;
        b.center_world = Eigen::Vector3d(U(rng), U(rng), U(rng));
        b.size_m = Eigen::Vector3d(S(rng), S(rng), S(rng));
        b.R_world_box = rotationFromRpy(A(rng), A(rng), A(rng));
        set.boxes.push_back(b);
        break;
      }
      case 1:
        set.cylinders.push_back(Cylinder{Eigen::Vector3d(U(rng), U(rng), U(rng)), Eigen::Vector3d(U(rng), U(rng), U(rng)), R(rng)});
        break;
      default:  // a 2 cm wire
        set.cylinders.push_back(Cylinder{Eigen::Vector3d(U(rng), U(rng), U(rng)), Eigen::Vector3d(U(rng), U(rng), U(rng)), 0.01});
    }
  }
  MapConfig m;
  m.resolution_m = 0.2;
  m.bounds = Aabb{Eigen::Vector3d::Constant(-8.0), Eigen::Vector3d::Constant(8.0)};
  const bool ground = std::uniform_int_distribution<int>(0, 1)(rng) == 1;
  return OccupancyMap::fromPrimitives(m, set, GroundSpec{ground, -6.0});
}

}  // namespace

class CorridorRandomWorlds : public ::testing::TestWithParam<int> {};

TEST_P(CorridorRandomWorlds, ContainsSegmentExcludesEveryPointOverlapsNeighbours) {
  const int first_seed = GetParam();
  std::size_t segments = 0;  // the checks are checkCorridor's and the neighbours' EXPECTs
  for (int seed = first_seed; seed < first_seed + 10; ++seed) {
    std::mt19937 rng(static_cast<unsigned>(seed));
    const OccupancyMap map = randomWorld(rng);
    CorridorConfig cfg;
    cfg.clearance_m = std::array<double, 3>{0.0, 0.25, 0.6}[static_cast<std::size_t>(seed % 3)];
    cfg.local_box_margin_m = Eigen::Vector3d(1.0 + seed % 2, 2.0, 1.5);
    const CorridorBuilder builder(cfg);
    ASSERT_TRUE(builder.configError().empty());
    std::uniform_real_distribution<double> W(-6.5, 6.5);
    std::vector<Eigen::Vector3d> path;
    for (int i = 0; i < 5; ++i) path.emplace_back(W(rng), W(rng), W(rng));
    const auto corridors = builder.buildPath(path, map);
    ASSERT_TRUE(corridors) << "seed " << seed << ": " << corridors.reason();
    ASSERT_EQ(corridors->size(), path.size() - 1);
    for (std::size_t i = 0; i < corridors->size(); ++i) {
      SCOPED_TRACE("seed " + std::to_string(seed) + " segment " + std::to_string(i));
      checkCorridor((*corridors)[i], path[i], path[i + 1], map.occupiedCenters(), cfg, rng);
      if (i > 0) {  // neighbours share their waypoint strictly inside both
        EXPECT_LT((*corridors)[i - 1].polytope.violation(path[i]), 0.0);
        EXPECT_LT((*corridors)[i].polytope.violation(path[i]), 0.0);
      }
      ++segments;
    }
  }
  EXPECT_EQ(segments, 40u);
}

INSTANTIATE_TEST_SUITE_P(HundredWorlds, CorridorRandomWorlds, ::testing::Range(1, 101, 10));

TEST(CorridorBuilderTest, EmptyWorldGivesTheLocalBoxInEveryDirection) {
  CorridorConfig cfg;
  cfg.local_box_margin_m = Eigen::Vector3d(1.0, 2.0, 3.0);
  const CorridorBuilder builder(cfg);
  const PointCloudObstacles none({});
  std::mt19937 rng(5);
  // Segments in all 8 octant directions plus axis-aligned ones: min/max on every axis.
  for (int sx = -1; sx <= 1; ++sx) {
    for (int sy = -1; sy <= 1; ++sy) {
      for (int sz = -1; sz <= 1; ++sz) {
        if (sx == 0 && sy == 0 && sz == 0) continue;
        const Eigen::Vector3d p0(1, -2, 3), p1 = p0 + Eigen::Vector3d(4 * sx, 3 * sy, 2 * sz);
        const auto c = builder.buildSegment(p0, p1, none);
        ASSERT_TRUE(c) << c.reason();
        EXPECT_EQ(c->polytope.rows(), 6);
        EXPECT_EQ(c->clearance_m, cfg.clearance_m);
        EXPECT_TRUE(std::isinf(c->segment_clearance_m));
        checkCorridor(*c, p0, p1, {}, cfg, rng);
      }
    }
  }
}

TEST(CorridorBuilderTest, ObstacleTouchingTheSegmentIsReportedNotContained) {
  const CorridorBuilder builder(CorridorConfig{});
  const Eigen::Vector3d p0(0, 0, 0), p1(4, 0, 0);
  for (const Eigen::Vector3d& o : {Eigen::Vector3d(2, 0, 0), Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(4, 0, 0),
                                   Eigen::Vector3d(1, 1e-4, 0), Eigen::Vector3d(4.0005, 0, 0)}) {
    const auto c = builder.buildSegment(p0, p1, PointCloudObstacles({o}));
    ASSERT_FALSE(c) << o.transpose();
    EXPECT_NE(c.reason().find("obstacle point"), std::string::npos) << c.reason();
  }
  const auto path = builder.buildPath({Eigen::Vector3d(-3, 0, 0), p0, p1}, PointCloudObstacles({Eigen::Vector3d(2, 0, 0)}));
  ASSERT_FALSE(path);
  EXPECT_NE(path.reason().find("segment 1 (waypoints 1 → 2)"), std::string::npos) << path.reason();
  EXPECT_FALSE(builder.buildSegment(p0, p0, PointCloudObstacles({})));
  EXPECT_FALSE(builder.buildSegment(p0, Eigen::Vector3d(std::nan(""), 0, 0), PointCloudObstacles({})));
  EXPECT_FALSE(builder.buildPath({p0}, PointCloudObstacles({})));
}

TEST(CorridorBuilderTest, ObstaclesCloserThanTheClearanceShrinkTheCorridor) {
  CorridorConfig cfg;
  cfg.clearance_m = 0.5;
  const CorridorBuilder builder(cfg);
  const Eigen::Vector3d p0(0, 0, 0), p1(4, 0, 0);
  std::mt19937 rng(8);
  // A sleeve of points 1 cm around the segment, and points just past both ends on its axis.
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i <= 40; ++i) {
    for (int k = 0; k < 8; ++k) {
      const double a = k * M_PI / 4;
      pts.emplace_back(0.1 * i, 0.01 * std::cos(a), 0.01 * std::sin(a));
    }
  }
  pts.emplace_back(-0.01, 0, 0);
  pts.emplace_back(4.01, 0, 0);
  pts.emplace_back(4.02, 0.003, 0);
  const auto c = builder.buildSegment(p0, p1, PointCloudObstacles(pts));
  ASSERT_TRUE(c) << c.reason();
  EXPECT_LT(c->clearance_m, 0.01);
  EXPECT_NEAR(c->segment_clearance_m, 0.01, 1e-12);
  checkCorridor(*c, p0, p1, pts, cfg, rng);
}

TEST(CorridorBuilderTest, ThreeDimensionalSlotBetweenFloorCeilingAndWalls) {
  // A horizontal slot: floor z = −0.6, ceiling z = +0.8, walls y = ±1.5 (points every 0.2 m).
  std::vector<Eigen::Vector3d> pts;
  for (double x = -4; x <= 8; x += 0.2) {
    for (double y = -3; y <= 3; y += 0.2) {
      pts.emplace_back(x, y, -0.6);
      pts.emplace_back(x, y, 0.8);
    }
    for (double z = -0.6; z <= 0.8; z += 0.2) {
      pts.emplace_back(x, -1.5, z);
      pts.emplace_back(x, 1.5, z);
    }
  }
  CorridorConfig cfg;
  cfg.clearance_m = 0.2;
  const CorridorBuilder builder(cfg);
  std::mt19937 rng(9);
  for (const Eigen::Vector3d& p1 : {Eigen::Vector3d(4, 0, 0), Eigen::Vector3d(4, 0.6, 0.3), Eigen::Vector3d(3, -1, -0.2)}) {
    const Eigen::Vector3d p0(0, 0, 0);
    const auto c = builder.buildSegment(p0, p1, PointCloudObstacles(pts));
    ASSERT_TRUE(c) << c.reason();
    checkCorridor(*c, p0, p1, pts, cfg, rng);
    EXPECT_NEAR(c->clearance_m, 0.2, 1e-12);
    // The corridor fills the slot: its vertical and lateral extent at the middle is
    // bounded by the slot minus the clearance, and it reaches most of it.
    const Eigen::Vector3d mid = 0.5 * (p0 + p1);
    auto reach = [&](const Eigen::Vector3d& dir) {
      double lo = 0.0, hi = 5.0;
      for (int i = 0; i < 60; ++i) ((c->polytope.contains(mid + 0.5 * (lo + hi) * dir)) ? lo : hi) = 0.5 * (lo + hi);
      return lo;
    };
    EXPECT_LE(mid.z() + reach(Eigen::Vector3d::UnitZ()), 0.8 - 0.2 + 1e-9);
    EXPECT_GE(mid.z() + reach(Eigen::Vector3d::UnitZ()), 0.3);
    EXPECT_GE(mid.z() - reach(-Eigen::Vector3d::UnitZ()), -0.6 + 0.2 - 1e-9);
    EXPECT_LE(mid.z() - reach(-Eigen::Vector3d::UnitZ()), -0.2);
    EXPECT_LE(mid.y() + reach(Eigen::Vector3d::UnitY()), 1.5 - 0.2 + 1e-9);
    EXPECT_GE(mid.y() + reach(Eigen::Vector3d::UnitY()), 0.9);
  }
}

TEST(CorridorBuilderTest, InvalidConfigIsNamed) {
  CorridorConfig cfg;
  cfg.clearance_m = -1.0;
  cfg.local_box_margin_m.y() = 0.0;
  cfg.seed_margin_m = 0.0;
  EXPECT_EQ(cfg.validate().size(), 3u);
  const CorridorBuilder builder(cfg);
  EXPECT_NE(builder.configError().find("clearance_m"), std::string::npos);
  EXPECT_NE(builder.configError().find("local_box_margin_m[1]"), std::string::npos);
  EXPECT_EQ(builder.config().clearance_m, CorridorConfig{}.clearance_m);
}

// One range per setting (issue 34): `gfctl corridor --clearance` is read with
// corridorConfigFields()' range, and validate() refuses exactly what it refuses.
TEST(CorridorBuilderTest, ValidateAndTheClearanceOptionAgreeOnBoundaries) {
  const gesture_formation::common::Range& range = *corridorConfigFields().rangeOf("clearance_m");
  for (const double clearance : {0.0, 3.0, -1e-9, std::nan("")}) {
    CorridorConfig c;
    c.clearance_m = clearance;
    EXPECT_EQ(c.validate().empty(), range.contains(clearance)) << clearance;
  }
  EXPECT_TRUE(range.contains(0.0));
  EXPECT_FALSE(range.contains(-1e-9));
}

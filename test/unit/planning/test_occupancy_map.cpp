// Rasterisation against analytic geometry, box queries, .bt round trip, clearance queries.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "gesture_formation/planning/catenary.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/worker_obstacle.hpp"

using namespace gesture_formation::planning;

namespace {

MapConfig mapConfig(double res = 0.2) {
  MapConfig m;
  m.resolution_m = res;
  m.bounds = Aabb{Eigen::Vector3d(-6, -6, -6), Eigen::Vector3d(6, 6, 6)};
  return m;
}

/// Volume of the shape dilated by r (Steiner formula for convex bodies: V + S r + M r² + 4/3 π r³).
double dilatedVolume(double V, double S, double M, double r) { return V + S * r + M * r * r + 4.0 / 3.0 * M_PI * r * r * r; }

/// Checks the rasterisation rule and its consequences for one solid set:
/// (a) every occupied voxel centre lies within ρ of a solid, every free one farther;
/// hence every point of a solid lies in an occupied voxel (its voxel's centre is within ρ);
/// (b) the occupied volume lies between V and the volume dilated by √3·res, and within half a
///     voxel of surface thickness of the volume dilated by ρ.
void checkRaster(const OccupancyMap& map, const PrimitiveSet& solids, double V, double S, double M) {
  const double res = map.resolution(), rho = OccupancyMap::rasterInflation(res);
  std::size_t occupied = 0;
  const VoxelIndex o = map.gridOrigin(), n = map.gridSize();
  for (int k = 0; k < n.z(); ++k) {
    for (int j = 0; j < n.y(); ++j) {
      for (int i = 0; i < n.x(); ++i) {
        const VoxelIndex v = o + VoxelIndex(i, j, k);
        const double d = solids.distance(map.centerOf(v));
        if (map.isOccupied(v)) {
          ++occupied;
          ASSERT_LE(d, rho + 1e-9);
        } else {
          ASSERT_GT(d, rho - 1e-9);
        }
      }
    }
  }
  EXPECT_EQ(occupied, map.occupiedCount());
  const double vol = occupied * res * res * res;
  EXPECT_GE(vol, V);
  EXPECT_LE(vol, dilatedVolume(V, S, M, std::sqrt(3.0) * res));
  const double expected = dilatedVolume(V, S, M, rho);
  const double area = S + 2.0 * M * rho + 4.0 * M_PI * rho * rho;  // surface of the dilated body
  EXPECT_NEAR(vol, expected, 0.5 * res * area) << "occupied " << vol << " m³, expected ≈ " << expected;
}

}  // namespace

TEST(OccupancyMapTest, BoxMatchesAnalyticVolume) {
  OrientedBox b;
  b.center_world = Eigen::Vector3d(0.37, -0.41, 0.13);
  b.size_m = Eigen::Vector3d(3.0, 2.0, 1.5);
  b.R_world_box = rotationFromRpy(0.3, -0.2, 0.7);
  PrimitiveSet set;
  set.boxes.push_back(b);
  const OccupancyMap map = OccupancyMap::fromPrimitives(mapConfig(), set, GroundSpec{});
  const double a = 3.0, bb = 2.0, c = 1.5;
  // Mean-curvature term of a box: π (a + b + c).
  checkRaster(map, set, a * bb * c, 2 * (a * bb + bb * c + a * c), M_PI * (a + bb + c));
}

TEST(OccupancyMapTest, CylinderMatchesAnalyticVolume) {
  PrimitiveSet set;
  set.cylinders.push_back(Cylinder{Eigen::Vector3d(-2.1, 0.3, -3.0), Eigen::Vector3d(1.7, -0.5, 3.2), 0.8});
  const OccupancyMap map = OccupancyMap::fromPrimitives(mapConfig(), set, GroundSpec{});
  const double r = 0.8, h = (set.cylinders[0].p1_world - set.cylinders[0].p0_world).norm();
  // Cylinder: S = 2πr h + 2πr², M = π (h + π r).
  checkRaster(map, set, M_PI * r * r * h, 2 * M_PI * r * h + 2 * M_PI * r * r, M_PI * (h + M_PI * r));
}

TEST(OccupancyMapTest, ThinCatenaryOccupiesAnUnbrokenChain) {
  ConductorSpec spec;
  spec.from_world = Eigen::Vector3d(-5.5, -3.3, 4.0);
  spec.to_world = Eigen::Vector3d(5.2, 4.1, 3.0);
  spec.sag_m = 2.0;
  spec.radius_m = 0.015;
  const auto set = conductorPrimitives(spec);
  ASSERT_TRUE(set);
  const OccupancyMap map = OccupancyMap::fromPrimitives(mapConfig(), *set, GroundSpec{});
  const auto cat = Catenary::fit(spec.from_world, spec.to_world, spec.sag_m);
  // Every point of the line lies in an occupied voxel.
  for (int i = 0; i <= 2000; ++i) ASSERT_TRUE(map.isOccupied(cat->point(i / 2000.0))) << i;
  // A thin line (r → 0) occupies ≈ the tube of radius ρ around it: π ρ² L (+ end caps).
  const double rho = OccupancyMap::rasterInflation(0.2), L = cat->length();
  const double vol = map.occupiedCount() * 0.008;
  EXPECT_NEAR(vol, M_PI * rho * rho * L, 0.25 * M_PI * rho * rho * L);
}

TEST(OccupancyMapTest, GroundAndBoxQueriesAndBtRoundTrip) {
  PrimitiveSet set;
  set.cylinders.push_back(Cylinder{Eigen::Vector3d(1, 1, -1), Eigen::Vector3d(1, 1, 4), 0.5});
  GroundSpec ground{true, -1.0};
  const OccupancyMap map = OccupancyMap::fromPrimitives(mapConfig(), set, ground);
  EXPECT_TRUE(map.isOccupied(Eigen::Vector3d(-5.9, -5.9, -5.9)));
  EXPECT_TRUE(map.isOccupied(Eigen::Vector3d(3, -3, -1.05)));
  EXPECT_FALSE(map.isOccupied(Eigen::Vector3d(3, -3, -0.5)));
  // pointsInBox equals a brute-force filter, for boxes straddling the grid's edges too.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(-8, 8);
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::Vector3d a(U(rng), U(rng), U(rng)), b(U(rng), U(rng), U(rng));
    const Aabb box{a.cwiseMin(b), a.cwiseMax(b)};
    std::vector<Eigen::Vector3d> fast;
    map.pointsInBox(box, fast);
    std::size_t brute = 0;
    for (const auto& p : map.occupiedCenters()) brute += box.contains(p);
    EXPECT_EQ(fast.size(), brute);
    for (const auto& p : fast) EXPECT_TRUE(box.contains(p));
  }
  // .bt round trip gives the same voxels.
  const std::string path = ::testing::TempDir() + "gf_planning_roundtrip.bt";
  ASSERT_EQ(map.writeBinary(path), "");
  const auto back = OccupancyMap::fromOctomapFile(mapConfig(), path);
  ASSERT_TRUE(back) << back.reason();
  EXPECT_EQ(back->occupiedCount(), map.occupiedCount());
  EXPECT_EQ(back->denseGrid(), map.denseGrid());
  EXPECT_EQ(back->droppedVoxels(), 0u);
  EXPECT_FALSE(OccupancyMap::fromOctomapFile(mapConfig(0.1), path));  // resolution mismatch
  EXPECT_FALSE(OccupancyMap::fromOctomapFile(mapConfig(), path + ".missing"));
  std::remove(path.c_str());
}

TEST(DistanceFieldTest, ExactAtVoxelCentresAndALowerBoundElsewhere) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-5, 5);
  PrimitiveSet set;
  for (int i = 0; i < 6; ++i) {
    set.cylinders.push_back(Cylinder{Eigen::Vector3d(U(rng), U(rng), U(rng)), Eigen::Vector3d(U(rng), U(rng), U(rng)), 0.3});
  }
  const OccupancyMap map = OccupancyMap::fromPrimitives(mapConfig(), set, GroundSpec{});
  const DistanceField field(map);
  const FclClearance fcl(map);
  auto brute = [&](const Eigen::Vector3d& p) {
    double d = std::numeric_limits<double>::infinity();
    for (const auto& c : map.occupiedCenters()) d = std::min(d, (c - p).norm());
    return d;
  };
  const double res = map.resolution();
  std::uniform_int_distribution<int> I(0, map.gridSize().x() - 1);
  for (int trial = 0; trial < 300; ++trial) {
    const VoxelIndex v = map.gridOrigin() + VoxelIndex(I(rng), I(rng), I(rng));
    const Eigen::Vector3d c = map.centerOf(v);
    EXPECT_NEAR(field.clearance(c), brute(c), 1e-5);
    const Eigen::Vector3d p(U(rng) * 1.4, U(rng) * 1.4, U(rng) * 1.4);  // also outside the grid
    const double truth = brute(p), lower = field.clearance(p);
    EXPECT_LE(lower, truth + 1e-5);
    // Inside the grid the bound is tight to √3·res; outside it only stays a lower bound.
    if (map.gridBounds().contains(p)) {
      EXPECT_GE(lower, truth - std::sqrt(3.0) * res - 1e-5);
    }
    // FCL measures to the voxel cube: at most the centre distance, at least that − ρ.
    const double f = fcl.clearance(p);
    EXPECT_LE(f, truth + 1e-4);
    EXPECT_GE(f, truth - OccupancyMap::rasterInflation(res) - 1e-4);
    if (f > 0.31) {
      EXPECT_FALSE(fcl.collides(p, 0.3));
    } else if (f < 0.29) {
      EXPECT_TRUE(fcl.collides(p, 0.3));
    }
  }
  const OccupancyMap empty = OccupancyMap::fromPrimitives(mapConfig(), PrimitiveSet{}, GroundSpec{});
  EXPECT_TRUE(std::isinf(DistanceField(empty).clearance(Eigen::Vector3d::Zero())));
  EXPECT_TRUE(std::isinf(FclClearance(empty).clearance(Eigen::Vector3d::Zero())));
}

// The field stores squared voxel distances in 2 bytes: exact below 256 voxels (every voxel centre
// of a 300-voxel-long grid with one obstacle at its end against the exact √n·res), and beyond it
// the distance of 256 voxels (√65535·res: a lower bound of the truth), never more.
TEST(DistanceFieldTest, ExactBelowTheCapAndTheCapsLowerBoundBeyond) {
  MapConfig m;
  m.resolution_m = 0.2;
  m.bounds = Aabb{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(60, 1, 1)};  // 300 x 5 x 5 voxels
  PrimitiveSet set;
  OrientedBox slab;  // the first x slab of voxels
  slab.center_world = Eigen::Vector3d(0.1, 0.5, 0.5);
  slab.size_m = Eigen::Vector3d(0.1, 1.0, 1.0);
  set.boxes.push_back(slab);
  const OccupancyMap map = OccupancyMap::fromPrimitives(m, set, GroundSpec{});
  ASSERT_EQ(map.gridSize().x(), 300);
  const DistanceField field(map);
  const auto centres = map.occupiedCenters();
  ASSERT_FALSE(centres.empty());
  const float cap = static_cast<float>(std::sqrt(65535.0) * m.resolution_m);
  int capped = 0, exact = 0;
  for (int i = 0; i < map.gridSize().x(); ++i) {
    const Eigen::Vector3d c = map.centerOf(map.gridOrigin() + VoxelIndex(i, 2, 2));
    double truth = std::numeric_limits<double>::infinity();
    for (const auto& o : centres) truth = std::min(truth, (o - c).norm());
    const float stored = field.atLocal(i, 2, 2);
    if (truth < cap) {
      EXPECT_NEAR(stored, truth, 1e-5) << "voxel " << i;
      ++exact;
    } else {
      EXPECT_EQ(stored, cap) << "voxel " << i << ", truth " << truth;
      EXPECT_LE(stored, truth);
      ++capped;
    }
  }
  EXPECT_GT(exact, 200);
  EXPECT_GT(capped, 30);
}

TEST(WorkerObstacleTest, CylinderAtThePredictedPosition) {
  WorkerObstacleConfig cfg;
  EXPECT_TRUE(cfg.validate().empty());
  const WorkerObstacle w(cfg, Eigen::Vector3d(1, 2, 1), Eigen::Vector3d(0.5, 0, 0), 10.0);
  EXPECT_NEAR((w.positionAt(12.0) - Eigen::Vector3d(2, 2, 1)).norm(), 0.0, 1e-12);
  EXPECT_DOUBLE_EQ(w.clearance(Eigen::Vector3d(2, 2, 1.5), 12.0), 0.0);           // inside
  EXPECT_NEAR(w.clearance(Eigen::Vector3d(4, 2, 1), 12.0), 1.5, 1e-12);            // beside
  EXPECT_NEAR(w.clearance(Eigen::Vector3d(2, 2, 3), 12.0), 1.0, 1e-12);            // above the head
  EXPECT_NEAR(w.clearance(Eigen::Vector3d(4, 2, 1), 10.0), 2.5, 1e-12);            // earlier
  WorkerObstacleConfig bad;
  bad.radius_m = 0.0;
  bad.height_m = std::nan("");
  EXPECT_EQ(bad.validate().size(), 2u);
}

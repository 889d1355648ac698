// In-place map updates (OccupancyMap::setOccupancy) and the incremental distance field
// (DistanceField::update): after random changes the map's indexes agree with its dense grid and
// the updated field equals a full rebuild bit for bit; the truncated field is min(exact, range)
// and, on a small map, the brute-force distance to the nearest occupied centre.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <tuple>

#include <octomap/OcTree.h>

#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"

using namespace gesture_formation::planning;

namespace {

MapConfig smallMap() {
  MapConfig m;
  m.resolution_m = 0.2;
  m.bounds = Aabb{Eigen::Vector3d(-1.0, -2.0, 0.0), Eigen::Vector3d(5.0, 3.0, 4.0)};  // 30 × 25 × 20 voxels
  return m;
}

/// A map with a few random boxes (so the occupancy has surfaces, not only noise).
OccupancyMap randomMap(std::mt19937& rng) {
  PrimitiveSet solids;
  std::uniform_real_distribution<double> x(-1.0, 5.0), y(-2.0, 3.0), z(0.0, 4.0), s(0.1, 1.2);
  for (int b = 0; b < 5; ++b) {
    OrientedBox box;
    box.center_world = Eigen::Vector3d(x(rng), y(rng), z(rng));
    box.size_m = Eigen::Vector3d(s(rng), s(rng), s(rng));
    solids.boxes.push_back(box);
  }
  return OccupancyMap::fromPrimitives(smallMap(), solids, GroundSpec{});
}

using Key = std::tuple<int, int, int>;
Key keyOf(const VoxelIndex& v) { return {v.x(), v.y(), v.z()}; }

std::set<Key> occupiedFromGrid(const OccupancyMap& map) {
  std::set<Key> out;
  const VoxelIndex n = map.gridSize();
  for (int k = 0; k < n.z(); ++k) {
    for (int j = 0; j < n.y(); ++j) {
      for (int i = 0; i < n.x(); ++i) {
        const VoxelIndex v = map.gridOrigin() + VoxelIndex(i, j, k);
        if (map.isOccupied(v)) out.insert(keyOf(v));
      }
    }
  }
  return out;
}

/// The block index (pointsInBox, occupiedCenters) and the OctoMap agree with the dense grid.
void expectIndexesMatchGrid(const OccupancyMap& map) {
  const std::set<Key> grid = occupiedFromGrid(map);
  EXPECT_EQ(map.occupiedCount(), grid.size());
  std::set<Key> centres;
  for (const auto& c : map.occupiedCenters()) centres.insert(keyOf(map.voxelOf(c)));
  EXPECT_EQ(centres, grid);
  std::vector<Eigen::Vector3d> in_box;
  map.pointsInBox(map.gridBounds(), in_box);
  EXPECT_EQ(in_box.size(), grid.size());
  std::set<Key> tree;
  const octomap::OcTree& t = *map.octree();
  for (auto it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it) {
    if (!t.isNodeOccupied(*it)) continue;
    const int n = static_cast<int>(std::lround(it.getSize() / map.resolution()));
    const Eigen::Vector3d corner =
        Eigen::Vector3d(it.getX(), it.getY(), it.getZ()) - Eigen::Vector3d::Constant(0.5 * it.getSize());
    for (int k = 0; k < n; ++k) {
      for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
          tree.insert(keyOf(map.voxelOf(corner + (Eigen::Vector3d(i, j, k).array() + 0.5).matrix() * map.resolution())));
        }
      }
    }
  }
  EXPECT_EQ(tree, grid);
}

/// Every value of `a` equals the one of `b` (bit for bit, floats compared with ==).
void expectFieldsEqual(const DistanceField& a, const DistanceField& b, const VoxelIndex& size, const std::string& what) {
  int mismatches = 0;
  for (int k = 0; k < size.z(); ++k) {
    for (int j = 0; j < size.y(); ++j) {
      for (int i = 0; i < size.x(); ++i) {
        if (a.atLocal(i, j, k) != b.atLocal(i, j, k) && ++mismatches <= 5) {
          ADD_FAILURE() << what << ": voxel (" << i << ", " << j << ", " << k << ") " << a.atLocal(i, j, k)
                        << " != full rebuild " << b.atLocal(i, j, k);
        }
      }
    }
  }
  EXPECT_EQ(mismatches, 0) << what;
}

/// Random changes: a cluster (a small box set or cleared) and scattered single voxels.
std::vector<VoxelChange> randomChanges(const OccupancyMap& map, std::mt19937& rng) {
  std::vector<VoxelChange> changes;
  const VoxelIndex n = map.gridSize(), o = map.gridOrigin();
  std::uniform_int_distribution<int> ix(0, n.x() - 1), iy(0, n.y() - 1), iz(0, n.z() - 1), len(1, 4), coin(0, 1);
  const VoxelIndex c(ix(rng), iy(rng), iz(rng));
  const VoxelIndex e(len(rng), len(rng), len(rng));
  const bool fill = coin(rng) == 1;
  for (int k = 0; k < e.z(); ++k) {
    for (int j = 0; j < e.y(); ++j) {
      for (int i = 0; i < e.x(); ++i) changes.push_back({o + c + VoxelIndex(i, j, k), fill});
    }
  }
  std::uniform_int_distribution<int> count(0, 6);
  for (int s = count(rng); s > 0; --s) changes.push_back({o + VoxelIndex(ix(rng), iy(rng), iz(rng)), coin(rng) == 1});
  // and some that change nothing (already in that state) or lie outside the grid
  changes.push_back({o - VoxelIndex::Ones(), true});
  return changes;
}

}  // namespace

TEST(DistanceFieldUpdateTest, TruncatedFieldIsTheExactFieldCappedAtItsRange) {
  std::mt19937 rng(11);
  const OccupancyMap map = randomMap(rng);
  const DistanceField exact(map);
  const auto capped = DistanceField::truncated(map, 0.9);
  ASSERT_TRUE(capped) << capped.reason();
  const VoxelIndex n = map.gridSize();
  for (int k = 0; k < n.z(); ++k) {
    for (int j = 0; j < n.y(); ++j) {
      for (int i = 0; i < n.x(); ++i) {
        ASSERT_EQ(capped->atLocal(i, j, k), std::min(exact.atLocal(i, j, k), 0.9f)) << i << " " << j << " " << k;
      }
    }
  }
}

TEST(DistanceFieldUpdateTest, TruncatedFieldMatchesBruteForceDistancesToOccupiedCentres) {
  std::mt19937 rng(5);
  const OccupancyMap map = randomMap(rng);
  const auto field = DistanceField::truncated(map, 1.3);
  ASSERT_TRUE(field) << field.reason();
  const std::vector<Eigen::Vector3d> centres = map.occupiedCenters();
  ASSERT_GT(centres.size(), 10u);
  const VoxelIndex n = map.gridSize();
  for (int k = 0; k < n.z(); k += 3) {
    for (int j = 0; j < n.y(); j += 2) {
      for (int i = 0; i < n.x(); ++i) {
        const Eigen::Vector3d p = map.centerOf(map.gridOrigin() + VoxelIndex(i, j, k));
        double d = 1.3;
        for (const auto& c : centres) d = std::min(d, (c - p).norm());
        ASSERT_NEAR(field->atLocal(i, j, k), d, 1e-5) << "voxel " << i << " " << j << " " << k;
      }
    }
  }
}

TEST(DistanceFieldUpdateTest, BadRangeIsNamed) {
  std::mt19937 rng(1);
  const OccupancyMap map = randomMap(rng);
  for (double bad : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()}) {
    const auto field = DistanceField::truncated(map, bad);
    ASSERT_FALSE(field);
    EXPECT_NE(field.reason().find("max_distance_m"), std::string::npos) << field.reason();
  }
}

TEST(DistanceFieldUpdateTest, SetOccupancyKeepsEveryIndexConsistentAndReportsRealChanges) {
  std::mt19937 rng(3);
  OccupancyMap map = randomMap(rng);
  expectIndexesMatchGrid(map);
  for (int round = 0; round < 15; ++round) {
    const std::set<Key> before = occupiedFromGrid(map);
    const std::vector<VoxelChange> changes = randomChanges(map, rng);
    const std::vector<VoxelIndex> changed = map.setOccupancy(changes);
    const std::set<Key> after = occupiedFromGrid(map);
    std::set<Key> expected_changed;
    for (const auto& k : before) {
      if (!after.count(k)) expected_changed.insert(k);
    }
    for (const auto& k : after) {
      if (!before.count(k)) expected_changed.insert(k);
    }
    std::set<Key> reported;
    for (const auto& v : changed) reported.insert(keyOf(v));
    EXPECT_EQ(reported, expected_changed) << "round " << round;
    EXPECT_EQ(reported.size(), changed.size()) << "a voxel reported twice";
    expectIndexesMatchGrid(map);
  }
}

TEST(DistanceFieldUpdateTest, CopyOwnsItsOwnOctomap) {
  std::mt19937 rng(4);
  const OccupancyMap original = randomMap(rng);
  OccupancyMap copy = original;
  const std::size_t before = original.octree()->size();
  const VoxelIndex v = copy.gridOrigin() + VoxelIndex(1, 1, 1);
  copy.setOccupancy({VoxelChange{v, !copy.isOccupied(v)}});
  EXPECT_NE(copy.octree().get(), original.octree().get());
  EXPECT_EQ(original.octree()->size(), before);
  expectIndexesMatchGrid(original);
  expectIndexesMatchGrid(copy);
}

class IncrementalFieldTest : public ::testing::TestWithParam<std::tuple<int, double>> {};

TEST_P(IncrementalFieldTest, EqualsAFullRebuildAfterRandomUpdates) {
  const auto [seed, range_m] = GetParam();
  std::mt19937 rng(static_cast<unsigned>(seed));
  OccupancyMap map = randomMap(rng);
  auto field = DistanceField::truncated(map, range_m);
  ASSERT_TRUE(field) << field.reason();
  for (int round = 0; round < 12; ++round) {
    const std::vector<VoxelIndex> changed = map.setOccupancy(randomChanges(map, rng));
    const auto stats = field->update(map, changed);
    ASSERT_TRUE(stats) << stats.reason();
    EXPECT_EQ(stats->changed_voxels, static_cast<int>(changed.size()));
    const auto rebuilt = DistanceField::truncated(map, range_m);
    expectFieldsEqual(*field, *rebuilt, map.gridSize(), "seed " + std::to_string(seed) + " round " + std::to_string(round));
  }
}

INSTANTIATE_TEST_SUITE_P(SeedsAndRanges, IncrementalFieldTest,
                         ::testing::Combine(::testing::Values(1, 2, 3, 4), ::testing::Values(0.5, 0.9, 2.0)));

TEST(DistanceFieldUpdateTest, UntruncatedFieldUpdatesByAFullRebuild) {
  std::mt19937 rng(9);
  OccupancyMap map = randomMap(rng);
  DistanceField field(map);
  for (int round = 0; round < 3; ++round) {
    const std::vector<VoxelIndex> changed = map.setOccupancy(randomChanges(map, rng));
    const auto stats = field.update(map, changed);
    ASSERT_TRUE(stats) << stats.reason();
    expectFieldsEqual(field, DistanceField(map), map.gridSize(), "untruncated round " + std::to_string(round));
  }
}

TEST(DistanceFieldUpdateTest, ClearingEveryVoxelGivesTheRangeEverywhere) {
  std::mt19937 rng(2);
  OccupancyMap map = randomMap(rng);
  auto field = DistanceField::truncated(map, 0.7);
  ASSERT_TRUE(field);
  std::vector<VoxelChange> clear;
  for (const auto& c : map.occupiedCenters()) clear.push_back({map.voxelOf(c), false});
  const auto changed = map.setOccupancy(clear);
  ASSERT_TRUE(field->update(map, changed));
  EXPECT_EQ(map.occupiedCount(), 0u);
  const VoxelIndex n = map.gridSize();
  for (int k = 0; k < n.z(); ++k) {
    for (int j = 0; j < n.y(); ++j) {
      for (int i = 0; i < n.x(); ++i) ASSERT_EQ(field->atLocal(i, j, k), 0.7f);
    }
  }
  EXPECT_DOUBLE_EQ(field->clearance(Eigen::Vector3d(1.1, 0.1, 1.1)), 0.7f);  // a voxel centre
}

TEST(DistanceFieldUpdateTest, UpdateWithAnotherGridFailsAndKeepsTheField) {
  std::mt19937 rng(6);
  const OccupancyMap map = randomMap(rng);
  auto field = DistanceField::truncated(map, 0.9);
  ASSERT_TRUE(field);
  MapConfig other = smallMap();
  other.bounds.max_world.x() += 1.0;
  const OccupancyMap wrong = OccupancyMap::fromPrimitives(other, PrimitiveSet{}, GroundSpec{});
  const auto stats = field->update(wrong, {wrong.gridOrigin()});
  ASSERT_FALSE(stats);
  EXPECT_NE(stats.reason().find("grid"), std::string::npos);
  expectFieldsEqual(*field, *DistanceField::truncated(map, 0.9), map.gridSize(), "after a refused update");
}

// Online mapping against an analytic scene: depth images of an axis-aligned box rendered in the
// test (ray–box intersection per pixel), integrated by LiveMap. The box's front-face voxels become
// occupied and nothing else; after the box moves the old voxels are cleared and the new ones
// occupied; the field stays equal to a full rebuild; prior voxels stay; bad settings and frames are
// named.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include <octomap/OcTree.h>

#include "gesture_formation/comm/map_update.hpp"
#include "gesture_formation/mapping/depth_points.hpp"
#include "gesture_formation/mapping/live_map.hpp"
#include "gesture_formation/mapping/mapping_config.hpp"

using namespace gesture_formation;
using mapping::DepthFrame;
using mapping::LiveMap;
using mapping::MappingConfig;
using planning::VoxelIndex;

namespace {

constexpr double kRes = 0.2;

planning::MapConfig grid() {
  planning::MapConfig m;
  m.resolution_m = kRes;
  m.bounds = planning::Aabb{Eigen::Vector3d(-1.0, -6.0, -1.0), Eigen::Vector3d(14.0, 6.0, 5.0)};
  return m;
}

/// A camera at p looking along world +x (optical z = +x, x = −y, y = −z), 640×480, f = 400 px.
DepthFrame cameraAt(const Eigen::Vector3d& p_world) {
  DepthFrame f;
  f.intrinsics = mapping::PinholeIntrinsics{400.0, 400.0, 319.5, 239.5};
  Eigen::Matrix3d R;
  R.col(0) = Eigen::Vector3d(0, -1, 0);
  R.col(1) = Eigen::Vector3d(0, 0, -1);
  R.col(2) = Eigen::Vector3d(1, 0, 0);
  f.T_world_camera.linear() = R;
  f.T_world_camera.translation() = p_world;
  f.depth_m = cv::Mat(480, 640, CV_32FC1);
  return f;
}

/// Renders the depth of an axis-aligned box [lo, hi] (slab method per pixel ray): the optical z of
/// the first intersection, +Inf where the ray misses it (nothing within the sensor's range).
void renderBox(DepthFrame& f, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  const Eigen::Matrix3d R = f.T_world_camera.linear();
  const Eigen::Vector3d o = f.T_world_camera.translation();
  for (int v = 0; v < f.depth_m.rows; ++v) {
    for (int u = 0; u < f.depth_m.cols; ++u) {
      // direction with optical z = 1, so the ray parameter is the depth
      const Eigen::Vector3d d = R * Eigen::Vector3d((u - f.intrinsics.cx) / f.intrinsics.fx,
                                                    (v - f.intrinsics.cy) / f.intrinsics.fy, 1.0);
      double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
      for (int i = 0; i < 3; ++i) {
        if (std::abs(d(i)) < 1e-12) {
          if (o(i) < lo(i) || o(i) > hi(i)) t0 = std::numeric_limits<double>::infinity();
          continue;
        }
        double a = (lo(i) - o(i)) / d(i), b = (hi(i) - o(i)) / d(i);
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
      }
      f.depth_m.at<float>(v, u) = t0 <= t1 ? static_cast<float>(t0) : std::numeric_limits<float>::infinity();
    }
  }
}

using Key = std::tuple<int, int, int>;

/// Voxels of the face x = x_face, y ∈ [y0, y1], z ∈ [z0, z1] (edges mid-voxel, so unambiguous).
std::set<Key> faceVoxels(double x_face, double y0, double y1, double z0, double z1) {
  std::set<Key> out;
  const int i = static_cast<int>(std::floor(x_face / kRes));
  for (int j = static_cast<int>(std::floor(y0 / kRes)); j <= static_cast<int>(std::floor(y1 / kRes)); ++j) {
    for (int k = static_cast<int>(std::floor(z0 / kRes)); k <= static_cast<int>(std::floor(z1 / kRes)); ++k) {
      out.insert({i, j, k});
    }
  }
  return out;
}

std::set<Key> occupiedVoxels(const planning::OccupancyMap& map) {
  std::set<Key> out;
  for (const auto& c : map.occupiedCenters()) {
    const VoxelIndex v = map.voxelOf(c);
    out.insert({v.x(), v.y(), v.z()});
  }
  return out;
}

Eigen::Vector3d centre(const Key& k) {
  return (Eigen::Vector3d(std::get<0>(k), std::get<1>(k), std::get<2>(k)).array() + 0.5).matrix() * kRes;
}

/// The live field equals a full rebuild over the live map.
void expectFieldIsFullRebuild(const LiveMap& live) {
  const auto rebuilt = planning::DistanceField::truncated(*live.map(), live.config().field_range_m);
  ASSERT_TRUE(rebuilt);
  const VoxelIndex n = live.map()->gridSize();
  int mismatches = 0;
  for (int k = 0; k < n.z(); ++k) {
    for (int j = 0; j < n.y(); ++j) {
      for (int i = 0; i < n.x(); ++i) mismatches += live.field()->atLocal(i, j, k) != rebuilt->atLocal(i, j, k);
    }
  }
  EXPECT_EQ(mismatches, 0);
}

std::unique_ptr<LiveMap> makeLiveMap(std::shared_ptr<const planning::OccupancyMap> prior = nullptr,
                                     double refresh_share = 0.0) {
  MappingConfig config;
  config.share.refresh_share = refresh_share;  // 0: updates carry new changes only (MapShareRefreshTest: resends)
  auto live = LiveMap::create(config, grid(), std::move(prior));
  EXPECT_TRUE(live) << live.reason();
  return live ? std::move(*live) : nullptr;
}

const Eigen::Vector3d kCamera(0.0, 0.0, 1.5);
// Box A: front face x = 4.7, y ∈ [−0.9, 0.9], z ∈ [0.9, 2.1] (every edge in the middle of a voxel).
const Eigen::Vector3d kBoxALo(4.7, -0.9, 0.9), kBoxAHi(5.5, 0.9, 2.1);
// Box B: the same box moved 2.6 m to the left (+y): y ∈ [1.7, 3.5].
const Eigen::Vector3d kBoxBLo(4.7, 1.7, 0.9), kBoxBHi(5.5, 3.5, 2.1);

}  // namespace

TEST(LiveMapTest, DepthImageOfABoxOccupiesExactlyItsFrontFaceVoxels) {
  auto live = makeLiveMap();
  ASSERT_TRUE(live);
  DepthFrame frame = cameraAt(kCamera);
  renderBox(frame, kBoxALo, kBoxAHi);
  const auto update = live->integrate(frame);
  ASSERT_TRUE(update) << update.reason();
  const std::set<Key> face = faceVoxels(4.7, -0.9, 0.9, 0.9, 2.1);
  ASSERT_EQ(face.size(), 70u);  // 10 × 7 voxels
  EXPECT_EQ(occupiedVoxels(*live->map()), face);  // the camera sees neither the sides nor the top
  EXPECT_EQ(update->map_changes, 70);
  EXPECT_EQ(update->pixels, 160 * 120);  // stride 4
  EXPECT_GT(update->free_rays, 0);       // the +Inf pixels around the box
  for (const auto& k : face) EXPECT_EQ(live->observed(centre(k)), mapping::Observed::kOccupied);
  // in front of the face: observed free; behind it: never seen
  EXPECT_EQ(live->observed(Eigen::Vector3d(2.5, 0.1, 1.5)), mapping::Observed::kFree);
  EXPECT_EQ(live->observed(Eigen::Vector3d(6.1, 0.1, 1.5)), mapping::Observed::kUnknown);
  // the field: distance to the nearest face voxel centre, capped at the range
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(3.7, 0.1, 1.5), Eigen::Vector3d(4.1, 1.9, 2.7), Eigen::Vector3d(0.5, 0.1, 1.5)}) {
    double d = live->config().field_range_m;
    for (const auto& k : face) d = std::min(d, (centre(k) - live->map()->centerOf(live->map()->voxelOf(p))).norm());
    EXPECT_NEAR(live->field()->clearance(live->map()->centerOf(live->map()->voxelOf(p))), d, 1e-5) << p.transpose();
  }
  expectFieldIsFullRebuild(*live);
}

TEST(LiveMapTest, MovedBoxIsClearedWhereItWasAndOccupiedWhereItIs) {
  auto live = makeLiveMap();
  ASSERT_TRUE(live);
  DepthFrame a = cameraAt(kCamera);
  renderBox(a, kBoxALo, kBoxAHi);
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(live->integrate(a));  // saturated log-odds
  const std::set<Key> old_face = faceVoxels(4.7, -0.9, 0.9, 0.9, 2.1);
  ASSERT_EQ(occupiedVoxels(*live->map()), old_face);

  DepthFrame b = cameraAt(kCamera);
  renderBox(b, kBoxBLo, kBoxBHi);
  int changes = 0;
  for (int i = 0; i < 10; ++i) {
    const auto update = live->integrate(b);
    ASSERT_TRUE(update) << update.reason();
    changes += update->map_changes;
    expectFieldIsFullRebuild(*live);
  }
  const std::set<Key> occupied = occupiedVoxels(*live->map());
  for (const auto& k : old_face) {
    EXPECT_EQ(occupied.count(k), 0u) << "old voxel " << centre(k).transpose() << " still occupied";
    EXPECT_EQ(live->observed(centre(k)), mapping::Observed::kFree);
  }
  const std::set<Key> new_face = faceVoxels(4.7, 1.7, 3.5, 0.9, 2.1);
  for (const auto& k : new_face) EXPECT_EQ(occupied.count(k), 1u) << "new voxel " << centre(k).transpose() << " free";
  // Besides the new front face only the side face y = 1.7 (which the camera at y = 0 sees) is occupied.
  for (const auto& k : occupied) {
    const Eigen::Vector3d c = centre(k);
    const bool front = new_face.count(k) > 0;
    const bool side = std::abs(c.y() - 1.7) < kRes && c.x() > 4.6 && c.x() < 5.6 && c.z() > 0.8 && c.z() < 2.2;
    EXPECT_TRUE(front || side) << "unexpected occupied voxel " << c.transpose();
  }
  EXPECT_EQ(changes, 70 + static_cast<int>(occupied.size()));  // every old voxel freed once, every new one set once
}

TEST(LiveMapTest, PriorVoxelsStayOccupiedWhenRaysPassThem) {
  planning::PrimitiveSet solids;
  planning::OrientedBox post;  // a thin post between the camera and the box, on the rays to it
  post.center_world = Eigen::Vector3d(3.1, 0.1, 1.5);
  post.size_m = Eigen::Vector3d(0.05, 0.05, 0.05);
  solids.boxes.push_back(post);
  auto prior = std::make_shared<planning::OccupancyMap>(
      planning::OccupancyMap::fromPrimitives(grid(), solids, planning::GroundSpec{}));
  const std::size_t prior_count = prior->occupiedCount();
  ASSERT_GT(prior_count, 0u);
  auto live = makeLiveMap(prior);
  ASSERT_TRUE(live);
  DepthFrame a = cameraAt(kCamera);
  renderBox(a, kBoxALo, kBoxAHi);  // the rendered world has no post: its rays pass through it
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(live->integrate(a));
  EXPECT_EQ(live->observed(post.center_world), mapping::Observed::kFree);
  EXPECT_TRUE(live->map()->isOccupied(post.center_world));
  EXPECT_EQ(live->map()->occupiedCount(), prior_count + 70);
  EXPECT_EQ(prior->occupiedCount(), prior_count);  // the prior itself is untouched
  expectFieldIsFullRebuild(*live);
}

TEST(LiveMapTest, RayCastingEqualsOctomapInsertPointCloud) {
  // LiveMap casts its rays itself (a dense mark instead of OctoMap's hash sets, clamped voxels
  // skipped): the observed tree must equal OctoMap's insertPointCloud of the same rays, also
  // outside the grid (the rays here leave it above, below and to the sides).
  auto live = makeLiveMap();
  ASSERT_TRUE(live);
  const MappingConfig& c = live->config();
  octomap::OcTree reference(kRes);
  reference.setProbHit(c.prob_hit);
  reference.setProbMiss(c.prob_miss);
  reference.setClampingThresMin(c.clamping_min);
  reference.setClampingThresMax(c.clamping_max);
  const std::vector<std::pair<Eigen::Vector3d, bool>> shots = {
      {kCamera, false}, {kCamera, false}, {Eigen::Vector3d(0.5, -1.0, 2.0), true},
      {Eigen::Vector3d(1.0, 0.7, 1.2), false}, {kCamera, true}, {kCamera, true}, {kCamera, true}};
  std::vector<std::size_t> nodes;
  for (const auto& [p, moved] : shots) {
    DepthFrame f = cameraAt(p);
    renderBox(f, moved ? kBoxBLo : kBoxALo, moved ? kBoxBHi : kBoxAHi);
    const auto update = live->integrate(f);
    ASSERT_TRUE(update);
    nodes.push_back(update->tree_nodes);
    const auto points = mapping::depthToPoints(f, c, 2.0 * kRes);
    ASSERT_TRUE(points);
    // the same rays: the first return per end voxel, returns within range before the others
    octomap::Pointcloud cloud;
    octomap::KeySet ends;
    for (const auto* list : {&points->hits_world, &points->free_rays_world}) {
      for (const auto& q : *list) {
        const octomap::point3d e(static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z()));
        if (ends.insert(reference.coordToKey(e)).second) cloud.push_back(e);
      }
    }
    reference.insertPointCloud(cloud, octomap::point3d(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())),
                               c.max_range_m);
  }
  const octomap::OcTree& tree = live->observedTree();
  int compared = 0, known = 0;
  for (int k = -40; k < 40; ++k) {
    for (int j = -45; j < 45; ++j) {
      for (int i = -10; i < 75; ++i) {
        const octomap::point3d q(static_cast<float>((i + 0.5) * kRes), static_cast<float>((j + 0.5) * kRes),
                                 static_cast<float>((k + 0.5) * kRes));
        const octomap::OcTreeNode* a = tree.search(q);
        const octomap::OcTreeNode* b = reference.search(q);
        ++compared;
        ASSERT_EQ(a == nullptr, b == nullptr) << "voxel " << i << " " << j << " " << k;
        if (a != nullptr) {
          ++known;
          ASSERT_EQ(a->getLogOdds(), b->getLogOdds()) << "voxel " << i << " " << j << " " << k;
        }
      }
    }
  }
  EXPECT_GT(known, 20000) << "of " << compared;
  // the tree was pruned during the sequence (updates are lazy, pruning in batches) and updated after
  bool pruned = false;
  for (std::size_t i = 1; i + 1 < nodes.size(); ++i) pruned = pruned || nodes[i] < nodes[i - 1];
  EXPECT_TRUE(pruned) << ::testing::PrintToString(nodes);
}

// OctoMap's keys hold voxel indices -32768 .. 32767 per axis: a grid beyond them is refused, named.
TEST(LiveMapTest, AGridBeyondOctomapsKeysIsRefused) {
  planning::MapConfig far = grid();
  far.resolution_m = 0.05;
  far.bounds = planning::Aabb{Eigen::Vector3d(1640.0, -0.5, 0.0), Eigen::Vector3d(1642.0, 0.5, 1.0)};  // x index 32800 .. 32839
  const auto live = LiveMap::create(MappingConfig{}, far);
  ASSERT_FALSE(live);
  EXPECT_NE(live.reason().find("leave OctoMap's key range"), std::string::npos) << live.reason();
  far.bounds = planning::Aabb{Eigen::Vector3d(1630.0, -0.5, 0.0), Eigen::Vector3d(1632.0, 0.5, 1.0)};  // 32600 .. 32639: fits
  EXPECT_TRUE(LiveMap::create(MappingConfig{}, far)) << "a grid inside the keys";
}

TEST(LiveMapTest, PriorOnAnotherGridIsRefused) {
  planning::MapConfig other = grid();
  other.resolution_m = 0.25;
  auto prior = std::make_shared<planning::OccupancyMap>(
      planning::OccupancyMap::fromPrimitives(other, planning::PrimitiveSet{}, planning::GroundSpec{}));
  const auto live = LiveMap::create(MappingConfig{}, grid(), prior);
  ASSERT_FALSE(live);
  EXPECT_NE(live.reason().find("prior map"), std::string::npos) << live.reason();
}

TEST(DepthPointsTest, DecimationRangesAndRep118ValuesAreSortedOut) {
  DepthFrame f = cameraAt(Eigen::Vector3d::Zero());
  f.depth_m = cv::Mat(4, 8, CV_32FC1, cv::Scalar(5.0f));
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  // row 0 (used with stride 2: columns 0, 2, 4, 6): NaN, +Inf, −Inf, 0
  f.depth_m.at<float>(0, 0) = nan;
  f.depth_m.at<float>(0, 2) = inf;
  f.depth_m.at<float>(0, 4) = -inf;
  f.depth_m.at<float>(0, 6) = 0.0f;
  // row 2: near, in range, beyond max range, in range
  f.depth_m.at<float>(2, 0) = 0.1f;
  f.depth_m.at<float>(2, 4) = 25.0f;
  f.depth_m.at<float>(1, 1) = nan;  // not on the decimated grid: never looked at
  MappingConfig c;
  c.pixel_stride = 2;
  c.min_range_m = 0.3;
  c.max_range_m = 10.0;
  const auto pts = mapping::depthToPoints(f, c, 0.4);
  ASSERT_TRUE(pts) << pts.reason();
  EXPECT_EQ(pts->pixels, 8);
  EXPECT_EQ(pts->skipped_invalid, 3);
  EXPECT_EQ(pts->skipped_near, 1);
  EXPECT_EQ(pts->free_rays_world.size(), 2u);
  EXPECT_EQ(pts->hits_world.size(), 2u);
  for (const auto& p : pts->free_rays_world) EXPECT_NEAR(p.norm(), 10.4, 1e-9);
  // pixel (2, 2) at depth 5: optical ((2 − 319.5)/400·5, (2 − 239.5)/400·5, 5) → world (5, 3.97, 2.97)
  EXPECT_NEAR(pts->hits_world[0].x(), 5.0, 1e-9);
  EXPECT_NEAR(pts->hits_world[0].y(), (319.5 - 2.0) / 400.0 * 5.0, 1e-9);
  EXPECT_NEAR(pts->hits_world[0].z(), (239.5 - 2.0) / 400.0 * 5.0, 1e-9);
}

TEST(DepthPointsTest, BadFramesAreNamed) {
  MappingConfig c;
  DepthFrame f = cameraAt(Eigen::Vector3d::Zero());
  f.depth_m = cv::Mat(4, 4, CV_16UC1, cv::Scalar(1000));
  auto r = mapping::depthToPoints(f, c, 0.4);
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find("depth_m must be CV_32FC1"), std::string::npos) << r.reason();
  f = cameraAt(Eigen::Vector3d::Zero());
  f.intrinsics.fx = 0.0;
  r = mapping::depthToPoints(f, c, 0.4);
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find("intrinsics.fx must be finite and > 0, got 0"), std::string::npos) << r.reason();
  f = cameraAt(Eigen::Vector3d::Zero());
  f.intrinsics.cy = std::nan("");
  r = mapping::depthToPoints(f, c, 0.4);
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find("intrinsics.cy"), std::string::npos) << r.reason();
  f = cameraAt(Eigen::Vector3d::Zero());
  f.T_world_camera.linear() *= 2.0;
  r = mapping::depthToPoints(f, c, 0.4);
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find("T_world_camera"), std::string::npos) << r.reason();
  f = cameraAt(Eigen::Vector3d::Zero());
  f.depth_m = cv::Mat();
  r = mapping::depthToPoints(f, c, 0.4);
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find("depth_m is empty"), std::string::npos);
  // a bad frame changes nothing in the live map
  auto live = makeLiveMap();
  ASSERT_TRUE(live);
  const auto refused = live->integrate(f);
  ASSERT_FALSE(refused);
  EXPECT_EQ(live->map()->occupiedCount(), 0u);
}

TEST(MappingConfigTest, DefaultsAreValid) { EXPECT_TRUE(MappingConfig{}.validate().empty()); }

TEST(MappingConfigTest, EveryBadFieldIsNamedWithItsValue) {
  MappingConfig c;
  c.pixel_stride = 0;
  c.min_range_m = -0.5;
  c.prob_hit = 0.4;
  c.prob_miss = 0.6;
  c.clamping_min = 0.0;
  c.clamping_max = 1.5;
  c.field_range_m = std::nan("");
  const auto problems = c.validate("mapping.");
  const auto has = [&](const std::string& text) {
    for (const auto& p : problems) {
      if (p.find(text) != std::string::npos) return true;
    }
    return false;
  };
  EXPECT_TRUE(has("mapping.depth.pixel_stride must be in [1, 64], got 0")) << ::testing::PrintToString(problems);
  EXPECT_TRUE(has("mapping.depth.min_range_m must be > 0, got -0.5")) << ::testing::PrintToString(problems);
  EXPECT_TRUE(has("mapping.octomap.prob_hit")) << ::testing::PrintToString(problems);
  EXPECT_TRUE(has("got 0.4")) << ::testing::PrintToString(problems);
  EXPECT_TRUE(has("mapping.octomap.prob_miss")) << ::testing::PrintToString(problems);
  EXPECT_TRUE(has("mapping.octomap.clamping_min")) << ::testing::PrintToString(problems);
  EXPECT_TRUE(has("mapping.octomap.clamping_max")) << ::testing::PrintToString(problems);
  EXPECT_TRUE(has("mapping.field.range_m")) << ::testing::PrintToString(problems);
  EXPECT_EQ(problems.size(), 7u) << ::testing::PrintToString(problems);

  MappingConfig ranges;
  ranges.min_range_m = 5.0;
  ranges.max_range_m = 4.0;
  const auto rule = ranges.validate();
  ASSERT_EQ(rule.size(), 1u);
  EXPECT_NE(rule[0].find("depth.max_range_m must be > depth.min_range_m, got 4"), std::string::npos) << rule[0];

  const auto live = LiveMap::create(c, grid());
  ASSERT_FALSE(live);
  EXPECT_NE(live.reason().find("depth.pixel_stride"), std::string::npos) << live.reason();
}

TEST(MappingConfigTest, YamlReaderUsesTheSameRanges) {
  auto reader = common::ConfigReader::fromString(
      "mapping: {depth: {pixel_stride: 8, max_range_m: 6.0}, field: {range_m: -1}}", "test.yaml",
      common::ConfigReader::MissingKeys::kUseDefaults);
  const MappingConfig c = mapping::readMappingConfig(reader, "mapping.");
  EXPECT_EQ(c.pixel_stride, 8);
  EXPECT_EQ(c.max_range_m, 6.0);
  ASSERT_FALSE(reader.ok());
  ASSERT_EQ(reader.problems().size(), 1u);
  EXPECT_EQ(reader.problems()[0].key, "mapping.field.range_m");
}

TEST(LiveMapTest, FrameMarksWhatItsRaysCrossOrEndInAsSeen) {
  auto live = makeLiveMap();
  ASSERT_TRUE(live);
  const planning::SeenSpace& seen = *live->seen();
  EXPECT_EQ(seen.seenCount(), 0u);
  DepthFrame a = cameraAt(kCamera);
  renderBox(a, kBoxALo, kBoxAHi);
  ASSERT_TRUE(live->integrate(a));
  EXPECT_GT(seen.seenCount(), 1000u);
  EXPECT_TRUE(seen.seen(kCamera + Eigen::Vector3d(2.0, 0.0, 0.0)));  // on the rays to the box
  EXPECT_TRUE(seen.seen(Eigen::Vector3d(4.7 + 0.05, 0.0, 1.5)));      // the box's front face (hit)
  EXPECT_FALSE(seen.seen(Eigen::Vector3d(6.5, 0.0, 1.5)));            // behind the box
  EXPECT_FALSE(seen.seen(kCamera - Eigen::Vector3d(1.0, 0.0, 0.0)));  // behind the camera
  EXPECT_FALSE(seen.seen(kCamera + Eigen::Vector3d(1.0, 3.0, 0.0)));  // outside the field of view
}

TEST(MappingConfigTest, SeenRuleKeysAreRangeChecked) {
  MappingConfig c;
  c.seen.margin_m = 0.0;
  c.seen.horizon_s = -1.0;
  const auto problems = c.validate();
  ASSERT_EQ(problems.size(), 2u) << ::testing::PrintToString(problems);
  EXPECT_NE(problems[0].find("seen.margin_m must be > 0, got 0"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("seen.horizon_s must be > 0, got -1"), std::string::npos) << problems[1];
}

// ---- Sharing (docs/mapping.md §8): one UAV's changes into another's live map ----------------

namespace {

DepthFrame boxFrame(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double stamp_s) {
  DepthFrame f = cameraAt(kCamera);
  renderBox(f, lo, hi);
  f.stamp_s = stamp_s;
  return f;
}

DepthFrame emptyFrame(double stamp_s) {  // nothing in view: every ray free up to the maximum range
  DepthFrame f = cameraAt(kCamera);
  f.depth_m.setTo(std::numeric_limits<float>::infinity());
  f.stamp_s = stamp_s;
  return f;
}

std::set<Key> keysToVoxels(const std::vector<mapping::VoxelKey>& keys) {
  std::set<Key> out;
  for (const auto& k : keys) out.insert({int(k[0]) - 32768, int(k[1]) - 32768, int(k[2]) - 32768});
  return out;
}

}  // namespace

TEST(MapShareTest, OneUavsBoxEntersTheOtherMapAndFieldButNotItsSeenSpace) {
  auto a = makeLiveMap(), b = makeLiveMap();
  ASSERT_TRUE(a && b);
  ASSERT_TRUE(a->integrate(boxFrame(kBoxALo, kBoxAHi, 1.0)));
  const std::set<Key> face = faceVoxels(4.7, -0.9, 0.9, 0.9, 2.1);
  EXPECT_EQ(a->pendingChanges(), face.size());  // created-free voxels are not changes to tell
  mapping::OutgoingStats stats;
  const mapping::MapDelta delta = a->takeChanges(kCamera, 1.0, 10000, 5.0, &stats);
  EXPECT_EQ(stats.sent, 70);
  EXPECT_EQ(stats.deferred + stats.dropped, 0);
  EXPECT_DOUBLE_EQ(delta.stamp_s, 1.0);
  EXPECT_DOUBLE_EQ(delta.resolution_m, kRes);
  EXPECT_EQ(keysToVoxels(delta.occupied), face);
  EXPECT_TRUE(delta.free.empty());
  EXPECT_EQ(a->pendingChanges(), 0u);
  EXPECT_EQ(a->takeChanges(kCamera, 1.1, 10000, 5.0).size(), 0u);  // sent once

  const std::size_t seen_before = b->seen()->seenCount();
  const auto merged = b->merge(delta);
  ASSERT_TRUE(merged) << merged.reason();
  EXPECT_EQ(merged->map_changes, 70);
  EXPECT_EQ(occupiedVoxels(*b->map()), face);
  expectFieldIsFullRebuild(*b);
  EXPECT_LT(b->field()->clearance(Eigen::Vector3d(4.5, 0.1, 1.5)), 0.3);
  EXPECT_EQ(b->seen()->seenCount(), seen_before);  // received voxels do not count as seen
  EXPECT_EQ(b->observed(centre(*face.begin())), mapping::Observed::kUnknown);  // nor as its own observation
  EXPECT_EQ(b->pendingChanges(), 0u);  // and are never passed on
}

TEST(MapShareTest, TheNewerWordWinsPerVoxel) {
  auto a = makeLiveMap(), b = makeLiveMap();
  ASSERT_TRUE(a && b);
  ASSERT_TRUE(a->integrate(boxFrame(kBoxALo, kBoxAHi, 2.0)));
  const mapping::MapDelta delta = a->takeChanges(kCamera, 2.0, 10000, 5.0);
  // B looked at the same place at 3 s and saw nothing there: its own, newer observation wins.
  ASSERT_TRUE(b->integrate(emptyFrame(3.0)));
  auto merged = b->merge(delta);
  ASSERT_TRUE(merged) << merged.reason();
  EXPECT_EQ(merged->superseded, 70);
  EXPECT_TRUE(occupiedVoxels(*b->map()).empty());
  // A fresh B receives the box (stamp 2 s), then sees the place empty at 3 s: the box is cleared.
  auto c = makeLiveMap();
  ASSERT_TRUE(c->merge(delta));
  ASSERT_EQ(occupiedVoxels(*c->map()).size(), 70u);
  ASSERT_TRUE(c->integrate(emptyFrame(3.0)));
  EXPECT_TRUE(occupiedVoxels(*c->map()).empty());
  expectFieldIsFullRebuild(*c);
  // An older update of the same voxels (stamp 1 s) changes nothing now.
  mapping::MapDelta old = delta;
  old.stamp_s = 1.0;
  merged = c->merge(old);
  ASSERT_TRUE(merged);
  EXPECT_EQ(merged->superseded, 70);
  EXPECT_TRUE(occupiedVoxels(*c->map()).empty());
}

TEST(MapShareTest, AMovedBoxIsClearedOnTheReceiverToo) {
  auto a = makeLiveMap(), b = makeLiveMap();
  ASSERT_TRUE(a && b);
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(a->integrate(boxFrame(kBoxALo, kBoxAHi, 0.1 * i)));
  ASSERT_TRUE(b->merge(a->takeChanges(kCamera, 1.0, 10000, 5.0)));
  const std::set<Key> old_face = faceVoxels(4.7, -0.9, 0.9, 0.9, 2.1);
  ASSERT_EQ(occupiedVoxels(*b->map()), old_face);
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(a->integrate(boxFrame(kBoxBLo, kBoxBHi, 2.0 + 0.1 * i)));
  const mapping::MapDelta moved = a->takeChanges(kCamera, 3.0, 10000, 5.0);
  EXPECT_EQ(keysToVoxels(moved.free), old_face);  // the old face, sent free
  ASSERT_TRUE(b->merge(moved));
  EXPECT_EQ(occupiedVoxels(*b->map()), occupiedVoxels(*a->map()));
  expectFieldIsFullRebuild(*b);
}

TEST(MapShareTest, TheBudgetSendsTheNearestFirstAndDropsWhatWaitedTooLong) {
  auto a = makeLiveMap();
  ASSERT_TRUE(a);
  ASSERT_TRUE(a->integrate(boxFrame(kBoxALo, kBoxAHi, 1.0)));
  const Eigen::Vector3d sender(4.0, -3.0, 1.5);  // nearest to the box's −y edge
  mapping::OutgoingStats stats;
  const mapping::MapDelta first = a->takeChanges(sender, 1.0, 20, 5.0, &stats);
  EXPECT_EQ(stats.sent, 20);
  EXPECT_EQ(stats.deferred, 50);
  double farthest_sent = 0.0;
  for (const auto& k : keysToVoxels(first.occupied)) farthest_sent = std::max(farthest_sent, (centre(k) - sender).norm());
  const mapping::MapDelta second = a->takeChanges(sender, 1.2, 20, 5.0, &stats);
  EXPECT_EQ(stats.sent, 20);
  for (const auto& k : keysToVoxels(second.occupied)) EXPECT_GE((centre(k) - sender).norm(), farthest_sent - 1e-9);
  // 30 left; 10 s later they are older than max_age_s: dropped, counted, never sent.
  const mapping::MapDelta late = a->takeChanges(sender, 11.0, 20, 5.0, &stats);
  EXPECT_EQ(late.size(), 0u);
  EXPECT_EQ(stats.dropped, 30);
  EXPECT_EQ(a->pendingChanges(), 0u);
}

// share.refresh_share: voxels sent as occupied are resent round robin in the room an update leaves,
// so a receiver that lost an update gets the obstacle again.
TEST(MapShareRefreshTest, ALostUpdateReachesTheReceiverWithTheResends) {
  auto a = makeLiveMap(nullptr, 0.5), b = makeLiveMap();
  ASSERT_TRUE(a && b);
  ASSERT_TRUE(a->integrate(boxFrame(kBoxALo, kBoxAHi, 1.0)));
  const std::set<Key> face = faceVoxels(4.7, -0.9, 0.9, 0.9, 2.1);
  mapping::OutgoingStats stats;
  const mapping::MapDelta lost = a->takeChanges(kCamera, 1.0, 40, 5.0, &stats);  // never reaches b
  EXPECT_EQ(stats.sent, 40);
  EXPECT_EQ(stats.refreshed, 0);  // nothing was sent before
  EXPECT_EQ(stats.deferred, 30);
  // Next update: the 30 deferred changes, then resends in the 10 left (at most 0.5 x 40 = 20).
  const mapping::MapDelta second = a->takeChanges(kCamera, 1.5, 40, 5.0, &stats);
  EXPECT_EQ(stats.sent, 40);
  EXPECT_EQ(stats.refreshed, 10);
  ASSERT_TRUE(b->merge(second));
  // Nothing new: each update resends 20 of the 70 announced, round robin; after a pass b holds the whole face.
  std::set<Key> resent;
  for (int i = 0; i < 4; ++i) {
    const mapping::MapDelta d = a->takeChanges(kCamera, 2.0 + i, 40, 5.0, &stats);
    EXPECT_EQ(stats.refreshed, 20);
    EXPECT_TRUE(d.free.empty());
    for (const auto& k : keysToVoxels(d.occupied)) resent.insert(k);
    ASSERT_TRUE(b->merge(d));
  }
  EXPECT_EQ(resent, face);
  EXPECT_EQ(occupiedVoxels(*b->map()), face);
  expectFieldIsFullRebuild(*b);
  // The box moves away: its old face is sent free once and never resent; the new face is.
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(a->integrate(boxFrame(kBoxBLo, kBoxBHi, 10.0 + 0.1 * i)));
  for (int i = 0; i < 8; ++i) ASSERT_TRUE(b->merge(a->takeChanges(kCamera, 12.0 + i, 40, 5.0, &stats)));
  for (int i = 0; i < 6; ++i) {
    const mapping::MapDelta d = a->takeChanges(kCamera, 20.0 + i, 40, 5.0, &stats);
    for (const auto& k : keysToVoxels(d.occupied)) EXPECT_EQ(face.count(k), 0u);
  }
  // refresh_share 0: nothing is ever resent.
  auto c = makeLiveMap();
  ASSERT_TRUE(c->integrate(boxFrame(kBoxALo, kBoxAHi, 1.0)));
  EXPECT_EQ(c->takeChanges(kCamera, 1.0, 100, 5.0).size(), 70u);
  EXPECT_EQ(c->takeChanges(kCamera, 2.0, 100, 5.0, &stats).size(), 0u);
  EXPECT_EQ(stats.refreshed, 0);
}

TEST(MapShareTest, ADeltaThatDoesNotFitIsRefusedNamingTheFieldAndChangesNothing) {
  auto a = makeLiveMap(), b = makeLiveMap();
  ASSERT_TRUE(a && b);
  ASSERT_TRUE(a->integrate(boxFrame(kBoxALo, kBoxAHi, 1.0)));
  mapping::MapDelta delta = a->takeChanges(kCamera, 1.0, 10000, 5.0);
  mapping::MapDelta bad = delta;
  bad.resolution_m = 0.4;
  auto r = b->merge(bad);
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find("resolution_m"), std::string::npos) << r.reason();
  bad = delta;
  bad.occupied.back()[0] = 1;  // far outside the grid
  r = b->merge(bad);
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find("occupied[69] key (1, "), std::string::npos) << r.reason();
  EXPECT_TRUE(occupiedVoxels(*b->map()).empty());
  const mapping::KeyGrid g = b->keyGrid();
  EXPECT_EQ(g.min_key[0], 32768 - 5);  // x from −1 m at 0.2 m
  EXPECT_DOUBLE_EQ(g.resolution_m, kRes);
}

TEST(MappingConfigTest, ShareKeysAndTheBudgetRuleAreChecked) {
  MappingConfig c;
  EXPECT_EQ(mapping::shareVoxelBudget(c.share), (25000u - 118u) / 6u);  // 50 000 B/s at 2 Hz
  c.share.rate_hz = 0.0;
  c.share.max_bytes_per_s = 500.0;
  c.share.max_age_s = 61.0;
  auto problems = c.validate();
  ASSERT_EQ(problems.size(), 3u) << ::testing::PrintToString(problems);
  EXPECT_NE(problems[0].find("share.rate_hz"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("share.max_bytes_per_s"), std::string::npos) << problems[1];
  EXPECT_NE(problems[2].find("share.max_age_s"), std::string::npos) << problems[2];
  // In range each, but 1 000 B/s at 10 updates a second leaves 100 B an update: not one voxel.
  c = MappingConfig{};
  c.share.rate_hz = 10.0;
  c.share.max_bytes_per_s = 1000.0;
  problems = c.validate();
  ASSERT_EQ(problems.size(), 1u) << ::testing::PrintToString(problems);
  EXPECT_NE(problems[0].find("share.max_bytes_per_s must allow one voxel per update"), std::string::npos) << problems[0];
  EXPECT_EQ(mapping::shareVoxelBudget(c.share), 0u);
  c.share.max_bytes_per_s = 1e7;  // capped by the payload limit
  EXPECT_EQ(mapping::shareVoxelBudget(c.share), mapping::kMaxMapUpdateVoxels);
}

// An update's stamp is the sender's newest frame, not when it saw each voxel: a "free" voxel may
// wait in its queue for seconds. UAV A sees the box, then the place empty at 2 s, then looks at
// nothing at 6 s: its update lists the face free, stamped 6 s. UAV B saw the box itself at 4 s: the
// received "free" must not clear it (before, the later stamp won and the obstacle left B's map and
// field). Nor, the other way round, may a received "free" outweigh B's own later return.
TEST(MapShareTest, AReceivedFreeNeverClearsWhatTheOwnCameraHoldsOccupied) {
  auto a = makeLiveMap(), b = makeLiveMap(), c = makeLiveMap();
  ASSERT_TRUE(a && b && c);
  const std::set<Key> face = faceVoxels(4.7, -0.9, 0.9, 0.9, 2.1);
  ASSERT_TRUE(a->integrate(boxFrame(kBoxALo, kBoxAHi, 1.0)));
  ASSERT_EQ(a->takeChanges(kCamera, 1.0, 10000, 5.0).size(), face.size());
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(a->integrate(emptyFrame(2.0 + 0.1 * i)));
  ASSERT_TRUE(occupiedVoxels(*a->map()).empty());
  DepthFrame blind = cameraAt(kCamera);  // no valid pixel: a frame that observes nothing here
  blind.depth_m.setTo(std::numeric_limits<float>::quiet_NaN());
  blind.stamp_s = 6.0;
  ASSERT_TRUE(a->integrate(blind));
  const mapping::MapDelta freed = a->takeChanges(kCamera, 6.0, 10000, 5.0);
  ASSERT_EQ(keysToVoxels(freed.free), face);
  ASSERT_DOUBLE_EQ(freed.stamp_s, 6.0);

  ASSERT_TRUE(b->integrate(boxFrame(kBoxALo, kBoxAHi, 4.0)));
  ASSERT_EQ(occupiedVoxels(*b->map()), face);
  const auto merged = b->merge(freed);
  ASSERT_TRUE(merged) << merged.reason();
  EXPECT_EQ(merged->superseded, static_cast<int>(face.size()));
  EXPECT_EQ(occupiedVoxels(*b->map()), face);
  expectFieldIsFullRebuild(*b);

  ASSERT_TRUE(c->merge(freed));  // C never saw the place: it takes the word
  ASSERT_TRUE(c->integrate(boxFrame(kBoxALo, kBoxAHi, 5.0)));  // then its camera sees the box, stamp < 6 s
  EXPECT_EQ(occupiedVoxels(*c->map()), face);
  expectFieldIsFullRebuild(*c);
}

// A voxel on the resend list that went free and occupied again is sent as a change; the resend pass
// of the same update must not list it a second time (a key listed twice refuses the whole update at
// the encoder and at every receiver).
TEST(MapShareRefreshTest, AChangeIsNotResentInTheSameUpdate) {
  auto a = makeLiveMap(nullptr, 0.5);
  ASSERT_TRUE(a);
  const std::set<Key> face = faceVoxels(4.7, -0.9, 0.9, 0.9, 2.1);
  ASSERT_TRUE(a->integrate(boxFrame(kBoxALo, kBoxAHi, 1.0)));
  ASSERT_EQ(a->takeChanges(kCamera, 1.0, 100, 5.0).occupied.size(), face.size());  // now on the resend list
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(a->integrate(emptyFrame(2.0 + 0.1 * i)));
  // Sent free in an update with no room left for resends: they stay on the resend list meanwhile.
  ASSERT_EQ(a->takeChanges(kCamera, 2.5, face.size(), 5.0).free.size(), face.size());
  ASSERT_TRUE(a->integrate(boxFrame(kBoxALo, kBoxAHi, 3.0)));
  ASSERT_EQ(occupiedVoxels(*a->map()), face);
  mapping::OutgoingStats stats;
  const mapping::MapDelta d = a->takeChanges(kCamera, 3.0, 100, 5.0, &stats);  // 70 changes, room for 30 resends
  EXPECT_EQ(keysToVoxels(d.occupied), face);
  EXPECT_EQ(d.occupied.size(), face.size());  // each key once
  EXPECT_EQ(stats.refreshed, 0);
  comm::MapUpdate u;
  u.delta = d;
  const auto bytes = comm::encodePayload(u);
  EXPECT_TRUE(bytes) << bytes.reason();
}

// ROS time went back (a simulation restarted at 0 s after 100 s): the map is kept, the old
// timeline's stamps are not — else every own frame and received word of the new timeline would
// lose to voxels stamped ~100 s until the clock caught up (the receiver ignoring the others'
// obstacles meanwhile).
TEST(MapShareTest, AfterTheClockWentBackTheMapStaysAndNewWordsWin) {
  auto a = makeLiveMap(), b = makeLiveMap();
  ASSERT_TRUE(a && b);
  const std::set<Key> face = faceVoxels(4.7, -0.9, 0.9, 0.9, 2.1);
  ASSERT_TRUE(b->integrate(emptyFrame(100.0)));  // B saw the place empty at 100 s
  ASSERT_TRUE(a->integrate(boxFrame(kBoxALo, kBoxAHi, 100.0)));
  a->restartClock(5.0);
  b->restartClock(5.0);
  EXPECT_EQ(occupiedVoxels(*a->map()), face);  // kept
  ASSERT_EQ(a->pendingChanges(), face.size());
  // A's waiting changes go out stamped with its first frame of the new timeline; B takes them (its
  // own word was of the old timeline: without the restart it would outweigh them until 100 s).
  ASSERT_TRUE(a->integrate(boxFrame(kBoxALo, kBoxAHi, 6.0)));
  const mapping::MapDelta d = a->takeChanges(kCamera, 6.0, 10000, 5.0);
  EXPECT_EQ(keysToVoxels(d.occupied), face);
  EXPECT_DOUBLE_EQ(d.stamp_s, 6.0);
  const auto merged = b->merge(d);
  ASSERT_TRUE(merged) << merged.reason();
  EXPECT_EQ(merged->superseded, 0);
  EXPECT_EQ(occupiedVoxels(*b->map()), face);
  expectFieldIsFullRebuild(*b);
}

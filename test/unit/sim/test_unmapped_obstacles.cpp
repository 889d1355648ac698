// The scenario schema of unmapped obstacles (sim::parseUnmappedObstacles, docs/simulation.md):
// shapes as in boxes / cylinders, motion, and every error naming its field and value.
#include <gtest/gtest.h>

#include <cmath>

#include "gesture_formation/sim/site_mapping_config.hpp"
#include "gesture_formation/sim/unmapped_obstacles.hpp"

namespace gf = gesture_formation;

namespace {

std::string parseError(const std::string& yaml) {
  const auto r = gf::sim::parseUnmappedObstacles(yaml, "test.yaml");
  return r ? std::string("(parsed)") : r.reason();
}

}  // namespace

TEST(UnmappedObstaclesTest, ParsesShapesAndMotion) {
  const auto r = gf::sim::parseUnmappedObstacles(R"(
boxes: [{center: [0, 0, 1], size: [1, 1, 2]}]   # mapped: not this section
unmapped_obstacles:
  - name: crane_arm
    box: {center: [10, 0, 8], size: [20, 0.6, 0.6], rpy_deg: [0, 0, 90]}
  - cylinder: {base: [3, 4, 0], radius_m: 0.05, height_m: 6}
  - name: truck
    box: {center: [0, -5, 1.5], size: [8, 2.5, 3]}
    moves: {from_s: 10, to_s: 20, velocity_mps: [3, 0, 0]}
    gone_after_s: 25
)", "test.yaml");
  ASSERT_TRUE(static_cast<bool>(r)) << r.reason();
  ASSERT_EQ(r->size(), 3u);
  const auto& arm = (*r)[0];
  EXPECT_EQ(arm.name, "crane_arm");
  EXPECT_EQ(arm.shape, gf::sim::UnmappedObstacle::Shape::kBox);
  EXPECT_NEAR(arm.distanceAt(Eigen::Vector3d(10, 5, 8), 0.0), 0.0, 1e-9);   // yawed 90°: along y
  EXPECT_NEAR(arm.distanceAt(Eigen::Vector3d(15, 0, 8), 0.0), 4.7, 1e-9);
  EXPECT_EQ((*r)[1].name, "unmapped_1");
  EXPECT_NEAR((*r)[1].distanceAt(Eigen::Vector3d(4, 4, 3), 0.0), 0.95, 1e-9);
  const auto& truck = (*r)[2];
  EXPECT_NEAR(truck.distanceAt(Eigen::Vector3d(0, -5, 1.5), 5.0), 0.0, 1e-9);    // parked
  EXPECT_NEAR(truck.distanceAt(Eigen::Vector3d(0, -5, 1.5), 15.0), 11.0, 1e-9);   // moved 15 m, half-length 4
  EXPECT_NEAR(truck.distanceAt(Eigen::Vector3d(30, -5, 1.5), 24.0), 0.0, 1e-9);   // stopped 30 m on
  EXPECT_TRUE(std::isinf(truck.distanceAt(Eigen::Vector3d(30, -5, 1.5), 25.0)));  // gone
  EXPECT_TRUE(truck.primitivesAt(26.0).boxes.empty());
  EXPECT_TRUE(gf::sim::parseUnmappedObstacles("map: {resolution_m: 0.2}\n", "x")->empty());  // no section: none
}

TEST(UnmappedObstaclesTest, ErrorsNameTheFieldAndValue) {
  struct Case {
    const char* yaml;
    const char* expected;
  };
  const Case cases[] = {
      {"unmapped_obstacles: {box: 1}\n", "unmapped_obstacles: expected a list"},
      {"unmapped_obstacles:\n  - name: a\n", "unmapped_obstacles[0]: missing its shape: give box or cylinder"},
      {"unmapped_obstacles:\n  - box: {center: [0, 0, 0], size: [1, 1, 1]}\n    cylinder: {base: [0, 0, 0], radius_m: 1, height_m: 1}\n",
       "unmapped_obstacles[0]: has both box and cylinder"},
      {"unmapped_obstacles:\n  - box: {center: [0, 0, 0], size: [1, -2, 1]}\n", "unmapped_obstacles[0].box.size"},
      {"unmapped_obstacles:\n  - box: {size: [1, 1, 1]}\n", "unmapped_obstacles[0].box.center: missing (required)"},
      {"unmapped_obstacles:\n  - cylinder: {base: [0, 0, 0], radius_m: 0, height_m: 3}\n",
       "unmapped_obstacles[0].cylinder.radius_m"},
      {"unmapped_obstacles:\n  - cylinder: {base: [0, 0, 0], height_m: 3}\n",
       "unmapped_obstacles[0].cylinder.radius_m: missing (required)"},
      {"unmapped_obstacles:\n  - box: {center: [0, 0, 0], size: [1, 1, 1]}\n    moves: {from_s: 5, to_s: 2, velocity_mps: [1, 0, 0]}\n",
       "unmapped_obstacles[0].moves.to_s: must be >= from_s (5), got 2"},
      {"unmapped_obstacles:\n  - box: {center: [0, 0, 0], size: [1, 1, 1]}\n    gone_after_s: -1\n",
       "unmapped_obstacles[0].gone_after_s"},
      {"unmapped_obstacles:\n  - box: {center: [0, 0, 0], size: [1, 1, 1]}\n    colour: red\n",
       "unmapped_obstacles[0].colour: unknown key"},
      {"unmapped_obstacles:\n  - {name: a, box: {center: [0, 0, 0], size: [1, 1, 1]}}\n  - {name: a, box: {center: [0, 0, 0], size: [1, 1, 1]}}\n",
       "unmapped_obstacles[1].name: duplicate name 'a'"},
  };
  for (const Case& c : cases) {
    const std::string err = parseError(c.yaml);
    EXPECT_NE(err.find(c.expected), std::string::npos) << "yaml:\n" << c.yaml << "error: " << err;
    EXPECT_NE(err.find("test.yaml"), std::string::npos) << err;
  }
  // A bad value names the value too.
  EXPECT_NE(parseError("unmapped_obstacles:\n  - box: {center: [0, 0, 0], size: [1, 1, 1]}\n    gone_after_s: -1\n").find("-1"),
            std::string::npos);
}

TEST(UnmappedObstaclesTest, MappingSettingsAreValidated) {
  gf::sim::SiteMappingConfig c;
  EXPECT_TRUE(c.validate("mission.mapping.").empty());
  c.rate_hz = 0.0;
  c.live.pixel_stride = 0;
  const auto e = c.validate("mission.mapping.");
  ASSERT_EQ(e.size(), 2u);
  EXPECT_NE(e[0].find("mission.mapping.rate_hz"), std::string::npos) << e[0];
  EXPECT_NE(e[1].find("mission.mapping.depth.pixel_stride"), std::string::npos) << e[1];
}

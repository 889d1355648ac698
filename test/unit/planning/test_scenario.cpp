// Scenario loading: the shipped files load; every problem is listed at once with its line;
// unknown keys in owned sections are errors; foreign top-level sections are ignored.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "gesture_formation/planning/scenario.hpp"

using namespace gesture_formation::planning;

namespace {

std::size_t countLines(const std::string& s) {
  std::size_t n = 0;
  for (const char c : s) n += c == '\n';
  return n;
}

const char* kMinimal = R"(
map:
  resolution_m: 0.2
  bounds: {min: [0, 0, 0], max: [10, 10, 10]}
)";

}  // namespace

TEST(ScenarioTest, ShippedScenariosLoad) {
  for (const std::string name : {"power_towers", "open_field", "dense_pillars"}) {
    const auto s = loadScenario(std::string(GF_SOURCE_DIR) + "/config/scenarios/" + name + ".yaml");
    ASSERT_TRUE(s) << name << ":\n" << s.reason();
    EXPECT_TRUE(s->map.validate().empty());
    EXPECT_TRUE(s->ground.enabled);
  }
  const auto s = loadScenario(std::string(GF_SOURCE_DIR) + "/config/scenarios/power_towers.yaml");
  ASSERT_TRUE(s);
  ASSERT_EQ(s->towers.size(), 2u);
  EXPECT_NEAR((s->towers[1].base_world - s->towers[0].base_world).norm(), 50.0, 1e-9);
  EXPECT_NEAR(s->towers[0].height_m, 30.0, 1e-9);
  EXPECT_GE(s->conductors.size(), 6u);
  EXPECT_EQ(s->insulators.size(), 8u);  // 4 phase conductors hung from 2 m strings, both ends
  // Conductors attached to arm tips end at the tip lowered by the insulator.
  EXPECT_NEAR((s->conductors[0].from_world - s->towers[0].armTip(0, 1, 2.0)).norm(), 0.0, 1e-12);
  for (const auto& c : s->conductors) {
    const auto cat = Catenary::fit(c.from_world, c.to_world, c.sag_m);
    ASSERT_TRUE(cat);
    EXPECT_GT(cat->lowestZ(), 8.0);  // well above the ground
  }
}

TEST(ScenarioTest, MinimalScenarioAndDefaults) {
  const auto s = parseScenario(kMinimal, "minimal.yaml");
  ASSERT_TRUE(s) << s.reason();
  EXPECT_FALSE(s->ground.enabled);
  EXPECT_TRUE(s->primitives().boxes.empty());
  EXPECT_DOUBLE_EQ(s->map.resolution_m, 0.2);
}

TEST(ScenarioTest, ForeignTopLevelSectionsAreIgnored) {
  const std::string yaml = std::string(kMinimal) + R"(
worker_route: {waypoints: [[1, 2, 3]], speed_mps: 1.0}
uavs: [{name: leader, frame: tarot650}]
mission: {anything: [1, 2, {deep: true}]}
)";
  const auto s = parseScenario(yaml, "foreign.yaml");
  EXPECT_TRUE(s) << s.reason();
}

TEST(ScenarioTest, ListsEveryProblemWithItsLine) {
  const std::string yaml = R"(map:
  resolution_m: 0
  bounds: {min: [0, 0, 0], max: [10, 10]}
ground: {heigth_m: 0}
boxes:
  - {center: [1, 2, 3], size: [1, -1, 1], colour: red}
  - {size: [1, 1, 1]}
cylinders:
  - {base: [1, 1, 0], radius_m: abc, height_m: 3}
towers:
  - {name: a, base: [0, 0, 0], height_m: 30, top_width_m: 9, cross_arms: [{height_m: 20, half_length_m: 5}]}
conductors:
  - {from: {tower: a, arm: 3, side: 1}, to: {tower: b, arm: 0, side: 1}, sag_m: 2}
  - {from: [0, 0, 10], to: [0, 0, 20], sag_m: 2}
worker_route: {whatever: 1}
)";
  const auto s = parseScenario(yaml, "bad.yaml");
  ASSERT_FALSE(s);
  const std::string& r = s.reason();
  const std::vector<std::string> expected = {
      "bad.yaml:2: map.resolution_m",          "bad.yaml:3: map.bounds.max",
      "bad.yaml:4: ground.height_m: missing",  "bad.yaml:4: ground.heigth_m: unknown key",
      "bad.yaml:6: boxes[0].size[1]",          "bad.yaml:6: boxes[0].colour: unknown key",
      "bad.yaml:7: boxes[1].center: missing",  "bad.yaml:9: cylinders[0].radius_m: expected a number",
      "bad.yaml:11: towers[0].top_width_m",    "bad.yaml:13: conductors[0].from.arm: tower 'a' has 1 cross-arms",
      "bad.yaml:13: conductors[0].to.tower: no tower named 'b'",
      "bad.yaml:14: conductors[1]: the attachment points are vertically aligned"};
  for (const auto& e : expected) EXPECT_NE(r.find(e), std::string::npos) << "missing '" << e << "' in:\n" << r;
  EXPECT_EQ(r.find("worker_route"), std::string::npos) << r;
  EXPECT_EQ(countLines(r), expected.size()) << r;
}

TEST(ScenarioTest, StructureErrors) {
  const auto s = parseScenario(std::string(kMinimal) + "boxes: 5\ntowers: [7]\n", "structure.yaml");
  ASSERT_FALSE(s);
  EXPECT_NE(s.reason().find("boxes: expected a list"), std::string::npos) << s.reason();
  EXPECT_NE(s.reason().find("towers[0]: expected a mapping"), std::string::npos) << s.reason();
  EXPECT_FALSE(loadScenario("/nonexistent/scenario.yaml"));
  const auto syntax = parseScenario("map: {resolution_m: [\n", "syntax.yaml");
  ASSERT_FALSE(syntax);
  EXPECT_NE(syntax.reason().find("syntax.yaml:"), std::string::npos);
}

TEST(ScenarioTest, MissingMapSectionIsAnError) {
  const auto s = parseScenario("ground: {height_m: 0}\n", "nomap.yaml");
  ASSERT_FALSE(s);
  EXPECT_NE(s.reason().find("map.resolution_m: missing"), std::string::npos) << s.reason();
  EXPECT_NE(s.reason().find("map.bounds.min: missing"), std::string::npos) << s.reason();
}

// Issue 34: the map's rule between keys (bounds max > min) is reported beside a key already out
// of range (before, only once every single key was fine: a broken map showed on a second run),
// and a tower's rules beside a bad tower key.
TEST(ScenarioTest, RulesBetweenKeysBesideAnOutOfRangeKey) {
  const auto s = parseScenario(
      "map:\n  resolution_m: 20\n  bounds: {min: [0, 0, 0], max: [10, -1, 10]}\n"
      "towers:\n  - {name: a, base: [0, 0, 0], height_m: 30, panels: 0, cross_arms: [{height_m: 31, half_length_m: 5}]}\n",
      "two.yaml");
  ASSERT_FALSE(s);
  const std::vector<std::string> expected = {"two.yaml:2: map.resolution_m: value 20 is out of range [0.01, 10]",
                                             "two.yaml:3: map.bounds: max[1] must be > min[1]",
                                             "two.yaml:5: towers[0].panels: value 0 is out of range [1, 1000]",
                                             "two.yaml:5: towers[0].cross_arms[0].height_m: must be <= the tower's "
                                             "height_m, got 31"};
  for (const auto& e : expected) EXPECT_NE(s.reason().find(e), std::string::npos) << e << " not in:\n" << s.reason();
  EXPECT_EQ(countLines(s.reason()), expected.size()) << s.reason();
}

// One range per key: the scenario reader and MapConfig / LatticeTowerSpec::validate() accept and
// refuse the same boundary values.
TEST(ScenarioTest, ValidateAndYamlAgreeOnBoundaries) {
  struct Case {
    const char* resolution;
    int panels;
    bool valid;
  };
  for (const Case& k : {Case{"0.01", 1000, true}, Case{"10", 1, true}, Case{"0.0099", 8, false},
                        Case{"0.2", 1001, false}}) {
    const std::string yaml = std::string("map:\n  resolution_m: ") + k.resolution +
                             "\n  bounds: {min: [0, 0, 0], max: [2, 2, 10]}\n"  // 4e7 voxels at 0.01 m
                             "towers:\n  - {name: a, base: [1, 1, 0], height_m: 8, panels: " +
                             std::to_string(k.panels) + "}\n";
    EXPECT_EQ(static_cast<bool>(parseScenario(yaml, "b.yaml")), k.valid) << yaml;
    MapConfig m;
    m.bounds = Aabb{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 2, 10)};
    m.resolution_m = std::stod(k.resolution);
    LatticeTowerSpec t;
    t.height_m = 8.0;
    t.panels = k.panels;
    EXPECT_EQ(m.validate().empty() && t.validate().empty(), k.valid) << yaml;
  }
}

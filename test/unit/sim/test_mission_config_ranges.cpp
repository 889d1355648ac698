// One range per setting: every number of every simulator section (plant, controller, odometry,
// wind, sensors, links, worker, route legs, fault entries) and every onboard replanning number is
// read by the mission loader with the range of its module's FieldTable — a value just outside that
// range, written into a shipped scenario, is refused naming its full key; the same value in the
// struct is named by the module's validate().
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "gesture_formation/planning/replan_step.hpp"
#include "gesture_formation/sim/mission_config.hpp"

namespace gf = gesture_formation;

namespace {

/// A value outside `range` (just below its lower end, else just above its upper end).
double outside(const gf::common::Range& range) {
  if (std::isfinite(range.lo)) return range.lo_inclusive ? range.lo - 1.0 : range.lo - 0.5;
  return range.hi_inclusive ? range.hi + 1.0 : range.hi + 0.5;
}

/// The node at `path` ("a.b.c"; "uavs[0]" indexes a list), created as maps where absent.
YAML::Node at(YAML::Node root, const std::string& path) {
  YAML::Node n = root;
  std::size_t from = 0;
  while (from <= path.size()) {
    const std::size_t dot = path.find('.', from);
    std::string part = path.substr(from, dot == std::string::npos ? std::string::npos : dot - from);
    const std::size_t bracket = part.find('[');
    if (bracket != std::string::npos) {
      const int index = std::stoi(part.substr(bracket + 1));
      n.reset(n[part.substr(0, bracket)][index]);
    } else {
      n.reset(n[part]);
    }
    if (dot == std::string::npos) break;
    from = dot + 1;
  }
  return n;
}

/// The shipped scenario with `key` (below mission.) set to `value`.
std::string scenarioWith(const std::string& key, double value) {
  YAML::Node root = YAML::LoadFile(std::string(GF_SOURCE_DIR) + "/config/scenarios/power_towers.yaml");
  YAML::Node n = at(root["mission"], key);
  n = value;
  YAML::Emitter out;
  out << root;
  return out.c_str();
}

template <class Config>
void expectEveryFieldRefused(const gf::common::FieldTable<Config>& table, const std::string& section,
                             const std::function<std::vector<std::string>(const Config&)>& validate) {
  ASSERT_FALSE(table.fields.empty());
  for (const auto& f : table.fields) {
    const double v = outside(f.range);
    const std::string key = section + f.key;
    const auto m = gf::sim::parseMissionConfig(scenarioWith(key, v), "t.yaml", std::string(GF_SOURCE_DIR) + "/config/scenarios");
    ASSERT_FALSE(m) << key << " = " << v << " was accepted";
    EXPECT_NE(m.reason().find("mission." + key), std::string::npos) << key << " not named in:\n" << m.reason();
    if (validate) {
      Config c;
      if (f.ref_int) {
        *f.ref_int(c) = static_cast<int>(v);
      } else if (f.ref_double) {
        *f.ref_double(c) = v;
      } else {
        *f.ref_float(c) = static_cast<float>(v);
      }
      std::string all;
      for (const auto& line : validate(c)) all += line + "\n";
      EXPECT_NE(all.find(std::string(f.key) + " must be"), std::string::npos) << f.key << " not named by validate():\n" << all;
    }
  }
}

}  // namespace

TEST(MissionConfigRangesTest, ShippedScenarioLoads) {
  const auto m = gf::sim::parseMissionConfig(scenarioWith("step_s", 0.01), "t.yaml",
                                             std::string(GF_SOURCE_DIR) + "/config/scenarios");
  ASSERT_TRUE(m) << m.reason();
}

TEST(MissionConfigRangesTest, EverySimulatorNumberIsReadWithItsModulesRange) {
  using namespace gf::sim;
  expectEveryFieldRefused<MultirotorParams>(multirotorParamsFields(), "uavs[1].plant.",
                                            [](const MultirotorParams& c) { return c.validate(); });
  expectEveryFieldRefused<ControllerConfig>(controllerConfigFields(), "controller.",
                                            [](const ControllerConfig& c) { return c.validate(); });
  expectEveryFieldRefused<OdometryConfig>(odometryConfigFields(), "odometry.",
                                          [](const OdometryConfig& c) { return c.validate(); });
  expectEveryFieldRefused<WindConfig>(windConfigFields(), "wind.", [](const WindConfig& c) { return c.validate(); });
  expectEveryFieldRefused<WindConfig>(windConfigFields(), "faults.wind.", nullptr);
  expectEveryFieldRefused<CameraSensorConfig>(cameraSensorFields(), "sensors.camera.",
                                              [](const CameraSensorConfig& c) { return c.validate(); });
  expectEveryFieldRefused<RangeSensorConfig>(rangeSensorFields(), "sensors.uwb.",
                                             [](const RangeSensorConfig& c) { return c.validate(); });
  expectEveryFieldRefused<gf::comm::FaultChannelConfig>(gf::comm::faultChannelFields(), "links.operator.",
                                                        [](const gf::comm::FaultChannelConfig& c) { return c.validate(); });
  expectEveryFieldRefused<gf::comm::FaultChannelConfig>(gf::comm::faultChannelFields(), "faults.link.", nullptr);
  expectEveryFieldRefused<RangeOutlierConfig>(rangeOutlierFields(), "faults.range_outliers.", nullptr);
  expectEveryFieldRefused<WorkerConfig>(workerConfigFields(), "worker.", [](const WorkerConfig& c) { return c.validate(); });
}

TEST(MissionConfigRangesTest, EveryReplanningNumberIsReadWithTheReplanningStepsRange) {
  expectEveryFieldRefused<gf::planning::ReplanConfig>(gf::planning::replanConfigFields(), "",
                                                      [](const gf::planning::ReplanConfig& c) { return c.validate(); });
  // The simulated flight controller brakes with the onboard braking deceleration and its range.
  gf::sim::ControllerConfig c;
  c.brake_accel_mps2 = 51.0;
  ASSERT_EQ(c.validate("mission.controller.").size(), 1u);
  EXPECT_EQ(c.validate("mission.controller.")[0], "mission.controller.brake_accel_mps2 must be in (0, 50], got 51");
}

TEST(MissionConfigRangesTest, RulesBetweenFieldsNameTheirKey) {
  gf::sim::MultirotorParams p;
  p.min_pitch_deg = 30.0;
  p.max_pitch_deg = 20.0;
  const auto e = p.validate("uavs[0].plant.");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0], "uavs[0].plant.min_pitch_deg must be < max_pitch_deg, got 30");

  gf::sim::FaultConfig f;
  f.follower_dropouts.push_back({0, 5.0, 2.0});  // uav 0 is the leader; the window is reversed
  f.range_outliers.min_error_m = 4.0;
  f.range_outliers.max_error_m = 2.0;
  std::string all;
  for (const auto& line : f.validate("faults.")) all += line + "\n";
  EXPECT_NE(all.find("faults.follower_dropouts[0].uav must be in [1, 63], got 0"), std::string::npos) << all;
  EXPECT_NE(all.find("faults.follower_dropouts[0] needs from_s < to_s, got from_s 5, to_s 2"), std::string::npos) << all;
  EXPECT_NE(all.find("faults.range_outliers.max_error_m must be >= min_error_m, got 2"), std::string::npos) << all;
}

// A UAV reaching farther than the verifier's clearance could be planned into contact.
TEST(MissionConfigRangesTest, ABodyWiderThanTheVerifiedClearanceIsRefused) {
  const std::string dir = std::string(GF_SOURCE_DIR) + "/config/scenarios";
  auto m = gf::sim::parseMissionConfig(scenarioWith("uavs[1].plant.body_radius_m", 0.52), "t.yaml", dir);
  ASSERT_FALSE(m);
  EXPECT_NE(m.reason().find("mission.uavs[1].plant.body_radius_m"), std::string::npos) << m.reason();
  EXPECT_NE(m.reason().find("0.52 m exceeds the planner's verify.clearance_m 0.5 m"), std::string::npos) << m.reason();
  m = gf::sim::parseMissionConfig(scenarioWith("uavs[1].plant.body_radius_m", 0.5), "t.yaml", dir);
  EXPECT_TRUE(m) << m.reason();
}

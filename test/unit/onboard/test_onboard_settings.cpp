// onboard::loadOnboardSettings — the product settings of a scenario's mission, the one parse the
// onboard nodelets (mission_file) and gfctl simulate share: the shipped scenarios load, a fault
// profile's limits are merged, every problem is listed at once with its key.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "gesture_formation/gesture/gesture_filter.hpp"
#include "gesture_formation/onboard/onboard_settings.hpp"

namespace go = gesture_formation::onboard;

namespace {

std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST(OnboardSettingsTest, PowerTowerMissionLoadsWithItsOwnValues) {
  const auto s = go::loadOnboardSettings(std::string(GF_SOURCE_DIR) + "/config/scenarios/power_towers.yaml");
  ASSERT_TRUE(s) << s.reason();
  EXPECT_EQ(s->formation.params.uavCount(), 3);
  EXPECT_GT(s->replan.steps, 1);
  EXPECT_GT(s->replanning_period_s, 0.0);
  EXPECT_GT(s->view_fusion.min_agreeing_views, 1);  // the formation's cameras vote
}

TEST(OnboardSettingsTest, FaultProfileReplacesTheMissionsFaultLimits) {
  const std::string scenario = writeTemp("onboard_scenario.yaml",
                                         "mission:\n  horizon_steps: 30\n  faults:\n    max_share_age_s: 2.0\n");
  const std::string faults = writeTemp("onboard_faults.yaml", "faults:\n  max_share_age_s: 0.7\n  max_plan_age_s: 3.0\n");
  const auto plain = go::loadOnboardSettings(scenario);
  ASSERT_TRUE(plain) << plain.reason();
  EXPECT_DOUBLE_EQ(plain->replan.freshness.max_share_age_s, 2.0);
  EXPECT_EQ(plain->replan.steps, 30);
  const auto merged = go::loadOnboardSettings(scenario, faults);
  ASSERT_TRUE(merged) << merged.reason();
  EXPECT_DOUBLE_EQ(merged->replan.freshness.max_share_age_s, 0.7);
  EXPECT_DOUBLE_EQ(merged->replan.rule.max_plan_age_s, 3.0);
  EXPECT_EQ(merged->replan.steps, 30);
}

TEST(OnboardSettingsTest, EveryProblemIsListedWithItsKey) {
  const std::string scenario = writeTemp("onboard_bad.yaml",
                                         "mission:\n"
                                         "  horizon_steps: 1\n"
                                         "  controller:\n    brake_accel_mps2: -2\n"
                                         "  faults:\n    max_worker_age_s: 0\n    search_period_s: nan\n"
                                         "  planner:\n    no_such_key: 3\n");
  const auto s = go::loadOnboardSettings(scenario);
  ASSERT_FALSE(s);
  for (const char* key : {"mission.horizon_steps", "mission.controller.brake_accel_mps2", "mission.faults.max_worker_age_s",
                          "mission.faults.search_period_s", "mission.planner.no_such_key"}) {
    EXPECT_NE(s.reason().find(key), std::string::npos) << key << " not named in:\n" << s.reason();
  }
}

TEST(OnboardSettingsTest, MissingFilesAndSectionsAreNamed) {
  const auto none = go::loadOnboardSettings("/nonexistent/scenario.yaml");
  ASSERT_FALSE(none);
  EXPECT_NE(none.reason().find("/nonexistent/scenario.yaml"), std::string::npos);
  const std::string no_mission = writeTemp("onboard_nomission.yaml", "scenario: {}\n");
  const auto s = go::loadOnboardSettings(no_mission);
  ASSERT_FALSE(s);
  EXPECT_NE(s.reason().find("mission"), std::string::npos);
  const std::string faults = writeTemp("onboard_badfaults.yaml", "faults: {}\nextra: 1\n");
  const auto f = go::loadOnboardSettings(std::string(GF_SOURCE_DIR) + "/config/scenarios/power_towers.yaml", faults);
  ASSERT_FALSE(f);
  EXPECT_NE(f.reason().find("extra: unknown key"), std::string::npos) << f.reason();
}

// The filter's re-arming mode reaches gfctl simulate and the nodelets' mission_file through this one
// parse (gesture::readGestureFilterConfig); default release, a bad value names the key and the value.
TEST(OnboardSettingsTest, GestureRearmModeIsReadFromTheMission) {
  namespace gg = gesture_formation::gesture;
  const auto shipped = go::loadOnboardSettings(std::string(GF_SOURCE_DIR) + "/config/scenarios/power_towers.yaml");
  ASSERT_TRUE(shipped) << shipped.reason();
  EXPECT_EQ(shipped->gesture_filter.rearm, gg::RearmMode::kRelease);
  const auto repeat = go::loadOnboardSettings(writeTemp("onboard_repeat.yaml", "mission:\n  gestures:\n    rearm: repeat\n    release_s: 2\n"));
  ASSERT_TRUE(repeat) << repeat.reason();
  EXPECT_EQ(repeat->gesture_filter.rearm, gg::RearmMode::kRepeat);
  EXPECT_DOUBLE_EQ(repeat->gesture_filter.release_s, 2.0);
  const auto bad = go::loadOnboardSettings(writeTemp("onboard_badrearm.yaml", "mission:\n  gestures:\n    rearm: twice\n"));
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.reason().find("mission.gestures.rearm"), std::string::npos) << bad.reason();
  EXPECT_NE(bad.reason().find("twice"), std::string::npos) << bad.reason();
}

TEST(OnboardSettingsTest, AHorizonShorterThanTheLongestBrakeIsRefusedNamingTheNumbers) {
  // The limits' defaults (config/planner.yaml): 5 m/s at 3 m/s² brakes in 1.67 s, on 0.2 s samples
  // in 1.8 s; a horizon of 9 steps spans 1.6 s, and a brake plan would end moving.
  const auto short_horizon = go::loadOnboardSettings(
      writeTemp("onboard_short_horizon.yaml", "mission:\n  horizon_dt_s: 0.2\n  horizon_steps: 9\n"));
  ASSERT_FALSE(short_horizon);
  for (const char* needle : {"mission.horizon_steps", "= 1.6 s", "longest brake 1.8 s", "need horizon_steps >= 10"}) {
    EXPECT_NE(short_horizon.reason().find(needle), std::string::npos) << needle << "\n" << short_horizon.reason();
  }
  const auto fits = go::loadOnboardSettings(
      writeTemp("onboard_fitting_horizon.yaml", "mission:\n  horizon_dt_s: 0.2\n  horizon_steps: 10\n"));
  EXPECT_TRUE(fits) << fits.reason();
  // The vertical bounds can bind: 2 m/s at 0.5 m/s² takes 4 s.
  const auto vertical = go::loadOnboardSettings(writeTemp(
      "onboard_vertical_brake.yaml",
      "mission:\n  horizon_dt_s: 0.2\n  horizon_steps: 10\n  planner:\n    limits: {max_vertical_acceleration_mps2: 0.5}\n"));
  ASSERT_FALSE(vertical);
  EXPECT_NE(vertical.reason().find("need horizon_steps >= 21"), std::string::npos) << vertical.reason();
}

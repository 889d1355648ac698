#include <gtest/gtest.h>

#include "gesture_formation/gesture/gesture_filter.hpp"
#include "gesture_formation/gesture/gesture_mapping.hpp"
#include "gesture_formation/gesture/view_fusion.hpp"

using namespace gesture_formation::gesture;
using gesture_formation::common::ConfigReader;
namespace fm = gesture_formation::formation;

namespace {

GestureMapping read(const std::string& yaml, int followers, std::string* errors) {
  ConfigReader r = ConfigReader::fromString(yaml, "g.yaml", ConfigReader::MissingKeys::kUseDefaults);
  GestureMapping m = GestureMapping::paperDefault();
  readGestureMapping(r, 4, followers, m);
  *errors = r.errorReport();
  return m;
}

}  // namespace

TEST(GestureMappingTest, PaperDefault) {
  const GestureMapping m = GestureMapping::paperDefault();
  ASSERT_EQ(m.actions.size(), 4u);
  EXPECT_EQ(m.find(0), nullptr);
  const double inc[] = {-30.0, 30.0, -5.0, 5.0};
  for (int id = 1; id <= 4; ++id) {
    const GestureAction* a = m.find(id);
    ASSERT_NE(a, nullptr);
    EXPECT_EQ(a->kind, GestureAction::Kind::kParameter);
    EXPECT_EQ(a->target.group, fm::TargetGroup::kLeader);
    EXPECT_EQ(a->parameter, id <= 2 ? fm::Parameter::kBeta : fm::Parameter::kGamma);
    EXPECT_EQ(a->increment, inc[id - 1]);
  }
}

TEST(GestureMappingTest, ReadsDistanceTargetsAndEvents) {
  std::string errors;
  const GestureMapping m = read(
      "mapping:\n  1: {parameter: all.distance_m, increment: +1}\n  2: {parameter: followers.distance_m, increment: -1.5}\n"
      "  3: {event: assist_requested}\n  4: {parameter: follower2.beta_deg, increment: 15}\n",
      2, &errors);
  EXPECT_EQ(errors, "");
  ASSERT_EQ(m.actions.size(), 4u);
  EXPECT_EQ(m.find(1)->target.group, fm::TargetGroup::kAll);
  EXPECT_EQ(m.find(1)->parameter, fm::Parameter::kDistance);
  EXPECT_EQ(m.find(1)->increment, 1.0);
  EXPECT_EQ(m.find(2)->target.group, fm::TargetGroup::kFollowers);
  EXPECT_EQ(m.find(3)->kind, GestureAction::Kind::kEvent);
  EXPECT_EQ(m.find(3)->event, GestureEvent::kAssistRequested);
  EXPECT_EQ(m.find(4)->target.uavs, std::vector<fm::UavIndex>{2});
  EXPECT_EQ(m.find(4)->parameter_path, "follower2.beta_deg");
}

TEST(GestureMappingTest, MappingKeyReplacesDefaultsAsAWhole) {
  std::string errors;
  const GestureMapping m = read("mapping: {2: {event: abort}}", 2, &errors);
  EXPECT_EQ(errors, "");
  EXPECT_EQ(m.actions.size(), 1u);
  EXPECT_EQ(m.find(1), nullptr);
  EXPECT_EQ(m.find(2)->event, GestureEvent::kAbort);
}

TEST(GestureMappingTest, EveryProblemIsReported) {
  std::string errors;
  const GestureMapping m = read(
      "mapping:\n  0: {event: abort}\n  5: {event: abort}\n  1: {parameter: leader.roll_deg, increment: 1}\n"
      "  2: {parameter: follower3.beta_deg, increment: 1}\n  3: {parameter: leader.beta_deg}\n"
      "  4: {event: dance}\n",
      2, &errors);
  for (const char* key : {"mapping.0", "mapping.5", "mapping.1.parameter", "mapping.2.parameter", "mapping.3.increment",
                          "mapping.4.event"}) {
    EXPECT_NE(errors.find(key), std::string::npos) << key << " not in:\n" << errors;
  }
  EXPECT_EQ(m.actions.size(), 4u);  // untouched on error: still the paper's mapping
}

TEST(GestureMappingTest, ToCommandIsAGestureIncrement) {
  const auto c = toCommand(*GestureMapping::paperDefault().find(3), 42);
  EXPECT_EQ(c.id.sender, "gesture");
  EXPECT_EQ(c.id.sequence, 42u);
  EXPECT_EQ(c.source, fm::CommandSource::kGesture);
  EXPECT_EQ(c.kind, fm::CommandKind::kIncrement);
  EXPECT_EQ(c.parameter, fm::Parameter::kGamma);
  EXPECT_EQ(c.amount, -5.0);
}

TEST(GestureMappingTest, ShippedConfigIsThePapersAndComplete) {
  ConfigReader r = ConfigReader::fromFile(std::string(GF_SOURCE_DIR) + "/config/gestures.yaml",
                                          ConfigReader::MissingKeys::kError);
  const GestureFilterConfig fc = readGestureFilterConfig(r);
  GestureMapping m;
  readGestureMapping(r, fc.max_gesture_id, 2, m);
  const ViewFusionConfig vf = readViewFusionConfig(r);
  ASSERT_TRUE(r.ok()) << r.errorReport();
  EXPECT_TRUE(r.unusedKeys().empty());
  EXPECT_TRUE(vf.validate().empty());
  EXPECT_EQ(vf.min_agreeing_views, 2);
  EXPECT_EQ(fc.window_size, 20);
  EXPECT_EQ(m.actions.size(), 4u);
  EXPECT_EQ(m.find(2)->increment, 30.0);
  EXPECT_EQ(m.find(4)->parameter_path, "leader.gamma_deg");
}

TEST(GestureMappingTest, GestureToFormationEndToEnd) {
  // 20 × "raise an arm" → one command: leader γ 11° → 16°; the next one only after the cooldown
  // (the paper's re-arming: a held gesture fires every t_d).
  GestureFilterConfig paper;
  paper.rearm = RearmMode::kRepeat;
  GestureFilter filter(paper);
  auto state = fm::FormationState::create(fm::FormationParams{}, fm::FormationLimits{}).value();
  const GestureMapping m = GestureMapping::paperDefault();
  std::uint64_t seq = 0;
  for (int i = 0; i < 200; ++i) {
    const auto o = filter.update(0.1 * i, 4);
    if (o.fired) {
      ASSERT_EQ(state.apply(toCommand(*m.find(o.dominant_id), ++seq)).status, fm::CommandStatus::kApplied);
    }
  }
  EXPECT_EQ(seq, 4u);  // t = 1.9, 6.9, 11.9, 16.9
  EXPECT_EQ(state.params().leader.gamma_deg, 31.0);
}

// The simulator's assistance request (assistance_drill.hpp, docs/safety.md §2.10): the acting
// leader's formation::AssistanceLatch, the operator's scripted acknowledgements, their metrics and
// the configuration key.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "gesture_formation/sim/assistance_drill.hpp"
#include "gesture_formation/sim/mission_config.hpp"

namespace gf = gesture_formation;
using gf::formation::CommandSource;
using gf::sim::AssistanceDrill;

TEST(AssistanceDrillTest, GesturesRefusedWhilePendingOperatorPassesUntilTheAcknowledgement) {
  AssistanceDrill d({40.0});
  EXPECT_FALSE(d.refusal(CommandSource::kGesture));  // nothing pending: applied
  d.request(25.0);
  EXPECT_TRUE(d.pending());
  const auto why = d.refusal(CommandSource::kGesture);
  ASSERT_TRUE(why);
  EXPECT_NE(why->find("assistance requested at 25"), std::string::npos) << *why;
  EXPECT_FALSE(d.refusal(CommandSource::kOperator));
  d.request(30.0);             // the worker repeats the gesture: the first request's time is kept
  d.acknowledgeDue(39.9);      // not due yet
  EXPECT_TRUE(d.pending());
  EXPECT_TRUE(d.refusal(CommandSource::kGesture));
  d.acknowledgeDue(40.0);
  EXPECT_FALSE(d.pending());
  EXPECT_FALSE(d.refusal(CommandSource::kGesture));
  const auto s = d.summary();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->requested_s, std::vector<double>({25.0}));
  EXPECT_EQ(s->acknowledged_s, std::vector<double>({40.0}));
  EXPECT_EQ(s->repeats_while_pending, 1);
  EXPECT_EQ(s->gesture_commands_refused, 2);
  EXPECT_EQ(s->operator_commands_while_pending, 1);
  EXPECT_EQ(s->acks_without_request, 0);
  EXPECT_FALSE(s->pending_at_end);
  const std::string js = gf::sim::assistanceJson(*s, 2);
  EXPECT_NE(js.find("\"requested_s\": [25]"), std::string::npos) << js;
  EXPECT_NE(js.find("\"gesture_commands_refused\": 2"), std::string::npos) << js;
}

TEST(AssistanceDrillTest, AnAcknowledgementWithNothingPendingAndAHandOverChangeNothingElse) {
  AssistanceDrill d({10.0});
  d.acknowledgeDue(10.0);  // nothing pending: ignored, counted
  d.request(20.0);         // a later request is not released by that acknowledgement
  EXPECT_TRUE(d.pending());
  d.leaderChanged();       // the latch is the leader's: lost with it
  EXPECT_FALSE(d.pending());
  EXPECT_FALSE(d.refusal(CommandSource::kGesture));
  const auto s = d.summary();
  ASSERT_TRUE(s);
  EXPECT_EQ(s->acks_without_request, 1);
  EXPECT_EQ(s->requests_lost_at_handover, 1);
  EXPECT_TRUE(s->acknowledged_s.empty());
  EXPECT_FALSE(AssistanceDrill({}).summary());  // neither: no metrics.json `assistance`
}

TEST(AssistanceDrillTest, AcknowledgementTimesAreReadAndCheckedWithTheirKey) {
  const std::string path = std::string(GF_SOURCE_DIR) + "/config/scenarios/open_field.yaml";
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string base = ss.str();
  const std::string anchor = "mission:\n";
  ASSERT_NE(base.find(anchor), std::string::npos);
  const auto with = [&](const std::string& line) {
    std::string y = base;
    y.insert(y.find(anchor) + anchor.size(), line);
    return gf::sim::parseMissionConfig(y, "t.yaml", std::string(GF_SOURCE_DIR) + "/config/scenarios");
  };
  const auto ok = with("  assistance_acks_s: [37, 80.5]\n");
  ASSERT_TRUE(ok) << ok.reason();
  EXPECT_EQ(ok->assistance_acks_s, std::vector<double>({37.0, 80.5}));
  const auto none = with("");
  ASSERT_TRUE(none) << none.reason();
  EXPECT_TRUE(none->assistance_acks_s.empty());
  const auto order = with("  assistance_acks_s: [37, 20]\n");
  ASSERT_FALSE(order);
  EXPECT_NE(order.reason().find("mission.assistance_acks_s[1]"), std::string::npos) << order.reason();
  EXPECT_NE(order.reason().find("20"), std::string::npos) << order.reason();
  const auto negative = with("  assistance_acks_s: [-1]\n");
  ASSERT_FALSE(negative);
  EXPECT_NE(negative.reason().find("mission.assistance_acks_s"), std::string::npos) << negative.reason();
}

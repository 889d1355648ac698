// comm::verifierConfigOf (docs/security.md §4, §7): the link's settings as the LcmBridge gets
// them, every problem reported at once, and the VerifierConfig the bridge runs with.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "gesture_formation/comm/link_settings.hpp"

using namespace gesture_formation::comm;
using gesture_formation::common::ConfigError;

namespace {

bool names(const std::vector<ConfigError>& problems, const std::string& key) {
  return std::any_of(problems.begin(), problems.end(), [&](const ConfigError& e) {
    return e.key.find(key) != std::string::npos || e.message.find(key) != std::string::npos;
  });
}

}  // namespace

TEST(LinkSettingsTest, AGoodSettingGivesTheBridgesVerifier) {
  LinkSettings s;
  s.sender_id = 2;
  s.known_senders = {0, 1, 2, 100};
  s.max_age_s = 1.0;
  s.command_senders = std::vector<int>{100};
  s.params_senders = std::vector<int>{0, 2};  // own id: never received, dropped
  std::vector<ConfigError> problems;
  const VerifierConfig c = verifierConfigOf(s, problems);
  EXPECT_TRUE(problems.empty()) << problems.front().key << ": " << problems.front().message;
  EXPECT_EQ(c.known_senders, (std::vector<std::uint16_t>{0, 1, 100}));
  EXPECT_EQ(c.own_sender_id, 2);
  EXPECT_EQ(c.senders_by_type.at(MessageType::kFormationCommand), (std::vector<std::uint16_t>{100}));
  EXPECT_EQ(c.senders_by_type.at(MessageType::kFormationParams), (std::vector<std::uint16_t>{0}));
  EXPECT_DOUBLE_EQ(c.max_age_s_by_type.at(MessageType::kHeartbeat), 2.0);
  EXPECT_DOUBLE_EQ(c.max_age_s_by_type.at(MessageType::kFormationCommand), 5.0);
  EXPECT_DOUBLE_EQ(c.max_age_s_by_type.at(MessageType::kAbortCommand), 5.0);
  EXPECT_EQ(c.senders_by_type.count(MessageType::kAbortCommand), 0u);  // absent: any known sender
}

// Acknowledgements come from the parameter owner: the params_senders, with the command age limit.
TEST(LinkSettingsTest, AcknowledgementsComeFromTheParamsSenders) {
  LinkSettings s;
  s.sender_id = 100;
  s.known_senders = {0, 1, 2, 100};
  s.command_max_age_s = 4.0;
  s.params_senders = std::vector<int>{0};
  std::vector<ConfigError> problems;
  const VerifierConfig c = verifierConfigOf(s, problems);
  EXPECT_TRUE(problems.empty());
  EXPECT_EQ(c.senders_by_type.at(MessageType::kCommandAck), (std::vector<std::uint16_t>{0}));
  EXPECT_DOUBLE_EQ(c.max_age_s_by_type.at(MessageType::kCommandAck), 4.0);
  EXPECT_EQ(c.senders_by_type.count(MessageType::kAssistance), 0u);  // command senders absent: any known sender
  // The assistance state: the parameter owner (the request) and the command senders (the operator's acknowledgement).
  // (Own id 100 is never received: dropped from every list.)
  s.command_senders = std::vector<int>{100, 2};
  const VerifierConfig both = verifierConfigOf(s, problems);
  EXPECT_EQ(both.senders_by_type.at(MessageType::kAssistance), (std::vector<std::uint16_t>{0, 2}));
  s.command_senders.reset();
  s.params_senders.reset();
  EXPECT_EQ(verifierConfigOf(s, problems).senders_by_type.count(MessageType::kCommandAck), 0u);  // any known sender
}

// Leadership messages come from the UAVs only: the known senders with a UAV index, never the ground
// station (own id dropped as for every list).
TEST(LinkSettingsTest, LeadershipMessagesComeFromTheKnownUavsOnly) {
  LinkSettings s;
  s.sender_id = 1;
  s.known_senders = {0, 1, 2, 100};
  std::vector<ConfigError> problems;
  const VerifierConfig c = verifierConfigOf(s, problems);
  EXPECT_TRUE(problems.empty());
  EXPECT_EQ(c.senders_by_type.at(MessageType::kLeadership), (std::vector<std::uint16_t>{0, 2}));
}

// Live-map changes likewise: a ground station's map update is refused by the verifier.
TEST(LinkSettingsTest, MapUpdatesComeFromTheKnownUavsOnly) {
  LinkSettings s;
  s.sender_id = 0;
  s.known_senders = {0, 1, 2, 100};
  std::vector<ConfigError> problems;
  const VerifierConfig c = verifierConfigOf(s, problems);
  EXPECT_TRUE(problems.empty());
  EXPECT_EQ(c.senders_by_type.at(MessageType::kMapUpdate), (std::vector<std::uint16_t>{1, 2}));
}

// Aborts come from the ground station and the UAVs' relay: their own sender list.
TEST(LinkSettingsTest, AbortSendersAreTheirOwnList) {
  LinkSettings s;
  s.sender_id = 1;
  s.known_senders = {0, 1, 2, 100};
  s.command_max_age_s = 3.0;
  s.abort_senders = std::vector<int>{0, 100};
  std::vector<ConfigError> problems;
  const VerifierConfig c = verifierConfigOf(s, problems);
  EXPECT_TRUE(problems.empty());
  EXPECT_EQ(c.senders_by_type.at(MessageType::kAbortCommand), (std::vector<std::uint16_t>{0, 100}));
  EXPECT_DOUBLE_EQ(c.max_age_s_by_type.at(MessageType::kAbortCommand), 3.0);
  s.abort_senders = std::vector<int>{};
  problems.clear();
  verifierConfigOf(s, problems);
  EXPECT_TRUE(names(problems, "abort_senders"));
  EXPECT_NE(describeOptional(s).find("abort_senders: 0 id(s)"), std::string::npos) << describeOptional(s);
}

// Every field is checked, and the verifier's own rules run too (no known sender), in one pass.
TEST(LinkSettingsTest, EveryProblemAtOnce) {
  LinkSettings s;
  s.sender_id = 70000;
  s.known_senders = {};
  s.command_max_age_s = 0.0;
  s.recv_buf_bytes = 100;
  s.command_senders = std::vector<int>{};
  s.params_senders = std::vector<int>{-1};
  std::vector<ConfigError> problems;
  verifierConfigOf(s, problems);
  for (const char* key : {"sender_id", "command_max_age_s", "recv_buf_bytes", "command_senders", "params_senders",
                          "known_senders"}) {
    EXPECT_TRUE(names(problems, key)) << key << " not reported";
  }
  EXPECT_GE(problems.size(), 6u);
}

TEST(LinkSettingsTest, ReceiveBufferIsAddedToMulticastUrlsOnly) {
  EXPECT_EQ(withReceiveBuffer("udpm://239.255.76.67:7667?ttl=0", 4194304),
            "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304");
  EXPECT_EQ(withReceiveBuffer("udpm://239.255.76.67:7667", 65536), "udpm://239.255.76.67:7667?recv_buf_size=65536");
  EXPECT_EQ(withReceiveBuffer("udpm://239.255.76.67:7667?recv_buf_size=1000", 4194304),
            "udpm://239.255.76.67:7667?recv_buf_size=1000");  // the user's own value wins
  EXPECT_EQ(withReceiveBuffer("memq://", 4194304), "memq://");
}

// LCM glue (gesture_formation_lcm) on memq:// only: in-process, no network traffic.
#include <gtest/gtest.h>

#include <vector>

#include "../comm_test_util.hpp"
#include "gesture_formation/comm/payloads.hpp"
#include "gesture_formation/lcm_bridge/lcm_transport.hpp"

using namespace gesture_formation;
using namespace gesture_formation::lcm_bridge;
namespace t = gesture_formation::comm::testing;

namespace {

comm::Verifier verifier(std::vector<std::uint16_t> senders) {
  comm::VerifierConfig c;
  c.known_senders = std::move(senders);
  auto v = comm::Verifier::create(c, t::ring({t::keyEntry(1, 10)}, 1));
  EXPECT_TRUE(v) << v.reason();
  return std::move(v.value());
}

std::unique_ptr<LcmTransport> memq() {
  auto tr = LcmTransport::create("memq://");
  EXPECT_TRUE(tr) << tr.reason();
  return std::move(tr.value());
}

}  // namespace

TEST(CommLcmTransportTest, ChannelNamesRoundTrip) {
  for (std::uint8_t k = comm::kMinMessageType; k <= comm::kMaxMessageType; ++k) {
    const auto type = static_cast<comm::MessageType>(k);
    const std::string name = channelName(type, "GF_");
    EXPECT_EQ(channelType(name, "GF_"), type) << name;
  }
  EXPECT_EQ(channelName(comm::MessageType::kPlannedTrajectory, "UAV_"), "UAV_PLANNED_TRAJECTORY");
  EXPECT_FALSE(channelType("GF_POSE", "GF_"));
  EXPECT_FALSE(channelType("XX_HEARTBEAT", "GF_"));
}

TEST(CommLcmTransportTest, LcmEnvelopeCodecChecksLengthBeforeDecoding) {
  const std::vector<std::uint8_t> sealed(100, 0xAB);
  const auto enc = encodeLcmEnvelope(sealed);
  ASSERT_EQ(enc.size(), 12 + sealed.size());
  std::vector<std::uint8_t> out;
  ASSERT_TRUE(decodeLcmEnvelope(enc.data(), enc.size(), out));
  EXPECT_EQ(out, sealed);
  auto bad = enc;
  bad[8] = 0xFF;  // negative length: lcm-gen's decoder would resize to it
  out.clear();
  EXPECT_FALSE(decodeLcmEnvelope(bad.data(), bad.size(), out));
  EXPECT_TRUE(out.empty());
  bad = enc;
  bad[11] = 101;  // longer than the buffer
  EXPECT_FALSE(decodeLcmEnvelope(bad.data(), bad.size(), out));
  bad = enc;
  bad[0] ^= 1;  // fingerprint
  EXPECT_FALSE(decodeLcmEnvelope(bad.data(), bad.size(), out));
  EXPECT_FALSE(decodeLcmEnvelope(enc.data(), 11, out));
  EXPECT_FALSE(decodeLcmEnvelope(nullptr, 0, out));
  EXPECT_TRUE(encodeLcmEnvelope(std::vector<std::uint8_t>(comm::kMaxEnvelopeBytes + 1)).empty());
}

TEST(CommLcmTransportTest, RefusesABadUrl) {
  auto tr = LcmTransport::create("nosuchprovider://");
  ASSERT_FALSE(tr);
  EXPECT_NE(tr.reason().find("nosuchprovider://"), std::string::npos);
}

// memq:// (in-process: tests, the simulator's links) subscribes to every message type's channel —
// it listed all but leadership and map updates, which in-process links then never received.
TEST(CommLcmTransportTest, MemqReceivesEveryMessageType) {
  auto tr = memq();
  int received = 0;
  tr->setHandler([&](comm::MessageType, const std::vector<std::uint8_t>&) { ++received; });
  for (int type = 1; type <= comm::kMaxMessageType; ++type) {
    ASSERT_TRUE(tr->publish(static_cast<comm::MessageType>(type), {1, 2, 3})) << type;
    EXPECT_EQ(tr->drain(), 1) << comm::toString(static_cast<comm::MessageType>(type));
  }
  EXPECT_EQ(received, comm::kMaxMessageType);
}

TEST(CommLcmTransportTest, SecureLinkCarriesAPlannedTrajectoryOverMemq) {
  auto tr = memq();
  double now = 10.0;
  SecureLink link(*tr, comm::Signer(1, t::ring({t::keyEntry(1, 10)}, 1), 1), verifier({1}), [&now] { return now; });
  std::vector<comm::Envelope> received;
  link.setHandler([&](const comm::Envelope& e) { received.push_back(e); });

  comm::PlanMessage plan;
  plan.plan.uav_index = 1;
  plan.plan.sequence = 5;
  plan.plan.t0_s = 10.0;
  plan.plan.samples.resize(40);
  plan.plan.samples[7].p_world = {1, 2, 3};
  auto seq = link.publish(plan);
  ASSERT_TRUE(seq) << seq.reason();
  EXPECT_EQ(seq.value(), 1u);
  EXPECT_EQ(tr->drain(), 1);
  ASSERT_EQ(received.size(), 1u);
  EXPECT_EQ(received[0].type, comm::MessageType::kPlannedTrajectory);
  comm::PayloadDecoder decoder;
  comm::PlanMessage got;
  ASSERT_TRUE(decoder.decode(received[0], got)) << decoder.lastReason();
  EXPECT_EQ(got.plan.samples.size(), 40u);
  EXPECT_EQ(got.plan.samples[7].p_world, plan.plan.samples[7].p_world);

  comm::Heartbeat hb;
  ASSERT_TRUE(link.publish(hb));
  EXPECT_EQ(tr->drain(), 1);
  EXPECT_EQ(received.size(), 2u);
  EXPECT_EQ(link.verifierCounters().accepted(), 2u);
  EXPECT_EQ(tr->counters().published, 2u);
}

TEST(CommLcmTransportTest, ForgedReplayedAndMisroutedEnvelopesAreDroppedAndCounted) {
  auto tr = memq();
  double now = 10.0;
  SecureLink link(*tr, comm::Signer(1, t::ring({t::keyEntry(1, 10)}, 1), 1), verifier({1, 2}), [&now] { return now; });
  int delivered = 0;
  link.setHandler([&](const comm::Envelope&) { ++delivered; });

  comm::Signer honest(2, t::ring({t::keyEntry(1, 10)}, 1), 1);
  comm::Signer mallory(2, t::ring({t::keyEntry(1, 66)}, 1), 100);
  const auto good = honest.seal(comm::MessageType::kFormationCommand, {1}, now).value();
  ASSERT_TRUE(tr->publish(comm::MessageType::kFormationCommand, good));
  ASSERT_TRUE(tr->publish(comm::MessageType::kFormationCommand, good));  // replay
  ASSERT_TRUE(tr->publish(comm::MessageType::kFormationCommand, mallory.seal(comm::MessageType::kFormationCommand, {1}, now).value()));
  ASSERT_TRUE(tr->publish(comm::MessageType::kHeartbeat, honest.seal(comm::MessageType::kFormationCommand, {2}, now).value()));
  ASSERT_TRUE(tr->publish(comm::MessageType::kHeartbeat, std::vector<std::uint8_t>(10, 0)));  // garbage envelope
  EXPECT_EQ(tr->drain(), 5);
  EXPECT_EQ(delivered, 1);
  EXPECT_EQ(link.verifierCounters().accepted(), 1u);
  EXPECT_EQ(link.verifierCounters().count(comm::Verdict::kReplayed), 1u);
  EXPECT_EQ(link.verifierCounters().count(comm::Verdict::kForged), 1u);
  EXPECT_EQ(link.verifierCounters().count(comm::Verdict::kTruncated), 1u);
  EXPECT_EQ(link.channelMismatches(), 1u);
  // The misrouted envelope did not consume its sequence: sent on its own channel it is accepted.
  const auto later = honest.seal(comm::MessageType::kHeartbeat, {}, now).value();
  ASSERT_TRUE(tr->publish(comm::MessageType::kHeartbeat, later));
  EXPECT_EQ(tr->drain(), 1);
  EXPECT_EQ(delivered, 2);
}

// The udpm:// receive path reads datagrams itself: an LCM short message is "LC02", a 32-bit
// sequence number, the channel and a NUL, then the message; anything else is refused.
TEST(CommLcmTransportTest, ParsesLcmShortMessageDatagramsOnly) {
  const std::string channel = "GF_WORKER_STATE";
  std::vector<std::uint8_t> d{'L', 'C', '0', '2', 0, 0, 0, 7};
  d.insert(d.end(), channel.begin(), channel.end());
  d.push_back(0);
  const std::vector<std::uint8_t> message{1, 2, 3, 4, 5};
  d.insert(d.end(), message.begin(), message.end());
  LcmDatagram out;
  ASSERT_TRUE(parseLcmDatagram(d.data(), d.size(), out));
  EXPECT_EQ(out.channel, channel);
  ASSERT_EQ(out.size, message.size());
  EXPECT_EQ(std::vector<std::uint8_t>(out.data, out.data + out.size), message);

  auto fragment = d;
  fragment[3] = '3';  // LC03: a fragment of a large message (ours never are)
  EXPECT_FALSE(parseLcmDatagram(fragment.data(), fragment.size(), out));
  std::vector<std::uint8_t> no_nul{'L', 'C', '0', '2', 0, 0, 0, 1};
  no_nul.insert(no_nul.end(), 80, 'A');  // a channel longer than LCM allows, never terminated
  EXPECT_FALSE(parseLcmDatagram(no_nul.data(), no_nul.size(), out));
  EXPECT_FALSE(parseLcmDatagram(d.data(), 8, out));  // header only
  EXPECT_FALSE(parseLcmDatagram(nullptr, 0, out));
  // An empty message on a channel is still a datagram (the envelope decoder refuses it later).
  std::vector<std::uint8_t> empty{'L', 'C', '0', '2', 0, 0, 0, 2, 'G', 0};
  ASSERT_TRUE(parseLcmDatagram(empty.data(), empty.size(), out));
  EXPECT_EQ(out.channel, "G");
  EXPECT_EQ(out.size, 0u);
}

TEST(CommLcmTransportTest, RefusesAnUnparsableUdpmUrl) {
  const auto t = LcmTransport::create("udpm://not-an-address:7667");
  ASSERT_FALSE(t);
  EXPECT_NE(t.reason().find("udpm://not-an-address:7667"), std::string::npos) << t.reason();
}

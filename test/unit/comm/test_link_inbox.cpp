// comm::LinkInbox (the receive side of a node's link) and comm::OutgoingRepeats (the sender's
// copies of single events): what each envelope yields, and when each copy falls due.
#include <gtest/gtest.h>

#include <variant>

#include "gesture_formation/comm/link_inbox.hpp"
#include "gesture_formation/comm/outgoing_repeats.hpp"

using namespace gesture_formation;
using namespace gesture_formation::comm;

namespace {

template <class T>
Envelope envelopeOf(const T& message, std::uint16_t sender, double stamp_s = 10.0) {
  Envelope e;
  e.type = messageTypeOf(message);
  e.sender_id = sender;
  e.stamp_s = stamp_s;
  auto payload = encodePayload(message);
  EXPECT_TRUE(payload) << payload.reason();
  if (payload) e.payload = payload.value();
  return e;
}

planning::PlannedTrajectory plan(std::uint32_t sequence) {
  planning::PlannedTrajectory p;
  p.sequence = sequence;
  p.t0_s = 10.0;
  p.dt_s = 0.1;
  p.samples.resize(3);
  return p;
}

}  // namespace

TEST(LinkInboxTest, APlanIsAFallbackOnlyWhenTheDegradedHeartbeatBeforeItNamedIt) {
  LinkInbox inbox;
  auto item = inbox.take(envelopeOf(plan(5), 1));
  ASSERT_TRUE(std::holds_alternative<ReceivedPlanMessage>(item));
  EXPECT_FALSE(std::get<ReceivedPlanMessage>(item).fallback);  // no heartbeat yet

  Heartbeat h;
  h.uav_index = 1;
  h.status = Heartbeat::Status::kDegraded;
  h.last_plan_sequence = 6;
  EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(envelopeOf(h, 1))));
  item = inbox.take(envelopeOf(plan(6), 1));
  EXPECT_TRUE(std::get<ReceivedPlanMessage>(item).fallback);
  item = inbox.take(envelopeOf(plan(7), 1));  // a later plan: not the one the heartbeat named
  EXPECT_FALSE(std::get<ReceivedPlanMessage>(item).fallback);
  item = inbox.take(envelopeOf(plan(6), 2));  // another sender's heartbeat state is its own
  EXPECT_FALSE(std::get<ReceivedPlanMessage>(item).fallback);
}

TEST(LinkInboxTest, CommandsForwardOnceWithTheNameBoundToTheSender) {
  LinkInbox inbox;
  formation::FormationCommand c;
  c.id = {"gcs", 3};
  c.target.group = formation::TargetGroup::kAll;
  const auto first = inbox.take(envelopeOf(c, 100));
  ASSERT_TRUE(std::holds_alternative<formation::FormationCommand>(first));
  EXPECT_EQ(std::get<formation::FormationCommand>(first).id.sender, "gcs@100");
  EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(envelopeOf(c, 100))));
  EXPECT_EQ(inbox.commandCopiesDropped(), 1u);
  EXPECT_TRUE(inbox.lastRefusal().empty());  // a copy is not a refusal
}

TEST(LinkInboxTest, ObservationsOfAnotherCameraOrWithABadTimeAreRefused) {
  LinkInbox inbox;
  GestureObservationMessage o;
  o.uav_index = 2;
  o.t_s = 12.0;
  o.probabilities = {0.5, 0.5};
  EXPECT_TRUE(std::holds_alternative<GestureObservationMessage>(inbox.take(envelopeOf(o, 2))));
  EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(envelopeOf(o, 1))));
  EXPECT_EQ(inbox.observationsRefused(), 1u);
  EXPECT_NE(inbox.lastRefusal().find("gesture observation refused (1 so far): sender 1, uav_index 2"), std::string::npos)
      << inbox.lastRefusal();
  EXPECT_FALSE(inbox.lastWasDecodeFailure());
  o.t_s = 5.0e9;  // not a ROS time
  EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(envelopeOf(o, 2))));
  EXPECT_EQ(inbox.observationsRefused(), 2u);
}

TEST(LinkInboxTest, EveryAbortCopyIsHandedOnStampedWithItsEnvelope) {
  LinkInbox inbox;
  AbortMessage a;
  a.id = {"operator", 9};
  for (const double stamp : {20.0, 20.2}) {
    const auto item = inbox.take(envelopeOf(a, 100, stamp));
    ASSERT_TRUE(std::holds_alternative<planning::AbortCommand>(item));
    const auto& c = std::get<planning::AbortCommand>(item);
    EXPECT_EQ(c.id.sender, "operator");
    EXPECT_EQ(c.id.sequence, 9u);
    EXPECT_EQ(c.source, planning::AbortSource::kOperator);
    EXPECT_EQ(c.sent_s, stamp);
  }
}

// A leadership message speaks for its sender only: `from` must be the envelope's sender; every
// copy is handed on (the election tolerates duplicates).
TEST(LinkInboxTest, ALeadershipMessageIsHandedOnOnlyFromItsOwnSender) {
  LinkInbox inbox;
  formation::LeadershipMessage m;
  m.kind = formation::LeadershipMessageKind::kHeartbeat;
  m.term = 2;
  m.from = 1;
  m.sent_s = 5.0;
  for (int copy = 0; copy < 2; ++copy) {
    const auto item = inbox.take(envelopeOf(m, 1));
    ASSERT_TRUE(std::holds_alternative<formation::LeadershipMessage>(item));
    EXPECT_EQ(std::get<formation::LeadershipMessage>(item).term, 2u);
  }
  const auto forged = inbox.take(envelopeOf(m, 2));  // UAV 2's key speaking for UAV 1
  EXPECT_TRUE(std::holds_alternative<std::monostate>(forged));
  EXPECT_EQ(inbox.leadershipRefused(), 1u);
  EXPECT_NE(inbox.lastRefusal().find("leadership message refused"), std::string::npos) << inbox.lastRefusal();
}

TEST(LinkInboxTest, AnAcknowledgementIsHandedOnOncePerCommandId) {
  LinkInbox inbox;
  CommandAckMessage a;
  a.id = {"operator@100", 41};
  a.status = formation::CommandStatus::kApplied;
  a.params_version = 3;
  a.outcome = "applied";
  const auto first = inbox.take(envelopeOf(a, 0, 20.0));
  ASSERT_TRUE(std::holds_alternative<CommandAckMessage>(first));
  EXPECT_EQ(std::get<CommandAckMessage>(first).params_version, 3u);
  EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(envelopeOf(a, 0, 20.1))));  // the leader's repeat
  a.id.sequence = 42;
  EXPECT_TRUE(std::holds_alternative<CommandAckMessage>(inbox.take(envelopeOf(a, 0, 20.2))));
  // The memory is bounded: after 256 other ids the first is forgotten (handed on again).
  for (std::uint64_t s = 100; s < 100 + 256; ++s) {
    a.id.sequence = s;
    inbox.take(envelopeOf(a, 0, 21.0));
  }
  a.id.sequence = 41;
  EXPECT_TRUE(std::holds_alternative<CommandAckMessage>(inbox.take(envelopeOf(a, 0, 22.0))));
  a.id.sequence = 100 + 255;
  EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(envelopeOf(a, 0, 22.1))));  // still remembered
}

TEST(LinkInboxTest, AnUndecodablePayloadIsADecodeFailureNamingTheField) {
  LinkInbox inbox;
  Envelope e = envelopeOf(plan(1), 1);
  e.payload.resize(e.payload.size() - 1);
  EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(e)));
  EXPECT_TRUE(inbox.lastWasDecodeFailure());
  EXPECT_NE(inbox.lastRefusal().find("decode_failure"), std::string::npos) << inbox.lastRefusal();
  EXPECT_EQ(inbox.payloadCounters().rejected(), 1u);
  // The next good envelope clears it.
  EXPECT_TRUE(std::holds_alternative<ReceivedPlanMessage>(inbox.take(envelopeOf(plan(2), 1))));
  EXPECT_FALSE(inbox.lastWasDecodeFailure());
  EXPECT_TRUE(inbox.lastRefusal().empty());
}

TEST(OutgoingRepeatsTest, EachCopyFallsDueOncePeriodApart) {
  OutgoingRepeats r;
  r.add(OutgoingPayload{MessageType::kFormationCommand, {1}}, 3, 0.1, 10.0);  // first sent at 10.0
  r.add(OutgoingPayload{MessageType::kHeartbeat, {2}}, 1, 0.1, 10.0);          // nothing to repeat
  EXPECT_EQ(r.pending(), 1u);
  EXPECT_TRUE(r.due(10.05).empty());
  auto d = r.due(10.1);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].payload, std::vector<std::uint8_t>{1});
  EXPECT_TRUE(r.due(10.15).empty());
  EXPECT_EQ(r.due(10.2).size(), 1u);
  EXPECT_EQ(r.pending(), 0u);
  EXPECT_TRUE(r.due(11.0).empty());
}

TEST(OutgoingRepeatsTest, ALateCallGetsEveryOverdueEventOnceAndKeepsTheirPeriods) {
  OutgoingRepeats r;
  r.add(OutgoingPayload{MessageType::kFormationCommand, {1}}, 5, 0.1, 0.0);
  r.add(OutgoingPayload{MessageType::kFormationCommand, {2}}, 2, 0.2, 0.0);
  const auto d = r.due(0.25);  // both overdue: one copy each per call
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].payload[0], 1);
  EXPECT_EQ(d[1].payload[0], 2);
  EXPECT_EQ(r.pending(), 1u);  // the second had one copy to repeat
  EXPECT_EQ(r.due(0.25).size(), 1u);  // the first's next copy was due at 0.2
}

// comm::LinkInbox (the receive side of a node's link) and comm::OutgoingRepeats (the sender's
// copies of single events), comm::AbortCopySchedule (the ground station's abort copies): what each
// envelope yields, and when each copy falls due.
#include <gtest/gtest.h>

#include <cstring>
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

PlanMessage plan(std::uint32_t sequence, int uav = 1, bool fallback = false) {
  PlanMessage m;
  m.plan.uav_index = uav;
  m.plan.sequence = sequence;
  m.plan.t0_s = 10.0;
  m.plan.dt_s = 0.1;
  m.plan.samples.resize(3);
  m.fallback = fallback;
  return m;
}

}  // namespace

// The fallback flag travels with the plan: with avoid_all_plans false a receiver avoids a
// lower-priority UAV's plan only when it is a fallback, so it must not depend on a heartbeat that
// can be lost or reordered (before, the flag was read from the heartbeat sent just before).
TEST(LinkInboxTest, APlansFallbackFlagIsItsOwnWhateverTheHeartbeats) {
  LinkInbox inbox;
  auto item = inbox.take(envelopeOf(plan(5, 1, true), 1));  // no heartbeat at all (lost)
  ASSERT_TRUE(std::holds_alternative<PlanMessage>(item));
  EXPECT_TRUE(std::get<PlanMessage>(item).fallback);
  EXPECT_EQ(std::get<PlanMessage>(item).plan.sequence, 5u);

  Heartbeat h;  // a late heartbeat of the sender, degraded and naming the next plan
  h.uav_index = 1;
  h.status = Heartbeat::Status::kDegraded;
  h.last_plan_sequence = 6;
  EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(envelopeOf(h, 1))));
  item = inbox.take(envelopeOf(plan(6, 1, false), 1));
  EXPECT_FALSE(std::get<PlanMessage>(item).fallback);
  item = inbox.take(envelopeOf(plan(7, 1, true), 1));
  EXPECT_TRUE(std::get<PlanMessage>(item).fallback);
}

// A holder of UAV 2's key must not speak for the leader: a plan claiming UAV 0 from sender 2 would
// be the leader's plan at every receiver (avoided instead of the real one, shaping the followers'
// references). Nor may a plan start after it was sent: receivers keep the newest t0, so a t0 an
// hour ahead would outrank every real plan of that UAV.
TEST(LinkInboxTest, APlanOfAnotherUavOrStartingAfterItsEnvelopeIsRefused) {
  LinkInbox inbox;
  EXPECT_TRUE(std::holds_alternative<PlanMessage>(inbox.take(envelopeOf(plan(1, 2), 2, 10.0))));
  EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(envelopeOf(plan(2, 0), 2, 10.0))));
  EXPECT_EQ(inbox.plansRefused(), 1u);
  EXPECT_NE(inbox.lastRefusal().find("plan refused (1 so far): sender 2, uav_index 0"), std::string::npos)
      << inbox.lastRefusal();
  PlanMessage future = plan(3, 2);
  future.plan.t0_s = 10.0 + 3600.0;
  EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(envelopeOf(future, 2, 10.0))));
  EXPECT_EQ(inbox.plansRefused(), 2u);
  EXPECT_NE(inbox.lastRefusal().find("t0 3610 s, envelope stamp 10 s"), std::string::npos) << inbox.lastRefusal();
  future.plan.t0_s = 10.05;  // a clock tick ahead of the bridge's stamp (separate processes on /clock): accepted
  EXPECT_TRUE(std::holds_alternative<PlanMessage>(inbox.take(envelopeOf(future, 2, 10.0))));
  EXPECT_EQ(inbox.plansRefused(), 2u);
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
}

namespace {

/// `e` with the big-endian double at payload byte `offset` replaced by `value`.
Envelope withDoubleAt(Envelope e, std::size_t offset, double value) {
  std::uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  for (int i = 0; i < 8; ++i) e.payload.at(offset + static_cast<std::size_t>(i)) = static_cast<std::uint8_t>(bits >> (56 - 8 * i));
  return e;
}

}  // namespace

// Every time a receiver turns into ros::Time (which throws outside [0, 2^32) s, and a throw in the
// bridge's timer ends the whole nodelet manager) is a wire time: an authenticated payload with a
// negative or too large one is a decode failure naming the field, and no encoder writes one.
TEST(LinkInboxTest, TimesOutsideTheWireRangeAreDecodeFailuresNamingTheField) {
  WorkerStateMessage w;
  w.t_s = 12.0;
  w.last_fused_t_s = 0.0;  // ≤ t_s whatever t_s is patched to below
  GestureObservationMessage o;
  o.uav_index = 2;
  o.t_s = 12.0;
  o.probabilities = {0.5, 0.5};
  CommandAckMessage a;
  a.id = {"op@100", 4};
  a.command_stamp_s = 12.0;
  AssistanceMessage s;
  s.state.requested_s = 12.0;
  s.state.acknowledged_s = 12.0;
  struct Case {
    Envelope e;
    std::size_t offset;
    const char* field;
  };
  const std::vector<Case> cases{
      {envelopeOf(w, 0), 0, "worker_state.t_s"},
      {envelopeOf(w, 0), 8, "worker_state.last_fused_t_s"},
      {envelopeOf(plan(3), 1), 7, "planned_trajectory.t0_s"},
      {envelopeOf(o, 2), 2, "gesture_observation.t_s"},
      {envelopeOf(a, 0), 1 + 6 + 8 + 1 + 1 + 8, "command_ack.command_stamp_s"},
      {envelopeOf(s, 0), 1, "assistance.requested_s"},
  };
  for (const Case& c : cases) {
    LinkInbox inbox;
    ASSERT_FALSE(std::holds_alternative<std::monostate>(inbox.take(c.e))) << c.field << ": the unpatched payload";
    for (const double bad : {-1.0, -1e-9, 5.0e9, kMaxWireTimeS}) {
      EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(withDoubleAt(c.e, c.offset, bad)))) << c.field << " = " << bad;
      EXPECT_TRUE(inbox.lastWasDecodeFailure()) << c.field << " = " << bad;
      EXPECT_NE(inbox.lastRefusal().find(std::string("out_of_range: ") + c.field), std::string::npos) << inbox.lastRefusal();
    }
    LinkInbox fresh;  // (the first take above made an acknowledgement's copies repeats)
    EXPECT_FALSE(std::holds_alternative<std::monostate>(fresh.take(withDoubleAt(c.e, c.offset, 0.0)))) << c.field << " = 0";
  }
  // The encoders refuse the same, naming the field and the value.
  w.t_s = -1.0;
  auto bytes = encodePayload(w);
  ASSERT_FALSE(bytes);
  EXPECT_NE(bytes.reason().find("worker_state.t_s must be a time in [0, 4e9) s, got -1"), std::string::npos) << bytes.reason();
  s.state.acknowledged_s = 5.0e9;
  bytes = encodePayload(s);
  ASSERT_FALSE(bytes);
  EXPECT_NE(bytes.reason().find("assistance.acknowledged_s"), std::string::npos) << bytes.reason();
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

// An acknowledgement is a repeat only of the same link sender's: another member sending an ack of
// the same command id first (a captured follower) does not silence the leader's.
TEST(LinkInboxTest, AnotherSendersAcknowledgementDoesNotSilenceTheLeaders) {
  LinkInbox inbox;
  CommandAckMessage forged;
  forged.id = {"operator@100", 7};
  forged.status = formation::CommandStatus::kRejected;
  ASSERT_TRUE(std::holds_alternative<CommandAckMessage>(inbox.take(envelopeOf(forged, 2, 30.0))));
  CommandAckMessage real = forged;
  real.status = formation::CommandStatus::kApplied;
  const auto item = inbox.take(envelopeOf(real, 0, 30.1));
  ASSERT_TRUE(std::holds_alternative<CommandAckMessage>(item));
  EXPECT_EQ(std::get<CommandAckMessage>(item).status, formation::CommandStatus::kApplied);
  EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(envelopeOf(real, 0, 30.2))));  // the leader's own repeat
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
  EXPECT_TRUE(std::holds_alternative<PlanMessage>(inbox.take(envelopeOf(plan(2), 1))));
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

// Map updates come through the inbox like every payload (before, the LcmBridge nodelet decoded them
// itself): handed on when the UAV speaks for its own map, refused and counted when it speaks for
// another's, a decode failure naming the field when the payload is broken.
TEST(LinkInboxTest, AMapUpdateIsHandedOnOnlyFromItsOwnUav) {
  MapUpdate u;
  u.uav_index = 2;
  u.sequence = 4;
  u.delta.stamp_s = 9.5;
  u.delta.resolution_m = 0.2;
  u.delta.occupied = {{32768, 32769, 32770}};
  LinkInbox inbox;
  auto item = inbox.take(envelopeOf(u, 2));
  ASSERT_TRUE(std::holds_alternative<MapUpdate>(item)) << inbox.lastRefusal();
  EXPECT_EQ(std::get<MapUpdate>(item).sequence, 4u);
  EXPECT_EQ(std::get<MapUpdate>(item).delta.occupied, u.delta.occupied);
  EXPECT_EQ(inbox.mapUpdatesRefused(), 0u);

  EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(envelopeOf(u, 1))));  // sender 1 for UAV 2's map
  EXPECT_EQ(inbox.mapUpdatesRefused(), 1u);
  EXPECT_FALSE(inbox.lastWasDecodeFailure());
  EXPECT_EQ(inbox.lastRefusal(), "map update refused (1 so far): sender 1, uav_index 2");

  Envelope broken = envelopeOf(u, 2);
  broken.payload.pop_back();
  EXPECT_TRUE(std::holds_alternative<std::monostate>(inbox.take(broken)));
  EXPECT_TRUE(inbox.lastWasDecodeFailure());
  EXPECT_NE(inbox.lastRefusal().find("map_update"), std::string::npos) << inbox.lastRefusal();
  EXPECT_EQ(inbox.mapUpdatesRefused(), 1u);
}

// The ground station's abort copies (OperatorInterface): the burst one per tick, then a resend per
// resend period on schedule, from now after a stall — and at once after ROS time went back (before,
// the resends paused until the clock caught up with the old schedule: 95 s after a restart at 5 s).
TEST(AbortCopyScheduleTest, BurstThenResendsOnScheduleAndAtOnceAfterTheClockWentBack) {
  AbortCopySchedule s(3, 1.0);
  EXPECT_FALSE(s.due(99.0));  // no abort yet
  s.start();
  EXPECT_TRUE(s.due(100.0));  // the burst: one copy per tick
  EXPECT_TRUE(s.due(100.2));
  EXPECT_TRUE(s.due(100.4));
  EXPECT_DOUBLE_EQ(s.nextResendS(), 101.4);
  EXPECT_FALSE(s.due(100.6));
  EXPECT_FALSE(s.due(101.2));
  EXPECT_TRUE(s.due(101.4));   // on schedule
  EXPECT_FALSE(s.due(101.6));
  EXPECT_TRUE(s.due(102.5));   // the first tick after 102.4; the next stays on schedule
  EXPECT_DOUBLE_EQ(s.nextResendS(), 103.4);
  EXPECT_TRUE(s.due(110.0));   // after a stall: from now
  EXPECT_DOUBLE_EQ(s.nextResendS(), 111.0);
  EXPECT_TRUE(s.due(5.0));     // ROS time went back to 5 s: a copy at once, the schedule from now
  EXPECT_DOUBLE_EQ(s.nextResendS(), 6.0);
  EXPECT_FALSE(s.due(5.2));
  EXPECT_TRUE(s.due(6.0));
  s.start();                   // another abort: a new burst
  EXPECT_TRUE(s.due(6.2));
  EXPECT_TRUE(s.due(6.4));
  EXPECT_TRUE(s.due(6.6));
  EXPECT_FALSE(s.due(6.8));
}

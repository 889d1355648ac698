// onboard::FormationParamsRole: the leader applies commands (version, record), a follower takes
// the leader's parameters for the same number of UAVs only.
#include <gtest/gtest.h>

#include "gesture_formation/onboard/formation_params_role.hpp"

using namespace gesture_formation;
using onboard::FormationParamsRole;

namespace {

formation::FormationCommand distancePlusOne(std::uint64_t sequence) {
  formation::FormationCommand c;
  c.id = {"operator@100", sequence};
  c.target.group = formation::TargetGroup::kFollowers;
  c.parameter = formation::Parameter::kDistance;
  c.amount = 1.0;
  return c;
}

}  // namespace

TEST(FormationParamsRoleTest, TheLeaderAppliesACommandOnceAndBumpsTheVersion) {
  formation::FormationConfig config;
  FormationParamsRole role(config, 0);
  ASSERT_TRUE(role.leader());
  const double d1 = role.params().uav(1).distance_m;
  const auto& r = role.apply(common::Result<formation::FormationCommand>::ok(distancePlusOne(3)), "op #3", "operator", 7.5);
  EXPECT_EQ(r.status, "applied");
  EXPECT_EQ(r.text, "op #3");
  EXPECT_EQ(r.source, "operator");
  EXPECT_DOUBLE_EQ(r.stamp_s, 7.5);
  EXPECT_EQ(r.uavs, (std::vector<int>{1, 2}));
  EXPECT_EQ(role.version(), 1u);
  EXPECT_DOUBLE_EQ(role.params().uav(1).distance_m, d1 + 1.0);
  // The same id again (a repeat): a duplicate, nothing changes.
  role.apply(common::Result<formation::FormationCommand>::ok(distancePlusOne(3)), "op #3", "operator", 7.6);
  EXPECT_EQ(role.last().status, "duplicate");
  EXPECT_EQ(role.version(), 1u);
  EXPECT_TRUE(role.last().uavs.empty());
  EXPECT_DOUBLE_EQ(role.params().uav(1).distance_m, d1 + 1.0);
}

TEST(FormationParamsRoleTest, AnUnparsableCommandIsRecordedAsRejectedWithItsReason) {
  FormationParamsRole role(formation::FormationConfig{}, 0);
  role.apply(common::Result<formation::FormationCommand>::fail("parameter: 'speed' unknown"), "op #1", "operator", 1.0);
  EXPECT_EQ(role.last().status, "rejected");
  EXPECT_EQ(role.last().outcome, "rejected: parameter: 'speed' unknown");
  EXPECT_EQ(role.version(), 0u);
}

TEST(FormationParamsRoleTest, AFollowerTakesTheLeadersParametersForItsUavCountOnly) {
  formation::FormationConfig config;
  FormationParamsRole role(config, 2);
  EXPECT_FALSE(role.leader());
  formation::FormationParams p = config.params;
  p.followers[1].distance_m += 2.0;
  ASSERT_TRUE(role.receive(p, 4));
  EXPECT_EQ(role.version(), 4u);
  EXPECT_DOUBLE_EQ(role.params().uav(2).distance_m, p.followers[1].distance_m);
  formation::FormationParams wrong = p;
  wrong.followers.pop_back();
  const auto r = role.receive(wrong, 5);
  ASSERT_FALSE(r);
  EXPECT_NE(r.reason().find("for 2 UAVs, the formation has 3"), std::string::npos) << r.reason();
  EXPECT_EQ(role.version(), 4u);
  // A follower applies no command.
  role.apply(common::Result<formation::FormationCommand>::ok(distancePlusOne(1)), "op #1", "operator", 1.0);
  EXPECT_EQ(role.last().status, "rejected");
  EXPECT_EQ(role.params().uav(2).distance_m, p.followers[1].distance_m);
}

// docs/safety.md §2.10: while the worker's request for assistance is pending, the worker's gesture
// commands are refused and the operator's applied; the operator's acknowledgement (of that request)
// releases the views; a repeated request keeps the first time.
TEST(FormationParamsRoleTest, AnAssistanceRequestHoldsTheViewsAgainstGesturesUntilAcknowledged) {
  FormationParamsRole role(formation::FormationConfig{}, 0);
  auto gesture = distancePlusOne(10);
  gesture.id = {"gesture", 10};
  gesture.source = formation::CommandSource::kGesture;
  ASSERT_TRUE(role.assistance().request(20.0, "gesture"));
  EXPECT_FALSE(role.assistance().request(25.0, "gesture"));  // the worker repeats it
  EXPECT_DOUBLE_EQ(role.assistance().state().requested_s, 20.0);
  role.apply(common::Result<formation::FormationCommand>::ok(gesture), "gesture #10", "gesture", 21.0);
  EXPECT_EQ(role.last().status, "rejected");
  EXPECT_NE(role.last().outcome.find("assistance requested at 20"), std::string::npos) << role.last().outcome;
  EXPECT_EQ(role.version(), 0u);
  role.apply(common::Result<formation::FormationCommand>::ok(distancePlusOne(11)), "op #11", "operator", 22.0);
  EXPECT_EQ(role.last().status, "applied");  // the operator's commands pass
  EXPECT_EQ(role.version(), 1u);
  EXPECT_FALSE(role.assistance().acknowledge(19.0, 23.0, "gcs"));  // another (older) request's acknowledgement
  EXPECT_EQ(role.assistance().state().phase, formation::AssistancePhase::kRequested);
  ASSERT_TRUE(role.assistance().acknowledge(20.0, 23.0, "gcs"));
  EXPECT_EQ(role.assistance().state().acknowledged_by, "gcs");
  gesture.id.sequence = 12;
  role.apply(common::Result<formation::FormationCommand>::ok(gesture), "gesture #12", "gesture", 24.0);
  EXPECT_EQ(role.last().status, "applied");
  EXPECT_EQ(role.version(), 2u);
  EXPECT_TRUE(role.assistance().request(30.0, "gesture"));  // a new request latches again
  EXPECT_EQ(role.assistance().state().phase, formation::AssistancePhase::kRequested);
}

// The states as they arrive (AssistanceLatch::receive): a request latches, an acknowledgement acts
// only on the request it names, "none" changes nothing.
TEST(FormationParamsRoleTest, ReceivedAssistanceStatesDispatchByPhase) {
  using formation::AssistancePhase;
  using formation::AssistanceState;
  formation::AssistanceLatch latch;
  EXPECT_FALSE(latch.receive(AssistanceState{AssistancePhase::kNone, 5.0, "gesture", 0.0, ""}));
  EXPECT_EQ(latch.state().phase, AssistancePhase::kNone);
  EXPECT_FALSE(latch.receive(AssistanceState{AssistancePhase::kAcknowledged, 5.0, "gesture", 6.0, "gcs"}));
  ASSERT_TRUE(latch.receive(AssistanceState{AssistancePhase::kRequested, 10.0, "gesture", 0.0, ""}));
  EXPECT_FALSE(latch.receive(AssistanceState{AssistancePhase::kRequested, 11.0, "gesture", 0.0, ""}));
  EXPECT_FALSE(latch.receive(AssistanceState{AssistancePhase::kAcknowledged, 9.0, "gesture", 12.0, "gcs"}));
  EXPECT_EQ(latch.state().phase, AssistancePhase::kRequested);
  ASSERT_TRUE(latch.receive(AssistanceState{AssistancePhase::kAcknowledged, 10.0, "gesture", 12.0, "gcs"}));
  EXPECT_EQ(latch.state().phase, AssistancePhase::kAcknowledged);
  EXPECT_DOUBLE_EQ(latch.state().acknowledged_s, 12.0);
  EXPECT_EQ(latch.state().acknowledged_by, "gcs");
}

// onboard::ParamsOwnership following the leadership (docs/safety.md §1.2): a follower that starts
// acting takes over the parameters it received with their version, applies only commands sent since,
// and stops owning (taking received parameters again) when it stops acting. By index it never changes.
TEST(ParamsOwnershipTest, TheActingUavTakesTheParametersOverWithTheirVersion) {
  formation::FormationConfig config;
  onboard::ParamsOwnership own(config, 1, true);
  EXPECT_FALSE(own.owns());
  formation::FormationParams p = config.params;
  p.followers[0].distance_m += 2.0;
  ASSERT_TRUE(own.receive(p, 7));
  EXPECT_EQ(own.version(), 7u);
  EXPECT_FALSE(own.takesCommand(100.0)) << "not acting: no command is this UAV's";
  EXPECT_EQ(own.setActing(false, 5.0), onboard::ParamsOwnership::Change::kNone);
  ASSERT_EQ(own.setActing(true, 10.0), onboard::ParamsOwnership::Change::kStarted);
  EXPECT_TRUE(own.owns());
  EXPECT_TRUE(own.role().leader());
  EXPECT_EQ(own.version(), 7u) << "the version taken over";
  EXPECT_DOUBLE_EQ(own.role().params().uav(1).distance_m, p.followers[0].distance_m) << "the parameters taken over";
  EXPECT_FALSE(own.takesCommand(9.9)) << "sent before the take-over: the predecessor's";
  EXPECT_TRUE(own.takesCommand(10.0));
  own.role().apply(common::Result<formation::FormationCommand>::ok(distancePlusOne(1)), "op #1", "operator", 10.5);
  EXPECT_EQ(own.version(), 8u) << "counted on from the version taken over";
  const auto ignored = own.receive(config.params, 99);
  ASSERT_TRUE(ignored);
  EXPECT_FALSE(*ignored) << "while owning, received parameters are ignored";
  EXPECT_EQ(own.version(), 8u);
  EXPECT_EQ(own.setActing(false, 20.0), onboard::ParamsOwnership::Change::kStopped);
  EXPECT_FALSE(own.owns());
  ASSERT_TRUE(own.receive(p, 9));
  EXPECT_EQ(own.version(), 9u) << "the received version is the formation's";

  onboard::ParamsOwnership by_index(config, 0, false);
  EXPECT_TRUE(by_index.owns());
  EXPECT_EQ(by_index.setActing(false, 1.0), onboard::ParamsOwnership::Change::kNone) << "by index the acting state is not used";
  EXPECT_TRUE(by_index.owns());
  EXPECT_TRUE(by_index.takesCommand(0.0));
}

// A lease that lapses and comes back in the same term (a lossy link): nobody else can have acted, so
// the role is resumed as it was and the commands that arrived in the gap are kept for it; back in a
// newer term it is a take-over (the gap's commands may have been another leader's: none kept).
TEST(ParamsOwnershipTest, ALeaderResumingInItsTermKeepsTheGapsCommands) {
  using Change = onboard::ParamsOwnership::Change;
  formation::FormationConfig config;
  onboard::ParamsOwnership own(config, 0, true);
  ASSERT_EQ(own.setActing(true, 1.0, 0, 1), Change::kStarted);
  EXPECT_FALSE(own.keepsCommand(2.0)) << "acting: it takes commands, it does not keep them";
  own.role().apply(common::Result<formation::FormationCommand>::ok(distancePlusOne(1)), "op #1", "operator", 2.0);
  ASSERT_EQ(own.version(), 1u);
  ASSERT_EQ(own.setActing(false, 3.0, 0, 1), Change::kStopped);
  EXPECT_FALSE(own.takesCommand(3.2));
  EXPECT_TRUE(own.keepsCommand(3.2)) << "its lease lapsed in the term in which it acts";
  EXPECT_FALSE(own.keepsCommand(0.5)) << "sent before it took over: its predecessor's";
  ASSERT_EQ(own.setActing(true, 3.4, 0, 1), Change::kResumed);
  EXPECT_TRUE(own.owns());
  EXPECT_EQ(own.version(), 1u) << "the role resumed as it was";
  EXPECT_DOUBLE_EQ(own.tookOverS(), 1.0);
  EXPECT_TRUE(own.takesCommand(3.2)) << "the gap's command is now its to apply";

  // It learns a newer term led by another UAV: nothing is kept any more, and acting again is a take-over.
  ASSERT_EQ(own.setActing(false, 5.0, 0, 1), Change::kStopped);
  EXPECT_EQ(own.setActing(false, 5.5, 2, 2), Change::kNone);
  EXPECT_FALSE(own.keepsCommand(5.6)) << "a newer term: another UAV may act";
  ASSERT_EQ(own.setActing(true, 8.0, 0, 3), Change::kStarted);
  EXPECT_DOUBLE_EQ(own.tookOverS(), 8.0);
  EXPECT_FALSE(own.takesCommand(5.6));

  // Without the term (callers that do not know it): every start is a take-over, nothing kept.
  onboard::ParamsOwnership no_term(config, 0, true);
  ASSERT_EQ(no_term.setActing(true, 1.0, 0), Change::kStarted);
  ASSERT_EQ(no_term.setActing(false, 2.0, 0), Change::kStopped);
  EXPECT_FALSE(no_term.keepsCommand(2.5));
  EXPECT_EQ(no_term.setActing(true, 3.0, 0), Change::kStarted);
  // Not following the leadership: never kept.
  onboard::ParamsOwnership by_index(config, 0, false);
  EXPECT_FALSE(by_index.keepsCommand(1.0));
}

// Review finding: the same UAV elected again in a newer term (its lease out long enough for an
// election under a lossy link, no other leader in between) got a fresh role: the worker's pending
// assistance request was dropped (gestures applied again, the operator's banner gone) and the
// version restarted. Now the role stays, as in gfctl simulate; a late copy of parameters arriving
// while its lease has lapsed in its term does not overwrite the ones it resumes with.
TEST(ParamsOwnershipTest, TheSameLeaderReElectedKeepsItsRoleAndAPendingAssistanceRequest) {
  using Change = onboard::ParamsOwnership::Change;
  formation::FormationConfig config;
  onboard::ParamsOwnership own(config, 0, true);
  ASSERT_EQ(own.setActing(true, 1.0, 0, 1), Change::kStarted);
  own.role().apply(common::Result<formation::FormationCommand>::ok(distancePlusOne(1)), "op #1", "operator", 2.0);
  ASSERT_TRUE(own.role().assistance().request(3.0, "gesture"));
  ASSERT_EQ(own.setActing(false, 4.0, 0, 1), Change::kStopped);
  formation::FormationParams stale = config.params;  // an earlier owner's parameters, arriving late
  stale.followers[0].distance_m = 20.0;
  ASSERT_TRUE(own.receive(stale, 7));
  EXPECT_FALSE(*own.receive(stale, 7)) << "lapsed in its own term: nobody else owns the parameters";
  EXPECT_EQ(own.setActing(false, 5.0, -1, 2), Change::kNone);  // a newer term, its leader unknown
  ASSERT_EQ(own.setActing(true, 6.0, 0, 3), Change::kStarted);
  EXPECT_EQ(own.role().assistance().state().phase, formation::AssistancePhase::kRequested);
  EXPECT_DOUBLE_EQ(own.role().assistance().state().requested_s, 3.0);
  EXPECT_EQ(own.version(), 1u);
  EXPECT_EQ(own.role().params().followers[0].distance_m, config.params.followers[0].distance_m + 1.0);
  // With another leader in between it is a take-over: a fresh role from the parameters received.
  ASSERT_EQ(own.setActing(false, 7.0, 0, 3), Change::kStopped);
  EXPECT_EQ(own.setActing(false, 7.5, 1, 4), Change::kNone);
  ASSERT_TRUE(own.receive(stale, 9));
  ASSERT_EQ(own.setActing(true, 9.0, 0, 5), Change::kStarted);
  EXPECT_EQ(own.role().assistance().state().phase, formation::AssistancePhase::kNone);
  EXPECT_EQ(own.version(), 9u);
  EXPECT_EQ(own.role().params().followers[0].distance_m, 20.0);
}

TEST(ParamsOwnershipTest, TheSlotAndTheLeadersPlanFollowTheLeadership) {
  formation::FormationConfig config;
  // Not following the leadership: by index, UAV 0 leads, every UAV flies its own slot.
  onboard::ParamsOwnership by_index(config, 2, false);
  by_index.setActing(true, 1.0, 2);
  EXPECT_EQ(by_index.slot(), -1);
  EXPECT_EQ(by_index.leaderIndex(), 0);

  onboard::ParamsOwnership uav1(config, 1, true);
  EXPECT_EQ(uav1.slot(), -1) << "a follower flies its own slot";
  EXPECT_EQ(uav1.leaderIndex(), 0) << "before any leadership state: UAV 0's plan is the leader's";
  uav1.setActing(false, 1.0, 0);
  EXPECT_EQ(uav1.leaderIndex(), 0);
  ASSERT_EQ(uav1.setActing(true, 10.0, 1), onboard::ParamsOwnership::Change::kStarted);
  EXPECT_EQ(uav1.slot(), 0) << "the acting leader flies the leader's slot";
  EXPECT_EQ(uav1.leaderIndex(), 1);
  uav1.setActing(false, 20.0, 2);
  EXPECT_EQ(uav1.slot(), -1) << "no longer acting: its own slot again";
  EXPECT_EQ(uav1.leaderIndex(), 2) << "the new leader's plan";

  onboard::ParamsOwnership uav0(config, 0, true);
  EXPECT_EQ(uav0.slot(), -1) << "its own index: the leader's slot";
  uav0.setActing(true, 0.0, 0);
  EXPECT_EQ(uav0.slot(), 0);
  uav0.setActing(false, 8.0, 0);
  EXPECT_EQ(uav0.slot(), -1) << "lease lapsed, no successor known: its own slot";
  EXPECT_EQ(uav0.leaderIndex(), 0);
  uav0.setActing(false, 12.0, 1);
  EXPECT_EQ(uav0.slot(), 1) << "UAV 0 flies the slot its successor left";
  EXPECT_EQ(uav0.leaderIndex(), 1);
}

// A fixed leader's planner restarted mid-mission (leadership off) started again from the config's
// parameters at version 0, and the followers took them: every adjustment of the mission lost. Its
// record (parameters, version, applied ids) lets it continue; a copy of a command it applied before
// the restart stays a duplicate.
TEST(FormationParamsRoleTest, ARestartedLeaderResumesItsRecordAndKnowsWhatItApplied) {
  formation::FormationConfig config;
  FormationParamsRole before(config, 0);
  before.apply(common::Result<formation::FormationCommand>::ok(distancePlusOne(3)), "op #3", "operator", 7.5);
  before.apply(common::Result<formation::FormationCommand>::ok(distancePlusOne(4)), "op #4", "operator", 8.5);
  ASSERT_EQ(before.version(), 2u);
  before.assistance().request(8.9, "gesture");  // the worker waits for help: it must stay pending
  const auto text = onboard::formatParamsRecord(before.record("run-42"));
  const auto parsed = onboard::parseParamsRecord(text);
  ASSERT_TRUE(parsed) << parsed.reason() << "\n" << text;
  EXPECT_EQ(parsed->run, "run-42");
  EXPECT_EQ(parsed->version, 2u);
  ASSERT_EQ(parsed->applied.size(), 2u);
  EXPECT_EQ(parsed->applied[1].sender, "operator@100");
  EXPECT_EQ(parsed->applied[1].sequence, 4u);

  FormationParamsRole after(config, 0);
  ASSERT_TRUE(after.resume(*parsed, config));
  EXPECT_EQ(after.version(), 2u);
  EXPECT_EQ(after.assistance().state().phase, formation::AssistancePhase::kRequested);
  EXPECT_EQ(after.assistance().state().requested_s, 8.9);
  EXPECT_EQ(after.assistance().state().requested_by, "gesture");
  EXPECT_TRUE(after.assistance().refusal(formation::CommandSource::kGesture)) << "the worker's gestures stay refused";
  for (int u = 0; u < 3; ++u) {
    EXPECT_EQ(after.params().uav(u).distance_m, before.params().uav(u).distance_m) << "UAV " << u;  // exact: %.17g
    EXPECT_EQ(after.params().uav(u).beta_deg, before.params().uav(u).beta_deg) << "UAV " << u;
  }
  after.apply(common::Result<formation::FormationCommand>::ok(distancePlusOne(4)), "op #4", "operator", 8.7);
  EXPECT_EQ(after.last().status, "duplicate");
  after.apply(common::Result<formation::FormationCommand>::ok(distancePlusOne(5)), "op #5", "operator", 9.0);
  EXPECT_EQ(after.last().status, "applied");
  EXPECT_EQ(after.version(), 3u);
  EXPECT_DOUBLE_EQ(after.params().uav(1).distance_m, config.params.uav(1).distance_m + 3.0);

  // Refused, nothing changed: a follower; another UAV count; parameters outside the limits.
  FormationParamsRole follower(config, 1);
  EXPECT_FALSE(follower.resume(*parsed, config));
  onboard::ParamsRecord two = *parsed;
  two.params.followers.pop_back();
  FormationParamsRole fresh(config, 0);
  const auto count = fresh.resume(two, config);
  ASSERT_FALSE(count);
  EXPECT_NE(count.reason().find("2 UAVs"), std::string::npos) << count.reason();
  onboard::ParamsRecord far = *parsed;
  far.params.leader.distance_m = 1000.0;
  const auto limits = fresh.resume(far, config);
  ASSERT_FALSE(limits);
  EXPECT_NE(limits.reason().find("distance"), std::string::npos) << limits.reason();
  EXPECT_EQ(fresh.version(), 0u);
  EXPECT_EQ(fresh.params().uav(0).distance_m, config.params.uav(0).distance_m);
}

TEST(FormationParamsRoleTest, ABadRecordIsRefusedNamingTheLine) {
  const std::string good = "gesture_formation_params 1\nrun r1\nversion 3\nuav 0 90 11 10\nuav 1 60 0 8\n";
  ASSERT_TRUE(onboard::parseParamsRecord(good));
  auto reason = [](const std::string& text) {
    const auto r = onboard::parseParamsRecord(text);
    EXPECT_FALSE(r) << text;
    return r ? std::string() : r.reason();
  };
  EXPECT_NE(reason("gesture_formation_params 2\n").find("line 1"), std::string::npos);
  EXPECT_NE(reason(good + "uav 3 0 0 8\n").find("line 6: uav 3 out of order"), std::string::npos);
  EXPECT_NE(reason("gesture_formation_params 1\nrun r1\nversion -1\nuav 0 90 11 10\n").find("line 3: version"), std::string::npos);
  EXPECT_NE(reason("gesture_formation_params 1\nrun r1\nversion 1\nuav 0 nan 11 10\n").find("line 4: uav"), std::string::npos);
  EXPECT_NE(reason("gesture_formation_params 1\nrun r1\nversion 1\n").find("incomplete"), std::string::npos);
  EXPECT_NE(reason(good + "speed 3\n").find("unknown key 'speed'"), std::string::npos);
  EXPECT_NE(reason("").find("empty"), std::string::npos);
  EXPECT_NE(reason(good + "assistance pending 1 0 gesture -\n").find("phase 'pending'"), std::string::npos);
  // A sender name a line cannot hold (a vertical tab splits it for the parser) is left out, not the record.
  onboard::ParamsRecord r;
  r.run = "r1";
  r.applied = {{"op\vx", 3}, {"operator@100", 4}};
  const auto back = onboard::parseParamsRecord(onboard::formatParamsRecord(r));
  ASSERT_TRUE(back) << back.reason();
  ASSERT_EQ(back->applied.size(), 1u);
  EXPECT_EQ(back->applied[0].sequence, 4u);
  EXPECT_EQ(back->assistance.phase, formation::AssistancePhase::kNone);
}

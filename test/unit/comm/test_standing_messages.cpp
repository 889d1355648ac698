// comm::StandingMessages — what the LcmBridge keeps sending on its own: the accepted abort with
// every heartbeat (docs/safety.md §2.8), the assistance state with every worker state while its
// request is pending (§2.10).
#include <gtest/gtest.h>

#include "gesture_formation/comm/standing_messages.hpp"

namespace gc = gesture_formation::comm;
namespace gfm = gesture_formation::formation;

TEST(StandingMessagesTest, TheAcceptedAbortIsRelayedFromThenOnAndTheFirstStays) {
  gc::StandingMessages s;
  EXPECT_FALSE(s.withHeartbeat());
  const gc::AbortMessage first{gfm::CommandId{"operator@100", 7}, gesture_formation::planning::AbortSource::kOperator};
  s.abortState(false, first);  // PHASE_NONE: nothing accepted yet
  EXPECT_FALSE(s.withHeartbeat());
  s.abortState(true, std::nullopt);  // a state whose command did not convert: nothing to relay
  EXPECT_FALSE(s.withHeartbeat());
  s.abortState(true, first);
  ASSERT_TRUE(s.withHeartbeat());
  EXPECT_EQ(s.withHeartbeat()->id.sequence, 7u);
  const gc::AbortMessage other{gfm::CommandId{"gesture", 1}, gesture_formation::planning::AbortSource::kGesture};
  s.abortState(true, other);  // a UAV acts on one abort: the relay stays the first
  EXPECT_EQ(s.withHeartbeat()->id.sender, "operator@100");
}

TEST(StandingMessagesTest, TheAssistanceStateIsResentOnlyWhileRequested) {
  gc::StandingMessages s;
  EXPECT_FALSE(s.withWorkerState());
  gc::AssistanceMessage m;
  m.state.phase = gfm::AssistancePhase::kRequested;
  m.state.requested_s = 20.0;
  s.assistanceSent(m);
  ASSERT_TRUE(s.withWorkerState());
  EXPECT_DOUBLE_EQ(s.withWorkerState()->state.requested_s, 20.0);
  m.state.phase = gfm::AssistancePhase::kAcknowledged;
  s.assistanceSent(m);
  EXPECT_FALSE(s.withWorkerState());
}

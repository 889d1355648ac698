// Rejection counters per claimed sender, the per-sender verification budget, and the state
// that survives restarts (boot counter, high-water marks): docs/security.md §4, §6.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "comm_test_util.hpp"
#include "gesture_formation/comm/rejection_report.hpp"
#include "gesture_formation/comm/sequence_store.hpp"
#include "gesture_formation/comm/signer.hpp"
#include "gesture_formation/comm/verifier.hpp"

using namespace gesture_formation::comm;
namespace t = gesture_formation::comm::testing;

namespace {

constexpr std::uint8_t kLeader = 40, kFollower = 41, kMe = 42;

VerifierConfig config() {
  VerifierConfig c;
  c.known_senders = {0, 1};
  c.own_sender_id = 2;
  c.max_age_s = 1.0;
  c.max_age_s_by_type[MessageType::kFormationCommand] = 5.0;
  return c;
}

Verifier makeVerifier(const VerifierConfig& c = config()) {
  auto v = Verifier::create(c, t::perSenderRing(2, kMe, {{0, kLeader}, {1, kFollower}}));
  EXPECT_TRUE(v) << v.reason();
  return std::move(v.value());
}

std::vector<std::uint8_t> seal(std::uint16_t sender, std::uint8_t fill, std::uint64_t sequence, double stamp_s,
                               MessageType type = MessageType::kHeartbeat, std::uint8_t key_id = 1) {
  Envelope e;
  e.type = type;
  e.sender_id = sender;
  e.key_id = key_id;
  e.sequence = sequence;
  e.stamp_s = stamp_s;
  e.payload = {0, 0, 0, 0, 0, 0, 0, 0};
  const auto seed = t::keyBytes(fill);
  return sealEnvelopeEd25519(e, seed.data()).value();
}

std::string tempPath() {
  char tmpl[] = "/tmp/gf_test_state_XXXXXX";
  const int fd = ::mkstemp(tmpl);
  if (fd >= 0) ::close(fd);
  std::remove(tmpl);
  return tmpl;
}

}  // namespace

TEST(CommLinkCountersTest, EveryClassIsCountedForItsClaimedSender) {
  Verifier v = makeVerifier();
  const double now = 100.0;
  auto run = [&](const std::vector<std::uint8_t>& b) { return v.verify(b.data(), b.size(), now).verdict; };
  EXPECT_EQ(run(seal(0, kLeader, 10, now)), Verdict::kAccepted);
  EXPECT_EQ(run(seal(0, kLeader, 10, now)), Verdict::kReplayed);
  EXPECT_EQ(run(seal(0, kFollower, 11, now)), Verdict::kForged);          // the follower's key as the leader
  EXPECT_EQ(run(seal(0, kLeader, 12, now - 1.5)), Verdict::kTooOld);
  EXPECT_EQ(run(seal(0, kLeader, 13, now + 1.0)), Verdict::kTooNew);
  EXPECT_EQ(run(seal(0, kLeader, 14, now, MessageType::kHeartbeat, 9)), Verdict::kUnknownKey);
  EXPECT_EQ(run(seal(0, kLeader, 5000, now)), Verdict::kAccepted);
  EXPECT_EQ(run(seal(0, kLeader, 15, now)), Verdict::kStale);              // below the 1024 window
  EXPECT_EQ(run(seal(0, kLeader, 6000, now - 4.0, MessageType::kFormationCommand)), Verdict::kAccepted);  // commands: 5 s
  EXPECT_EQ(run(seal(0, kLeader, 6001, now - 4.0, MessageType::kHeartbeat)), Verdict::kTooOld);           // others: 1 s
  auto bad = seal(1, kFollower, 1, now);
  bad.push_back(0);  // trailing byte: malformed, counted in the totals only
  EXPECT_EQ(run(bad), Verdict::kMalformed);
  EXPECT_EQ(run(seal(7, kFollower, 1, now)), Verdict::kUnknownSender);
  v.countDecodeFailure(1);
  v.countDecodeFailure(7);  // not configured: ignored

  const auto per = v.senderCounters();
  ASSERT_EQ(per.size(), 2u);
  const SenderCounters& leader = per.at(0);
  EXPECT_EQ(leader.count(Verdict::kAccepted), 3u);
  for (Verdict c : {Verdict::kReplayed, Verdict::kForged, Verdict::kTooNew, Verdict::kUnknownKey, Verdict::kStale}) {
    EXPECT_EQ(leader.count(c), 1u) << toString(c);
  }
  EXPECT_EQ(leader.count(Verdict::kTooOld), 2u);
  EXPECT_EQ(per.at(1).decode_failures, 1u);
  EXPECT_EQ(per.at(1).count(Verdict::kMalformed), 0u);
  EXPECT_EQ(v.counters().count(Verdict::kMalformed), 1u);
  EXPECT_EQ(v.counters().count(Verdict::kUnknownSender), 1u);
}

TEST(CommLinkCountersTest, AFloodSpendsOnlyItsClaimedSendersBudget) {
  VerifierConfig c = config();
  c.max_rate_hz = 100.0;
  c.burst = 20.0;
  Verifier v = makeVerifier(c);
  double now = 10.0;
  // 1000 forgeries claiming the leader within 0.1 s: 20 + 10 reach the signature check.
  int checked = 0;
  for (int i = 0; i < 1000; ++i) {
    now = 10.0 + 1e-4 * i;
    auto b = seal(0, kFollower, 100 + static_cast<std::uint64_t>(i), now);
    const Verdict r = v.verify(b.data(), b.size(), now).verdict;
    ASSERT_TRUE(r == Verdict::kForged || r == Verdict::kRateLimited) << toString(r);
    checked += r == Verdict::kForged;
  }
  EXPECT_GE(checked, 20);
  EXPECT_LE(checked, 31);
  EXPECT_EQ(v.senderCounters().at(0).count(Verdict::kRateLimited), static_cast<std::uint64_t>(1000 - checked));
  // The other sender is untouched; the leader's budget refills with time.
  auto f = seal(1, kFollower, 1, now);
  EXPECT_TRUE(v.verify(f.data(), f.size(), now).accepted());
  auto l = seal(0, kLeader, 5000, now + 0.05);
  EXPECT_TRUE(v.verify(l.data(), l.size(), now + 0.05).accepted());
}

TEST(CommLinkCountersTest, ABlindFloodDoesNotSpendTheBudgetOfTheSendersNextNumbers) {
  VerifierConfig c = config();
  c.max_rate_hz = 100.0;
  c.burst = 20.0;
  Verifier v = makeVerifier(c);
  double now = 10.0;
  auto first = seal(0, kLeader, 1000, now);
  ASSERT_TRUE(v.verify(first.data(), first.size(), now).accepted());
  // 5000 forgeries claiming the leader with numbers far above its window, interleaved with the
  // leader's real envelopes 1001, 1002, ...: every real one is accepted.
  std::uint64_t next = 1001;
  int accepted = 0;
  for (int i = 0; i < 5000; ++i) {
    now = 10.0 + 1e-4 * i;
    auto f = seal(0, kFollower, (std::uint64_t{1} << 60) + static_cast<std::uint64_t>(i), now);
    const Verdict r = v.verify(f.data(), f.size(), now).verdict;
    ASSERT_TRUE(r == Verdict::kForged || r == Verdict::kRateLimited) << toString(r);
    if (i % 200 == 0) {  // 50 per second, within the budget
      auto real = seal(0, kLeader, next++, now);
      accepted += v.verify(real.data(), real.size(), now).accepted();
    }
  }
  EXPECT_EQ(accepted, 25);
  EXPECT_GT(v.senderCounters().at(0).count(Verdict::kRateLimited), 4900u);
  // Forgeries with the leader's next numbers spend the near lane: then real ones are refused too
  // (the documented limit against an attacker who reads the traffic).
  for (int i = 0; i < 100; ++i) {
    auto f = seal(0, kFollower, next + 1 + static_cast<std::uint64_t>(i % 32), now);
    v.verify(f.data(), f.size(), now);
  }
  auto real = seal(0, kLeader, next, now);
  EXPECT_EQ(v.verify(real.data(), real.size(), now).verdict, Verdict::kRateLimited);
}

TEST(CommLinkCountersTest, OnlyPermittedSendersMaySendATypeThatHasAList) {
  VerifierConfig c = config();
  c.senders_by_type[MessageType::kFormationCommand] = {0};
  Verifier v = makeVerifier(c);
  auto from_follower = seal(1, kFollower, 1, 10.0, MessageType::kFormationCommand);
  EXPECT_EQ(v.verify(from_follower.data(), from_follower.size(), 10.0).verdict, Verdict::kNotPermitted);
  EXPECT_EQ(v.senderCounters().at(1).count(Verdict::kNotPermitted), 1u);
  auto from_leader = seal(0, kLeader, 1, 10.0, MessageType::kFormationCommand);
  EXPECT_TRUE(v.verify(from_leader.data(), from_leader.size(), 10.0).accepted());
  auto heartbeat = seal(1, kFollower, 2, 10.0);  // no list for heartbeats: any known sender
  EXPECT_TRUE(v.verify(heartbeat.data(), heartbeat.size(), 10.0).accepted());
  // The refused command changed no window: the follower's number 1 is still new.
  auto again = seal(1, kFollower, 1, 10.0);
  EXPECT_TRUE(v.verify(again.data(), again.size(), 10.0).accepted());

  // An empty list: nobody may send the type.
  VerifierConfig none = config();
  none.senders_by_type[MessageType::kFormationParams] = {};
  Verifier w = makeVerifier(none);
  auto params = seal(0, kLeader, 1, 10.0, MessageType::kFormationParams);
  EXPECT_EQ(w.verify(params.data(), params.size(), 10.0).verdict, Verdict::kNotPermitted);

  VerifierConfig bad = config();
  bad.senders_by_type[MessageType::kFormationCommand] = {5};
  const auto e = bad.validate();
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0], "senders_by_type.formation_command lists sender id 5, which is not in known_senders");
}

TEST(CommLinkCountersTest, ConfigValidationNamesTheBudgetFields) {
  VerifierConfig c = config();
  c.max_rate_hz = 0.0;
  c.burst = 0.5;
  const auto e = c.validate();
  ASSERT_EQ(e.size(), 2u);
  EXPECT_NE(e[0].find("max_rate_hz"), std::string::npos);
  EXPECT_NE(e[1].find("burst"), std::string::npos);
}

TEST(CommSequenceStoreTest, BootCounterSurvivesRestartsIndependentOfTheClock) {
  const std::string path = tempPath();
  auto b1 = advanceBootCounter(path);
  ASSERT_TRUE(b1) << b1.reason();
  EXPECT_EQ(b1.value(), 1u);
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0600u);
  auto b2 = advanceBootCounter(path);
  ASSERT_TRUE(b2);
  EXPECT_EQ(b2.value(), 2u);

  // Sender boot 1 sent many envelopes; it restarts with its clock 10 s behind (boot 2):
  // the receiver that never restarted accepts it at once.
  Verifier v = makeVerifier();
  Signer first(0, t::perSenderRing(0, kLeader, {}), firstSequenceOfBoot(b1.value()));
  for (int i = 0; i < 3000; ++i) {
    const double t = 70.0 + 0.01 * i;  // 100 per second, within the budget
    auto b = first.seal(MessageType::kHeartbeat, std::vector<std::uint8_t>(8, 0), t);
    ASSERT_TRUE(v.verify(b->data(), b->size(), t).accepted());
  }
  Signer second(0, t::perSenderRing(0, kLeader, {}), firstSequenceOfBoot(b2.value()));
  auto b = second.seal(MessageType::kHeartbeat, std::vector<std::uint8_t>(8, 0), 90.0);
  EXPECT_TRUE(v.verify(b->data(), b->size(), 90.0).accepted());
  EXPECT_GT(firstSequenceOfBoot(2), firstSequenceOfBoot(1) + 3000);

  std::ofstream(path) << "12x\n";
  auto bad = advanceBootCounter(path);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.reason().find("expected one boot counter"), std::string::npos) << bad.reason();
  ::chmod(path.c_str(), 0644);
  auto open = advanceBootCounter(path);
  ASSERT_FALSE(open);
  EXPECT_NE(open.reason().find("permissions 0644"), std::string::npos) << open.reason();
  std::remove(path.c_str());
}

TEST(CommSequenceStoreTest, HighWaterMarksRefuseReplaysAfterAReceiverRestart) {
  const std::string path = tempPath();
  std::vector<std::vector<std::uint8_t>> recorded;
  {
    Verifier v = makeVerifier();
    for (std::uint64_t s = 1; s <= 50; ++s) {
      recorded.push_back(seal(0, kLeader, s, 100.0));
      ASSERT_TRUE(v.verify(recorded.back().data(), recorded.back().size(), 100.0).accepted());
    }
    auto saved = saveHighWaterMarks(path, v.highWaterMarks());
    ASSERT_TRUE(saved) << saved.reason();
  }
  // Restarted receiver, same clock (the age check alone would let these through).
  Verifier fresh = makeVerifier();
  for (const auto& b : recorded) EXPECT_TRUE(makeVerifier().verify(b.data(), b.size(), 100.2).accepted());
  auto marks = loadHighWaterMarks(path);
  ASSERT_TRUE(marks) << marks.reason();
  EXPECT_EQ(marks->at(0), 50u);
  fresh.restoreHighWaterMarks(marks.value());
  for (const auto& b : recorded) EXPECT_FALSE(fresh.verify(b.data(), b.size(), 100.2).accepted());
  auto next = seal(0, kLeader, 51, 100.2);
  EXPECT_TRUE(fresh.verify(next.data(), next.size(), 100.2).accepted());
  // A missing file is an empty map; a damaged one is refused naming the line.
  std::remove(path.c_str());
  auto none = loadHighWaterMarks(path);
  ASSERT_TRUE(none);
  EXPECT_TRUE(none->empty());
  { std::ofstream(path) << "0 12\n1 x\n"; }
  ::chmod(path.c_str(), 0600);
  auto bad = loadHighWaterMarks(path);
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.reason().find(":2: expected '<sender id> <sequence>'"), std::string::npos) << bad.reason();
  std::remove(path.c_str());
}

TEST(CommReplayWindowTest, MarkSeenUpToRefusesEverythingBelowTheMark) {
  ReplayWindow w(256);
  w.accept(10);
  w.markSeenUpTo(5);  // below: no change
  EXPECT_EQ(w.highest(), 10u);
  EXPECT_EQ(w.check(9), ReplayWindow::Check::kNew);
  w.markSeenUpTo(1000);
  EXPECT_EQ(w.highest(), 1000u);
  EXPECT_EQ(w.check(1000), ReplayWindow::Check::kDuplicate);
  EXPECT_EQ(w.check(999), ReplayWindow::Check::kDuplicate);
  EXPECT_EQ(w.check(10), ReplayWindow::Check::kTooOld);
  EXPECT_EQ(w.check(1001), ReplayWindow::Check::kNew);
}

// comm::RejectionReport: the counts of /diagnostics and what was refused since the last report.
TEST(RejectionReportTest, ReportsCountsAndRefusalsSinceThePreviousReport) {
  using namespace gesture_formation::comm;
  RejectionReport report("LcmBridge sender 1");
  VerifierCounters link;
  std::map<std::uint16_t, SenderCounters> senders;
  senders[2].by_verdict[static_cast<std::size_t>(Verdict::kAccepted)] = 10;
  link.by_verdict[static_cast<std::size_t>(Verdict::kAccepted)] = 10;
  DiagnosticEntry e = report.link(link, senders, {{"channel_mismatch", 0}, {"published", 7}}, {"channel_mismatch"});
  EXPECT_EQ(e.name, "LcmBridge sender 1: link");
  EXPECT_FALSE(e.warn);
  EXPECT_EQ(e.message, "no refusals in the last second");
  EXPECT_EQ(e.values.size(), kVerdictCount + 3);
  EXPECT_EQ(e.values.back(), (std::pair<std::string, std::uint64_t>("published", 7)));
  // Two replays from sender 2, one decode failure, one channel mismatch: 4 refused since.
  senders[2].by_verdict[static_cast<std::size_t>(Verdict::kReplayed)] = 2;
  senders[2].decode_failures = 1;
  link.by_verdict[static_cast<std::size_t>(Verdict::kReplayed)] = 2;
  e = report.link(link, senders, {{"channel_mismatch", 1}, {"published", 9}}, {"channel_mismatch"});
  EXPECT_TRUE(e.warn);
  EXPECT_EQ(e.message, "4 refused in the last second");
  const DiagnosticEntry s = report.sender(2, senders[2]);
  EXPECT_EQ(s.name, "LcmBridge sender 1: from sender 2");
  EXPECT_TRUE(s.warn);
  EXPECT_EQ(s.message, "3 refused in the last second (claimed sender id)");
  EXPECT_EQ(s.values.size(), kVerdictCount);  // without kOwnMessage, with decode_failure
  // Nothing new: ok again.
  EXPECT_FALSE(report.sender(2, senders[2]).warn);
  EXPECT_FALSE(report.link(link, senders, {{"channel_mismatch", 1}}, {"channel_mismatch"}).warn);
}

// The bridge's default state directory: under $ROS_HOME, created (0700) only when a state file
// lives in it.
TEST(CommSequenceStoreTest, DefaultStateDirectoryIsCreatedOnlyForFilesInIt) {
  const std::string home = ::testing::TempDir() + "gf_state_home_" + std::to_string(::getpid());
  ::setenv("ROS_HOME", home.c_str(), 1);
  const std::string dir = gesture_formation::comm::defaultStateDirectory();
  EXPECT_EQ(dir, home + "/gesture_formation");
  struct stat st {};
  gesture_formation::comm::ensureStateDirectory(dir, {"/elsewhere/a.boot", "/elsewhere/a.marks"});
  EXPECT_NE(::stat(dir.c_str(), &st), 0) << "created although no state file lives in it";
  gesture_formation::comm::ensureStateDirectory(dir, {"/elsewhere/a.boot", dir + "/a.marks"});
  ASSERT_EQ(::stat(dir.c_str(), &st), 0);
  EXPECT_TRUE(S_ISDIR(st.st_mode));
  EXPECT_EQ(st.st_mode & 0777, 0700u);
  ::unsetenv("ROS_HOME");
}

// The leader hand-over in the simulator (docs/safety.md §1.2; sim/leader_handover.hpp): every UAV
// runs a formation::Leadership over the inter-UAV links; faults.leader_silence silences the leader.
// With a test-only stand-in planner (the plan is the stage-1 reference; safe in an empty world)
// that records every request it gets.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/sim/leader_handover.hpp"
#include "gesture_formation/sim/mission_runner.hpp"
#include "sim_test_support.hpp"

namespace gf = gesture_formation;

namespace {

using Call = gf::sim::test::PlanCall;
using gf::sim::test::RecordingPlanner;

struct Flight {
  std::shared_ptr<std::vector<Call>> calls = std::make_shared<std::vector<Call>>();
  gf::common::Result<gf::sim::MissionOutput> out = gf::common::Result<gf::sim::MissionOutput>::fail("not run");
};

/// The open-field mission with its operator requests (5, 15, 35, 55, 70 s), no gestures.
gf::sim::MissionConfig openField() {
  const auto m = gf::sim::loadMissionConfig(std::string(GF_SOURCE_DIR) + "/config/scenarios/open_field.yaml");
  EXPECT_TRUE(m) << m.reason();
  gf::sim::MissionConfig c = m ? *m : gf::sim::MissionConfig{};
  c.worker.gestures.clear();
  return c;
}

Flight fly(const gf::sim::MissionConfig& cfg, double duration_s, std::uint64_t seed = 5) {
  static gf::sim::test::EmptyWorld w;
  Flight r;
  gf::sim::MissionWorld world{&w.map, &w.field, 0.0};
  auto calls = r.calls;
  const gf::sim::PlannerFactory factory = [calls](int) { return std::make_unique<RecordingPlanner>(calls); };
  r.out = gf::sim::runMission(cfg, world, factory, nullptr, seed, duration_s);
  return r;
}

/// At most one UAV acts at every timeline row; returns the rows at which one acted, per UAV.
std::vector<int> checkActingRows(const gf::sim::MissionOutput& out, int n) {
  std::vector<int> rows(static_cast<std::size_t>(n), 0);
  for (const auto& row : out.timeline) {
    EXPECT_EQ(row.acting.size(), static_cast<std::size_t>(n)) << "t " << row.t_s;
    int acting = 0;
    for (std::size_t i = 0; i < row.acting.size(); ++i) {
      acting += row.acting[i];
      rows[i] += row.acting[i];
    }
    EXPECT_LE(acting, 1) << "two UAVs act at t " << row.t_s;
  }
  return rows;
}

const gf::sim::RequestRecord* requestSentAt(const gf::sim::MissionOutput& out, double t_s) {
  for (const auto& r : out.requests) {
    if (r.source == "operator" && std::abs(r.t_s - t_s) < 1e-6) return &r;
  }
  return nullptr;
}

}  // namespace

// A healthy leader acts alone from the first step to the last: leadership changes nothing.
TEST(LeaderHandoverTest, AHealthyLeaderActsAloneThroughoutTheMission) {
  const Flight r = fly(openField(), 30.0);
  ASSERT_TRUE(r.out) << r.out.reason();
  ASSERT_TRUE(r.out->metrics.leadership);
  const gf::sim::HandoverSummary& s = *r.out->metrics.leadership;
  ASSERT_EQ(s.leaders.size(), 1u);
  EXPECT_EQ(s.leaders[0].uav, 0);
  EXPECT_DOUBLE_EQ(s.leaders[0].from_s, 0.0);
  EXPECT_EQ(s.max_acting, 1);
  EXPECT_EQ(s.steps_two_acting, 0);
  EXPECT_EQ(s.silenced_uav, -1);
  const std::vector<int> rows = checkActingRows(*r.out, 3);
  EXPECT_EQ(rows[0], static_cast<int>(r.out->timeline.size()));
  EXPECT_GT(s.leadership_messages_sent, 0u);
}

// Silent for good at 20 s: a new leader acts within silence_limit + stagger + 2 election timeouts,
// never two at once, the later operator requests are applied by it, it avoids the silent leader's
// last plan, and the other follower follows its share.
TEST(LeaderHandoverTest, ALeaderSilentForGoodIsReplacedInTimeAndTheLaterRequestsApply) {
  gf::sim::MissionConfig cfg = openField();
  cfg.faults.leader_silence = gf::sim::LeaderSilence{20.0};
  const Flight r = fly(cfg, 45.0);
  ASSERT_TRUE(r.out) << r.out.reason();
  ASSERT_TRUE(r.out->metrics.leadership);
  const gf::sim::HandoverSummary& s = *r.out->metrics.leadership;
  const gf::formation::LeadershipConfig& lc = cfg.leadership;
  const double limit = lc.silence_limit_s + lc.candidacy_stagger_s + 2.0 * lc.election_timeout_s;
  EXPECT_EQ(s.silenced_uav, 0);
  ASSERT_GE(s.new_leader, 1);
  EXPECT_LE(s.handover_s, limit);
  EXPECT_GT(s.handover_s, lc.silence_limit_s - lc.lease_s);  // nobody stood while the promise held
  EXPECT_EQ(s.max_acting, 1);
  EXPECT_EQ(s.steps_two_acting, 0);
  EXPECT_LE(s.silenced_last_acting_s, 20.0 + lc.lease_s);  // its lease lapsed on its own clock
  const std::vector<int> rows = checkActingRows(*r.out, 3);
  EXPECT_GT(rows[static_cast<std::size_t>(s.new_leader)], 0);
  // The request of 35 s ([2] distance +2) is applied after the hand-over by the new leader.
  const gf::sim::RequestRecord* q = requestSentAt(*r.out, 35.0);
  ASSERT_NE(q, nullptr);
  EXPECT_EQ(q->status, "applied");
  EXPECT_GE(q->applied_s, s.new_leader_s);
  EXPECT_EQ(s.requests_after, 1);
  EXPECT_EQ(s.requests_after_applied, 1);
  // The silent UAV does not plan; the new leader avoids its last plan; the other follower avoids the new leader's.
  const int other = 3 - s.new_leader;
  int leader_calls = 0, other_calls = 0;
  for (const Call& c : *r.calls) {
    if (c.t_s < s.new_leader_s + 1.0) continue;
    EXPECT_NE(c.uav, 0) << "the silent leader planned at " << c.t_s;
    const auto avoids = [&c](int j) { return std::find(c.avoided.begin(), c.avoided.end(), j) != c.avoided.end(); };
    if (c.uav == s.new_leader) {
      ++leader_calls;
      EXPECT_TRUE(avoids(0)) << "t " << c.t_s;
    } else if (c.uav == other) {
      ++other_calls;
      EXPECT_TRUE(avoids(s.new_leader) && avoids(0)) << "t " << c.t_s;
    }
  }
  EXPECT_GT(leader_calls, 20);
  EXPECT_GT(other_calls, 20);
  // Its mode rows: silent at 20 s; the take-over named.
  bool silent = false, took_over = false;
  for (const auto& m : r.out->modes) {
    silent = silent || (m.uav == 0 && m.mode == "silent" && std::abs(m.t_s - 20.0) < 0.02);
    took_over = took_over || (m.uav == s.new_leader && m.reason.find("acting as leader") != std::string::npos);
  }
  EXPECT_TRUE(silent);
  EXPECT_TRUE(took_over);
  // (No distance assertions: the stand-in planner flies the reference unverified — into the silent
  // leader hovering near the leader's slot. The real planner's figures: gfctl_simulate_leader_dropout
  // and docs/results/leader_handover.md.)
}

// Silent for 5 s: replaced meanwhile, the old leader rejoins as a follower (listening first) and
// never acts again; never two act.
TEST(LeaderHandoverTest, ALeaderSilentFor5sRejoinsAsAFollower) {
  gf::sim::MissionConfig cfg = openField();
  cfg.faults.leader_silence = gf::sim::LeaderSilence{20.0, 5.0};
  const Flight r = fly(cfg, 40.0);
  ASSERT_TRUE(r.out) << r.out.reason();
  const gf::sim::HandoverSummary& s = *r.out->metrics.leadership;
  ASSERT_GE(s.new_leader, 1);
  EXPECT_EQ(s.steps_two_acting, 0);
  checkActingRows(*r.out, 3);
  for (const auto& row : r.out->timeline) {
    if (row.t_s > 25.0) {
      EXPECT_EQ(row.acting[0], 0) << "the old leader acts again at " << row.t_s;
    }
  }
  bool rejoined = false;
  for (const auto& m : r.out->modes) rejoined = rejoined || (m.uav == 0 && m.mode == "rejoin" && std::abs(m.t_s - 25.0) < 0.02);
  EXPECT_TRUE(rejoined);
  int calls_after = 0;
  for (const Call& c : *r.calls) calls_after += c.uav == 0 && c.t_s > 27.0 ? 1 : 0;
  EXPECT_GT(calls_after, 10);  // it plans again, as a follower
  EXPECT_EQ(requestSentAt(*r.out, 35.0)->status, "applied");
}

TEST(LeaderHandoverConfigTest, ProblemsNameTheKeyAndValue) {
  const std::string yaml = R"(
mission:
  leadership: {lease_s: 0.1, heartbeat_period_s: 0.2, uav_count: 4}
  faults:
    leader_silence: {duration_s: -5}
)";
  gf::common::ConfigReader r =
      gf::common::ConfigReader::fromString(yaml, "test.yaml", gf::common::ConfigReader::MissingKeys::kUseDefaults);
  gf::formation::LeadershipConfig lc;
  gf::sim::readLeadership(r, "mission.", 3, lc);
  std::optional<gf::sim::LeaderSilence> silence;
  gf::sim::readLeaderSilence(r, "mission.faults.leader_silence", silence);
  std::string all;
  for (const auto& e : r.errors()) all += e + "\n";
  for (const char* needle : {"mission.leadership.uav_count", "4", "mission.leadership.lease_s",
                             "mission.faults.leader_silence.t_s", "missing", "mission.faults.leader_silence.duration_s",
                             "-5"}) {
    EXPECT_NE(all.find(needle), std::string::npos) << needle << " not in:\n" << all;
  }
  EXPECT_EQ(lc.uav_count, 3);
}

TEST(LeaderHandoverConfigTest, TheThreeProfilesOverlayThePowerTowerMission) {
  const std::string scenario = std::string(GF_SOURCE_DIR) + "/config/scenarios/power_towers.yaml";
  const struct {
    const char* name;
    bool for_good;
    double duration_s;
  } profiles[] = {{"leader_dropout_5s", false, 5.0}, {"leader_dropout_60s", false, 60.0}, {"leader_dropout_for_good", true, 0.0}};
  for (const auto& p : profiles) {
    const auto m = gf::sim::loadMissionConfig(scenario, std::string(GF_SOURCE_DIR) + "/config/faults/" + p.name + ".yaml");
    ASSERT_TRUE(m) << p.name << ": " << m.reason();
    ASSERT_TRUE(m->faults.leader_silence) << p.name;
    EXPECT_DOUBLE_EQ(m->faults.leader_silence->t_s, 60.0) << p.name;
    EXPECT_EQ(m->faults.leader_silence->forGood(), p.for_good) << p.name;
    if (!p.for_good) {
      EXPECT_DOUBLE_EQ(m->faults.leader_silence->duration_s, p.duration_s) << p.name;
    }
    EXPECT_EQ(m->leadership.uav_count, 3) << p.name;
    EXPECT_EQ(m->requests.size(), 19u) << p.name;
  }
}

// The simulator's side of an abort (sim/abort_drill.hpp): the fault key faults.abort, the
// operator's repeated copies, and the metrics recorder.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "gesture_formation/sim/abort_drill.hpp"
#include "gesture_formation/sim/mission_config.hpp"

namespace gf = gesture_formation;

TEST(AbortEventTest, TheFaultKeyIsReadAndBadValuesAreNamed) {
  const std::string scenario = std::string(GF_SOURCE_DIR) + "/config/scenarios/power_towers.yaml";
  const auto m = gf::sim::loadMissionConfig(scenario, std::string(GF_SOURCE_DIR) + "/config/faults/abort_mid_mission.yaml");
  ASSERT_TRUE(m) << m.reason();
  ASSERT_TRUE(m->faults.abort);
  EXPECT_DOUBLE_EQ(m->faults.abort->t_s, 100.0);
  EXPECT_EQ(m->faults.abort->source, gf::planning::AbortSource::kOperator);
  EXPECT_EQ(m->requests.size(), 19u);  // the rest of the mission is untouched
  auto r = gf::common::ConfigReader::fromString("faults:\n  abort: {source: radio}\n", "f.yaml",
                                                gf::common::ConfigReader::MissingKeys::kUseDefaults);
  std::optional<gf::sim::AbortEvent> e;
  gf::sim::readAbortEvent(r, "faults.abort", e);
  std::string all;
  for (const auto& line : r.errors()) all += line + "\n";
  EXPECT_NE(all.find("faults.abort.t_s: missing"), std::string::npos) << all;
  EXPECT_NE(all.find("faults.abort.source"), std::string::npos) << all;
  EXPECT_NE(all.find("radio"), std::string::npos) << all;
}

TEST(AbortSenderTest, SendsTheSameCommandRepeatsTimesPeriodApartThenEveryResendPeriod) {
  gf::sim::AbortSender s(gf::sim::AbortEvent{10.0, gf::planning::AbortSource::kOperator}, 3, 0.2, 1.0);
  EXPECT_TRUE(s.due(9.9).empty());
  const auto first = s.due(10.0);
  ASSERT_EQ(first.size(), 1u);
  EXPECT_DOUBLE_EQ(first[0].sent_s, 10.0);
  const auto rest = s.due(11.0);
  ASSERT_EQ(rest.size(), 2u);  // the burst's 10.2 and 10.4; the first resend falls due at 11.4
  EXPECT_DOUBLE_EQ(rest[1].sent_s, 10.4);
  EXPECT_EQ(rest[1].id.sender, first[0].id.sender);
  EXPECT_EQ(rest[1].id.sequence, first[0].id.sequence);  // one command: the copies are repeats
  EXPECT_TRUE(s.due(11.3).empty());
  // After the burst, one copy per resend period for the rest of the mission, each stamped when sent.
  const auto later = s.due(20.0);
  ASSERT_EQ(later.size(), 9u);  // 11.4, 12.4, ..., 19.4
  EXPECT_DOUBLE_EQ(later.front().sent_s, 11.4);
  EXPECT_DOUBLE_EQ(later.back().sent_s, 19.4);
  EXPECT_EQ(later.back().id.sequence, first[0].id.sequence);
  EXPECT_EQ(s.due(20.0).size(), 0u);  // nothing twice
  gf::sim::AbortSender g(gf::sim::AbortEvent{10.0, gf::planning::AbortSource::kGesture}, 3, 0.2, 1.0);
  EXPECT_TRUE(g.due(20.0).empty());  // a gesture is the leader's, not the ground station's
}

TEST(AbortRecorderTest, RecordsAcceptanceArrivalAndTheDistancesFromTheIssueOn) {
  gf::sim::AbortRecorder rec(gf::sim::AbortEvent{10.0, gf::planning::AbortSource::kOperator}, 2,
                             [](const Eigen::Vector3d& p) { return p.z(); });
  rec.sample(9.0, {Eigen::Vector3d(0, 0, 0.1), Eigen::Vector3d(0, 0, 0.2)}, Eigen::Vector3d::Zero());  // before: ignored
  rec.accepted(0, 10.1);
  rec.accepted(0, 10.3);  // a repeat changes nothing
  rec.phase(0, 10.4, gf::planning::AbortPhase::kRetreat);
  rec.sample(11.0, {Eigen::Vector3d(0, 0, 5), Eigen::Vector3d(3, 4, 5)}, Eigen::Vector3d(0, 0, 1));
  rec.phase(0, 15.0, gf::planning::AbortPhase::kAtRetreat);
  const auto& s = rec.summary();
  EXPECT_DOUBLE_EQ(s.uavs[0].accepted_s, 10.1);
  EXPECT_DOUBLE_EQ(s.uavs[0].retreat_reached_s, 15.0);
  EXPECT_DOUBLE_EQ(s.uavs[0].settled_s, 15.0);
  EXPECT_EQ(s.uavs[0].phase, "at_retreat");
  EXPECT_DOUBLE_EQ(s.uavs[0].min_obstacle_distance_m, 5.0);
  EXPECT_DOUBLE_EQ(s.uavs[0].min_worker_distance_m, 4.0);
  EXPECT_DOUBLE_EQ(s.uavs[1].min_uav_distance_m, 5.0);
  EXPECT_TRUE(std::isnan(s.time_to_settle_max_s()));  // UAV 1 never settled
  rec.phase(1, 18.0, gf::planning::AbortPhase::kAtRetreat);
  EXPECT_DOUBLE_EQ(rec.summary().time_to_settle_max_s(), 8.0);
  EXPECT_NE(gf::sim::abortJson(rec.summary(), 0).find("\"settled_s\": 18"), std::string::npos);
}

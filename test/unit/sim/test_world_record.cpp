// sim::WorldRecord: what the ROS simulation's world records from the running system (plans and
// modes, parameter versions, one outcome per command, the files).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/sim/world_record.hpp"

namespace gf = gesture_formation;
using gf::sim::ParamsReport;
using gf::sim::PlanReport;
using gf::sim::WorldRecord;

namespace {

struct Fixture {
  gf::sim::MissionConfig cfg;
  gf::planning::OccupancyMap map;
  gf::planning::DistanceField field;
  Fixture() : cfg(load()), map(makeMap()), field(map) {}
  static gf::sim::MissionConfig load() {
    const auto m = gf::sim::loadMissionConfig(std::string(GF_SOURCE_DIR) + "/config/scenarios/open_field.yaml");
    EXPECT_TRUE(m) << m.reason();
    return *m;
  }
  static gf::planning::OccupancyMap makeMap() {
    gf::planning::MapConfig mc;
    mc.resolution_m = 0.5;
    mc.bounds = gf::planning::Aabb{Eigen::Vector3d(-20, -20, 0), Eigen::Vector3d(20, 20, 10)};
    return gf::planning::OccupancyMap::fromPrimitives(mc, gf::planning::PrimitiveSet{}, gf::planning::GroundSpec{true, 0.0});
  }
  gf::sim::ObstacleDistance obstacles() const { return gf::sim::ObstacleDistance{&field, nullptr, 0.0}; }
};

PlanReport planOf(int uav, double t, const std::string& mode, std::uint64_t version = 0) {
  PlanReport p;
  p.uav = uav;
  p.planned_at_s = t;
  p.params_version = version;
  p.mode = mode;
  return p;
}

std::string readFile(const std::string& path) {
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

}  // namespace

TEST(WorldRecordTest, ModeChangesAreRecordedOncePerChangeAndHoldReplanningsCounted) {
  Fixture fx;
  WorldRecord r(fx.cfg, fx.obstacles(), 1);
  r.plan(planOf(1, 1.0, "track"));
  r.plan(planOf(1, 1.2, "track"));
  auto hold = planOf(1, 1.4, "hold");
  hold.mode_reason = "worker estimate stale";
  r.plan(hold);
  r.plan(planOf(1, 1.6, "hold"));
  r.plan(planOf(1, 1.8, "search"));
  r.plan(planOf(2, 1.9, ""));  // mode not said: no change recorded
  r.plan(planOf(7, 2.0, "hold"));  // no such UAV: ignored
  ASSERT_EQ(r.modes().size(), 3u);
  EXPECT_EQ(r.modes()[0].mode, "track");
  EXPECT_EQ(r.modes()[0].reason, "fresh data");
  EXPECT_EQ(r.modes()[1].mode, "hold");
  EXPECT_EQ(r.modes()[1].reason, "worker estimate stale");
  EXPECT_DOUBLE_EQ(r.modes()[1].t_s, 1.4);
  EXPECT_EQ(r.modes()[2].mode, "search");
  EXPECT_EQ(r.metrics().counters().plans_hold, 3);
}

TEST(WorldRecordTest, ACommandOutcomeIsCountedOncePerCommandAndStatus) {
  Fixture fx;
  WorldRecord r(fx.cfg, fx.obstacles(), 1);
  ParamsReport p;
  p.params = fx.cfg.formation.params;
  p.version = 1;
  p.last_command = "operator gcs#1: all.distance_m += 1";
  p.last_status = "duplicate";
  p.last_source = "operator";
  r.params(p);
  r.params(p);  // re-published parameters repeat the last command
  EXPECT_EQ(r.metrics().counters().commands_duplicate, 1);
  p.last_command = "operator gcs#2: all.distance_m += 1";
  r.params(p);
  EXPECT_EQ(r.metrics().counters().commands_duplicate, 2);
  p.last_command.clear();  // nothing handled: parameters only
  r.params(p);
  EXPECT_EQ(r.metrics().counters().commands_duplicate, 2);
}

// A follower's plan comes without its parameter version: it is the latest version the leader
// published with exactly the parameters the plan lists; the current parameters follow the leader.
TEST(WorldRecordTest, AFollowersPlanGetsTheVersionTheLeaderPublishedItsParametersWith) {
  Fixture fx;
  WorldRecord r(fx.cfg, fx.obstacles(), 1);
  auto changed = fx.cfg.formation.params;
  changed.uav(1).distance_m += 2.0;
  ParamsReport p;
  p.params = changed;
  p.version = 4;
  r.params(p);
  EXPECT_DOUBLE_EQ(r.currentParams().uav(1).distance_m, changed.uav(1).distance_m);
  auto follower = planOf(1, 3.0, "track");
  follower.formation = changed;
  r.plan(follower);
  auto old = planOf(2, 3.1, "track");
  old.formation = fx.cfg.formation.params;  // still the mission's: version 0
  r.plan(old);
  auto leader = planOf(0, 3.2, "track", 4);
  r.plan(leader);
  const std::string dir = ::testing::TempDir() + "/world_record_versions";
  std::filesystem::create_directories(dir);
  std::string error, warning;
  ASSERT_TRUE(r.finish({}, 4.0, 1.0, dir, &error, &warning)) << error;
  const std::string plans = readFile(dir + "/plans.csv");
  std::istringstream lines(plans);
  std::string header, l1, l2, l3;
  std::getline(lines, header);
  std::getline(lines, l1);
  std::getline(lines, l2);
  std::getline(lines, l3);
  EXPECT_NE(l1.find(",optimized,4,"), std::string::npos) << l1;
  EXPECT_NE(l2.find(",optimized,0,"), std::string::npos) << l2;
  EXPECT_NE(l3.find(",optimized,4,"), std::string::npos) << l3;
  EXPECT_TRUE(std::filesystem::exists(dir + "/metrics.json"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/modes.csv"));
  const std::string metrics = readFile(dir + "/metrics.json");
  EXPECT_NE(metrics.find("messages_lost"), std::string::npos) << "not_measured lists what ROS does not report";
}

TEST(WorldRecordTest, SafetyIsSampledOnlyOnceEveryUavReportedItsTruth) {
  Fixture fx;
  WorldRecord r(fx.cfg, fx.obstacles(), 1);
  std::vector<std::optional<gf::sim::MultirotorState>> truths(3);
  gf::sim::WorkerState w;
  w.p_world = Eigen::Vector3d(0, 0, 0.9);
  EXPECT_FALSE(r.sampleSafety(0.1, truths, w));
  for (int i = 0; i < 3; ++i) {
    truths[static_cast<std::size_t>(i)] = gf::sim::MultirotorState{};
    truths[static_cast<std::size_t>(i)]->p_world = Eigen::Vector3d(5.0 * i, 8.0, 4.0);
  }
  EXPECT_TRUE(r.sampleSafety(0.2, truths, w));
}

// The mission's operator requests leave once each, in order, and stay pending ("lost") until the
// leader's outcome names them.
TEST(WorldRecordTest, OperatorRequestsAreDueOnceEachAndPendingUntilTheirOutcome) {
  Fixture fx;
  ASSERT_FALSE(fx.cfg.requests.empty()) << "open_field.yaml schedules operator requests";
  WorldRecord r(fx.cfg, fx.obstacles(), 1);
  const double first = fx.cfg.requests.front().t_s;
  EXPECT_TRUE(r.dueRequests(first - 0.01).empty());
  const auto due = r.dueRequests(first);
  ASSERT_GE(due.size(), 1u);
  EXPECT_TRUE(r.dueRequests(first).empty());  // each once
  const std::string dir = ::testing::TempDir() + "/world_record_requests";
  std::filesystem::create_directories(dir);
  std::string error, warning;
  ASSERT_TRUE(r.finish({}, first + 1.0, 1.0, dir, &error, &warning)) << error;
  const std::string events = readFile(dir + "/events.csv");
  EXPECT_NE(events.find("lost"), std::string::npos) << events;  // no outcome came
}

// faults.worker_approach in the ROS world: at its time (once the target UAV's truth is known) the
// worker turns towards the point below that UAV; the unseen phase is recorded in metrics.json.
TEST(WorldRecordTest, TheWorkerApproachTurnsTheWorkerTowardsTheUavAndIsRecorded) {
  Fixture fx;
  fx.cfg.faults.worker_approach = gf::sim::WorkerApproach{1.0, 1, 1.2, 0.0};
  fx.cfg.faults.camera_blackouts = {{0.5, 100.0}};
  WorldRecord r(fx.cfg, fx.obstacles(), 1);
  gf::sim::WorkerModel worker(fx.cfg.worker, 7);
  gf::sim::WorkerModel untouched(fx.cfg.worker, 7);
  std::vector<std::optional<gf::sim::MultirotorState>> truths(3);
  r.divertWorker(1.0, worker, truths);  // UAV 1's truth not known yet: nothing happens
  r.divertWorker(0.9, worker, truths);
  for (int i = 0; i < 3; ++i) {
    truths[static_cast<std::size_t>(i)] = gf::sim::MultirotorState{};
    truths[static_cast<std::size_t>(i)]->p_world = Eigen::Vector3d(-30.0 + 10.0 * i, 25.0, 6.0);
  }
  r.divertWorker(0.9, worker, truths);  // before its time
  EXPECT_TRUE((worker.stateAt(6.0).feet_world - untouched.stateAt(6.0).feet_world).norm() < 1e-9);
  r.divertWorker(1.0, worker, truths);
  const Eigen::Vector3d start = worker.stateAt(1.0).feet_world;
  const Eigen::Vector3d later = worker.stateAt(6.0).feet_world;
  const Eigen::Vector2d towards = (truths[1]->p_world.head<2>() - start.head<2>()).normalized();
  EXPECT_NEAR((later - start).head<2>().dot(towards), 1.2 * 5.0, 0.05) << "walks 1.2 m/s towards UAV 1";
  gf::sim::WorkerState ws;
  ws.p_world = later + Eigen::Vector3d(0, 0, 0.9);
  ASSERT_TRUE(r.sampleSafety(6.0, truths, ws));
  const std::string dir = ::testing::TempDir() + "/world_record_approach";
  std::filesystem::create_directories(dir);
  std::string error, warning;
  ASSERT_TRUE(r.finish({}, 6.0, 1.0, dir, &error, &warning)) << error;
  const std::string metrics = readFile(dir + "/metrics.json");
  EXPECT_NE(metrics.find("\"worker_approach\""), std::string::npos);
}

// faults.abort in the ROS world: the operator's abort is due once, at its time; every UAV's
// published abort states go into metrics.json's `abort` (accepted, retreat reached, settled, the
// least distances from the issue on), as gfctl simulate's AbortRecorder writes it.
TEST(WorldRecordTest, TheAbortIsDueOnceAtItsTimeAndEveryUavsStatesAreRecorded) {
  Fixture fx;
  fx.cfg.faults.abort = gf::sim::AbortEvent{10.0, gf::planning::AbortSource::kOperator};
  WorldRecord r(fx.cfg, fx.obstacles(), 1);
  EXPECT_FALSE(r.abortDue(9.9));
  EXPECT_TRUE(r.abortDue(10.05));
  EXPECT_FALSE(r.abortDue(10.1)) << "requested once";
  using P = gf::planning::AbortPhase;
  for (int i = 0; i < 3; ++i) {
    r.abortState({i, 10.2, P::kRetreat, 10.15, gf::planning::AbortSource::kOperator});
    r.abortState({i, 11.0, P::kRetreat, 10.15, gf::planning::AbortSource::kOperator});  // every replanning
  }
  r.abortState({0, 14.0, P::kAtRetreat, 10.15, gf::planning::AbortSource::kOperator});
  r.abortState({1, 15.0, P::kAtRetreat, 10.15, gf::planning::AbortSource::kOperator});
  r.abortState({1, 16.0, P::kAtRetreat, 10.15, gf::planning::AbortSource::kOperator});
  r.abortState({2, 12.0, std::nullopt, 0.0, gf::planning::AbortSource::kOperator});  // not aborting: ignored
  std::vector<std::optional<gf::sim::MultirotorState>> truths(3);
  for (int i = 0; i < 3; ++i) {
    truths[static_cast<std::size_t>(i)] = gf::sim::MultirotorState{};
    truths[static_cast<std::size_t>(i)]->p_world = Eigen::Vector3d(5.0 * i, 8.0, 4.0);
  }
  gf::sim::WorkerState w;
  w.p_world = Eigen::Vector3d(0, 0, 0.9);
  ASSERT_TRUE(r.sampleSafety(9.0, truths, w));  // before the issue: not the abort's
  truths[0]->p_world = Eigen::Vector3d(0, 12.0, 0.9);
  ASSERT_TRUE(r.sampleSafety(12.0, truths, w));
  const std::string dir = ::testing::TempDir() + "/world_record_abort";
  std::filesystem::create_directories(dir);
  std::string error, warning;
  ASSERT_TRUE(r.finish({}, 20.0, 1.0, dir, &error, &warning)) << error;
  const std::string metrics = readFile(dir + "/metrics.json");
  EXPECT_NE(metrics.find("\"issued_s\": 10"), std::string::npos) << metrics;
  EXPECT_NE(metrics.find("{\"uav\": 0, \"accepted_s\": 10.15, \"retreat_reached_s\": 14, \"settled_s\": 14, "
                         "\"phase\": \"at_retreat\""),
            std::string::npos)
      << metrics;
  EXPECT_NE(metrics.find("{\"uav\": 1, \"accepted_s\": 10.15, \"retreat_reached_s\": 15, \"settled_s\": 15"),
            std::string::npos)
      << metrics;
  EXPECT_NE(metrics.find("{\"uav\": 2, \"accepted_s\": 10.15, \"retreat_reached_s\": null, \"settled_s\": null, "
                         "\"phase\": \"retreat\""),
            std::string::npos)
      << metrics;
  // UAV 0's least worker distance is the sample after the issue (12 m), not the one before (8.6 m).
  EXPECT_NE(metrics.find("\"phase\": \"at_retreat\", \"min_worker_distance_m\": 12,"), std::string::npos) << metrics;
  EXPECT_NE(metrics.find("\"time_to_settle_max_s\": null"), std::string::npos) << metrics;
}

// An abort accepted without faults.abort (the worker's gesture) is recorded from its acceptance.
TEST(WorldRecordTest, AnAbortAcceptedWithoutTheFaultIsRecordedFromItsAcceptance) {
  Fixture fx;
  WorldRecord r(fx.cfg, fx.obstacles(), 1);
  EXPECT_FALSE(r.abortDue(100.0)) << "no faults.abort";
  r.abortState({0, 30.0, gf::planning::AbortPhase::kRetreat, 29.9, gf::planning::AbortSource::kGesture});
  const std::string dir = ::testing::TempDir() + "/world_record_abort_gesture";
  std::filesystem::create_directories(dir);
  std::string error, warning;
  ASSERT_TRUE(r.finish({}, 40.0, 1.0, dir, &error, &warning)) << error;
  const std::string metrics = readFile(dir + "/metrics.json");
  EXPECT_NE(metrics.find("\"issued_s\": 29.9"), std::string::npos) << metrics;
  EXPECT_NE(metrics.find("\"source\": \"gesture\""), std::string::npos) << metrics;
}

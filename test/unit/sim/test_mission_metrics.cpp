// The parts gfctl simulate and the ROS simulation share: the metrics accumulator and its
// writer (sim/mission_metrics.hpp), the leader's camera and the step schedule
// (sim/leader_camera.hpp). The planning request's tests: test/unit/planning/.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/sim/leader_camera.hpp"
#include "gesture_formation/sim/mission_metrics.hpp"
#include "gesture_formation/planning/plan_request_builder.hpp"
#include "gesture_formation/sim/random.hpp"

namespace gf = gesture_formation;
using gf::sim::CommandOutcome;
using gf::sim::MetricsAccumulator;
using gf::sim::ParamsVersions;
using gf::sim::RequestRecord;

namespace {

/// One 2 × 2 × 4 m box at (10, 0, 2) on the ground, 0.4 m voxels.
struct BoxWorld {
  gf::planning::PrimitiveSet solids;
  gf::planning::OccupancyMap map;
  gf::planning::DistanceField field;
  BoxWorld() : solids(makeSolids()), map(makeMap(solids)), field(map) {}
  static gf::planning::PrimitiveSet makeSolids() {
    gf::planning::PrimitiveSet s;
    gf::planning::OrientedBox b;
    b.center_world = Eigen::Vector3d(10, 0, 2);
    b.size_m = Eigen::Vector3d(2, 2, 4);
    s.boxes.push_back(b);
    return s;
  }
  static gf::planning::OccupancyMap makeMap(const gf::planning::PrimitiveSet& s) {
    gf::planning::MapConfig mc;
    mc.resolution_m = 0.4;
    mc.bounds = gf::planning::Aabb{Eigen::Vector3d(-30, -30, 0), Eigen::Vector3d(30, 30, 20)};
    return gf::planning::OccupancyMap::fromPrimitives(mc, s, gf::planning::GroundSpec{true, 0.0});
  }
  gf::sim::ObstacleDistance exact() const { return gf::sim::ObstacleDistance{&field, &solids, 0.0}; }
};

gf::sim::MissionConfig openField() {
  const auto m = gf::sim::loadMissionConfig(std::string(GF_SOURCE_DIR) + "/config/scenarios/open_field.yaml");
  EXPECT_TRUE(m) << m.reason();
  return *m;
}

gf::sim::WorkerState workerAt(const Eigen::Vector3d& feet) {
  gf::sim::WorkerState w;
  w.feet_world = feet;
  w.p_world = feet + Eigen::Vector3d(0, 0, 0.9);
  return w;
}

gf::sim::RequestRecord operatorRecord(double t_s) {
  gf::sim::RequestRecord r;
  r.t_s = t_s;
  r.source = "operator";
  r.status = "lost";
  return r;
}

}  // namespace

// ---- obstacle distance ------------------------------------------------------------------

TEST(ObstacleDistanceTest, ExactNearTheSolidsFieldValueFarAway) {
  const BoxWorld w;
  const gf::sim::ObstacleDistance d = w.exact();
  // 1.7 m in front of the box face x = 11 (2 m above the ground): the exact distance.
  EXPECT_NEAR(d(Eigen::Vector3d(12.7, 0, 2)), 1.7, 1e-12);
  // Above the ground, near nothing else: the ground plane wins.
  EXPECT_NEAR(d(Eigen::Vector3d(13.0, 0, 1.2)), 1.2, 1e-12);
  // Far from everything: the distance field's value.
  const Eigen::Vector3d far(-20, -20, 10);
  EXPECT_EQ(d(far), w.field.clearance(far));
  // Without solids: the field everywhere (voxel centres, not the face).
  const gf::sim::ObstacleDistance field_only{&w.field, nullptr, 0.0};
  EXPECT_EQ(field_only(Eigen::Vector3d(12.7, 0, 2)), w.field.clearance(Eigen::Vector3d(12.7, 0, 2)));
}

// ---- safety -----------------------------------------------------------------------------

TEST(MetricsAccumulatorTest, SafetyCountsCollisionOnsetsAndKeepsMinima) {
  const BoxWorld w;
  const auto cfg = openField();
  ASSERT_EQ(cfg.uavs.size(), 3u);
  const double r01 = cfg.uavs[0].plant.body_radius_m + cfg.uavs[1].plant.body_radius_m;
  MetricsAccumulator acc(cfg, w.exact(), 1);
  const auto worker = workerAt(Eigen::Vector3d(-10, 10, 3));  // on a 3 m platform (the metrics do not mind)
  const Eigen::Vector3d p2(-20, -10, 5);
  // UAV 0 and 1: apart, touching (onset), touching, apart, touching again (second onset).
  const double gaps[] = {3.0, 0.5 * r01, 0.4 * r01, 2.0, 0.3 * r01};
  double t = 0.0;
  for (const double gap : gaps) {
    acc.sampleSafety(t, {Eigen::Vector3d(0, -10, 5), Eigen::Vector3d(gap, -10, 5), p2}, worker);
    t += 0.01;
  }
  // UAV 2 flies into the worker's cylinder (r 0.3 m, feet → head) once.
  acc.sampleSafety(t, {Eigen::Vector3d(0, -10, 5), Eigen::Vector3d(3, -10, 5), Eigen::Vector3d(-10, 10.2, 4.0)}, worker);
  // UAV 0 next to the box: 1.7 m (exact), no collision.
  acc.sampleSafety(t + 0.01, {Eigen::Vector3d(12.7, 0, 2), Eigen::Vector3d(3, -10, 5), p2}, worker);
  const auto out = acc.finish({}, 1.0, 1.0);
  EXPECT_EQ(out.metrics.collisions, 3);
  EXPECT_NEAR(out.metrics.min_mutual_distance_m, 0.3 * r01, 1e-12);
  EXPECT_NEAR(out.metrics.min_human_distance_m, (Eigen::Vector3d(-10, 10.2, 4.0) - worker.p_world).norm(), 1e-12);
  EXPECT_NEAR(out.metrics.min_obstacle_distance_m, 1.7, 1e-12);
  EXPECT_EQ(out.metrics.min_obstacle_uav, 0);
  EXPECT_NEAR(out.metrics.min_obstacle_t_s, t + 0.01, 1e-12);
}

TEST(MetricsAccumulatorTest, TimelineErrorsAgainstTheFormationReference) {
  const BoxWorld w;
  const auto cfg = openField();
  MetricsAccumulator acc(cfg, w.exact(), 1);
  gf::sim::TimelineInput in;
  in.t_s = 2.0;
  in.worker = workerAt(Eigen::Vector3d(-10, 0, 0));
  in.params = cfg.formation.params;
  in.human_heading_rad = 0.0;
  // Every UAV exactly at its reference, then UAV 1 moved 1 m farther out along its ray.
  const gf::formation::UavReference lref =
      gf::formation::leaderReference(in.worker.p_world, 0.0, in.params.leader);
  for (int i = 0; i < 3; ++i) {
    gf::sim::MultirotorState s;
    s.p_world = i == 0 ? lref.p_world
                       : gf::formation::followerReference(in.worker.p_world, lref.heading_rad, lref.pitch_rad,
                                                          in.params.followers[static_cast<std::size_t>(i - 1)])
                             .p_world;
    in.uavs.push_back(s);
  }
  const Eigen::Vector3d ray = (in.uavs[1].p_world - in.worker.p_world).normalized();
  in.uavs[1].p_world += ray;
  acc.sampleTimeline(in);
  const auto out = acc.finish({}, 2.0, 1.0);
  ASSERT_EQ(out.timeline.size(), 1u);
  const auto& row = out.timeline[0];
  EXPECT_NEAR(row.uavs[0].d_t - row.uavs[0].d_ref, 0.0, 1e-9);
  EXPECT_NEAR(row.uavs[1].d_t - row.uavs[1].d_ref, 1.0, 1e-9);
  EXPECT_NEAR(row.uavs[2].d_t - row.uavs[2].d_ref, 0.0, 1e-9);
  EXPECT_NEAR(out.metrics.distance_error_rms_m, std::sqrt(1.0 / 3.0), 1e-9);
  EXPECT_NEAR(out.metrics.angle_error_rms_deg, 0.0, 1e-6);  // moved along its own azimuth
  EXPECT_EQ(row.mutual_m.size(), 3u);
  EXPECT_EQ(row.uavs[1].plan_status, -1);  // no plan fed yet
}

// ---- requests, adaptation starts, gestures ---------------------------------------------

TEST(MetricsAccumulatorTest, AdaptationStartIsTheEarliestPlanOfAnAddressedUavWithTheNewVersion) {
  const BoxWorld w;
  const auto cfg = openField();
  MetricsAccumulator acc(cfg, w.exact(), 1);
  const std::size_t r = acc.addRequest(operatorRecord(5.0));
  acc.requestOutcome(r, "applied", 5.1, 1, {1, 2});
  using PS = gf::planning::PlanStatus;
  acc.plan(0, 5.2, 1, PS::kOptimized, 1.0, "");   // not addressed
  acc.plan(2, 5.15, 0, PS::kOptimized, 1.0, "");  // the old parameters
  acc.plan(2, 5.6, 1, PS::kOptimized, 1.0, "");
  acc.plan(1, 5.3, 1, PS::kFallbackPrevious, 1.0, "QP primal infeasible at 3.5 s");  // fed later, earlier in time
  EXPECT_EQ(acc.lastPlanStatus(1), static_cast<int>(PS::kFallbackPrevious));
  const auto out = acc.finish({}, 10.0, 1.0);
  ASSERT_EQ(out.requests.size(), 1u);
  EXPECT_DOUBLE_EQ(out.requests[0].adaptation_start_s, 5.3);
  EXPECT_EQ(out.metrics.requests_applied, 1);
  EXPECT_EQ(out.metrics.operator_requests_applied, 1);
  EXPECT_EQ(out.metrics.plans, 4);
  EXPECT_EQ(out.metrics.plans_fallback_previous, 1);
  ASSERT_EQ(out.metrics.plan_failure_reasons.size(), 1u);
  EXPECT_EQ(out.metrics.plan_failure_reasons.begin()->first, "QP primal infeasible at # s");
}

TEST(MetricsAccumulatorTest, PlanningTimeMedianP99AndMax) {
  const BoxWorld w;
  const auto cfg = openField();
  MetricsAccumulator acc(cfg, w.exact(), 1);
  using PS = gf::planning::PlanStatus;
  // 200 plans of 1..200 ms, fed out of order: median 100.5, p99 the 198th value, max 200.
  for (int i = 0; i < 200; ++i) acc.plan(0, 0.1 * i, 0, PS::kOptimized, static_cast<double>((i * 37) % 200 + 1), "");
  const auto out = acc.finish({}, 30.0, 1.0);
  EXPECT_DOUBLE_EQ(out.metrics.planning_ms_median, 100.5);
  EXPECT_DOUBLE_EQ(out.metrics.planning_ms_p99, 198.0);
  EXPECT_DOUBLE_EQ(out.metrics.planning_ms_max, 200.0);
  EXPECT_NE(gf::sim::metricsJson(out.metrics).find("\"planning_ms_max\": 200,"), std::string::npos)
      << gf::sim::metricsJson(out.metrics);
}

TEST(MetricsAccumulatorTest, OutcomesFindTheirPendingRequestAndAnAppliedOneStaysApplied) {
  const BoxWorld w;
  const auto cfg = openField();
  MetricsAccumulator acc(cfg, w.exact(), 1);
  const std::size_t a = acc.addRequest(operatorRecord(5.0));
  const std::size_t b = acc.addRequest(operatorRecord(5.0));  // same instant: first come, first matched
  EXPECT_FALSE(acc.findPending("operator", 5.01));
  EXPECT_FALSE(acc.findPending("gesture", 5.0));
  ASSERT_TRUE(acc.findPending("operator", 5.0 + 1e-8));
  EXPECT_EQ(*acc.findPending("operator", 5.0), a);
  acc.requestOutcome(a, "applied", 5.1, 1, {0, 0, 2});
  EXPECT_EQ(*acc.findPending("operator", 5.0), b);
  acc.requestOutcome(a, "duplicate", 5.3, 0, {});  // a late copy changes nothing
  EXPECT_EQ(acc.request(a).status, "applied");
  EXPECT_DOUBLE_EQ(acc.request(a).applied_s, 5.1);
  EXPECT_EQ(acc.request(a).uavs, std::vector<int>({0, 2}));
  acc.requestOutcome(b, "rejected", 5.1, 0, {});
  EXPECT_FALSE(acc.findPending("operator", 5.0));
  const auto out = acc.finish({}, 10.0, 1.0);
  EXPECT_EQ(out.metrics.requests_applied, 1);
  EXPECT_EQ(out.requests[1].status, "rejected");
}

TEST(MetricsAccumulatorTest, StampedOutcomesWaitForTheirRequestAndMatchWithinTheTolerance) {
  const BoxWorld w;
  const auto cfg = openField();
  MetricsAccumulator acc(cfg, w.exact(), 1);
  const std::size_t a = acc.addRequest(operatorRecord(5.0));
  // A repeated copy stamped 0.4 s after the request (the first copies lost on the radio).
  acc.commandOutcome(CommandOutcome{"operator", "applied", 5.4, 5.45, 1, {0, 1, 2}}, 0.6);
  EXPECT_TRUE(acc.unmatchedOutcomes().empty());
  EXPECT_EQ(acc.request(a).status, "applied");
  EXPECT_DOUBLE_EQ(acc.request(a).applied_s, 5.45);
  // An outcome outside the tolerance, and one that arrives before its request, wait.
  acc.commandOutcome(CommandOutcome{"operator", "applied", 9.0, 9.05, 2, {0}}, 0.6);
  acc.commandOutcome(CommandOutcome{"gesture", "applied", 12.0, 12.01, 3, {0, 1, 2}}, 0.6);
  ASSERT_EQ(acc.unmatchedOutcomes().size(), 2u);
  const std::size_t g = acc.addRequest(operatorRecord(12.0));  // an operator request at 12 s: not the gesture's
  acc.resolveOutcomes(0.6);
  EXPECT_EQ(acc.unmatchedOutcomes().size(), 2u);
  EXPECT_EQ(acc.request(g).status, "lost");
  RequestRecord fired = operatorRecord(12.0);
  fired.source = "gesture";
  const std::size_t h = acc.addRequest(fired);
  acc.resolveOutcomes(0.6);
  ASSERT_EQ(acc.unmatchedOutcomes().size(), 1u);
  EXPECT_DOUBLE_EQ(acc.unmatchedOutcomes().front().issued_s, 9.0);
  EXPECT_EQ(acc.request(h).status, "applied");
  EXPECT_EQ(acc.request(h).params_version, 3u);
}

TEST(ParamsVersionsTest, LatestVersionWithExactlyTheseParameters) {
  const auto cfg = openField();
  const gf::formation::FormationParams p0 = cfg.formation.params;
  ParamsVersions v(p0);
  EXPECT_EQ(v.versionOf(p0), std::optional<std::uint64_t>(0));
  gf::formation::FormationParams p1 = p0;
  p1.uav(1).distance_m += 1.0;
  EXPECT_FALSE(v.versionOf(p1));
  v.published(1, p1);
  v.published(1, p0);  // not newer: ignored
  EXPECT_EQ(v.versionOf(p1), std::optional<std::uint64_t>(1));
  EXPECT_EQ(v.versionOf(p0), std::optional<std::uint64_t>(0));
  v.published(2, p0);  // back to the first parameters: the latest version wins
  EXPECT_EQ(v.versionOf(p0), std::optional<std::uint64_t>(2));
}

TEST(MetricsAccumulatorTest, GestureMatchingSuccessLatencyAndFalseAdaptations) {
  const BoxWorld w;
  auto cfg = openField();
  const auto mapping = gf::gesture::GestureMapping::paperDefault();
  MetricsAccumulator acc(cfg, w.exact(), 1);
  const std::vector<gf::sim::GestureEpisode> eps = {{2, 10.0, 10.0, 14.0}, {3, 30.0, 30.0, 33.0}, {4, 60.0, 60.0, 63.0}};
  // Gesture 2 fired at 12 s, applied, first plan with it at 12.4 s (before the worker lowered the arm).
  const std::size_t g2 = acc.addRequest(gf::sim::firedGestureRecord(12.0, 2, mapping));
  EXPECT_EQ(acc.request(g2).status, "lost");
  EXPECT_EQ(acc.request(g2).description, "gesture 2 → leader.beta_deg +30");
  acc.requestOutcome(g2, "applied", 12.05, 1, {0, 1, 2});
  acc.plan(0, 12.4, 1, gf::planning::PlanStatus::kOptimized, 1.0, "");
  // Gesture 3 fired 25 s after the worker started it: beyond the 20 s match window.
  ASSERT_DOUBLE_EQ(cfg.gesture_match_window_s, 20.0);
  const std::size_t g3 = acc.addRequest(gf::sim::firedGestureRecord(55.0, 3, mapping));
  acc.requestOutcome(g3, "applied", 55.0, 2, {0, 1, 2});
  // Gesture 4 fired during the episode but adapted only after it ended.
  const std::size_t g4 = acc.addRequest(gf::sim::firedGestureRecord(62.5, 4, mapping));
  acc.requestOutcome(g4, "applied", 62.5, 3, {0, 1, 2});
  acc.plan(1, 63.5, 3, gf::planning::PlanStatus::kOptimized, 1.0, "");
  const auto out = acc.finish(eps, 100.0, 1.0);
  EXPECT_EQ(out.metrics.gestures_performed, 3);
  EXPECT_EQ(out.metrics.gestures_successful, 1);
  EXPECT_EQ(out.metrics.false_adaptations, 1);
  EXPECT_NEAR(out.metrics.gesture_success_rate, 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(out.metrics.gesture_mean_latency_s, ((12.4 - 10.0) + (63.5 - 60.0)) / 2.0, 1e-12);
  EXPECT_EQ(out.requests[0].matched_episode, 0);
  EXPECT_EQ(out.requests[1].matched_episode, -1);
  EXPECT_EQ(out.requests[2].matched_episode, 2);
  EXPECT_EQ(out.metrics.requests_total, static_cast<int>(cfg.requests.size()) + 3);
  EXPECT_EQ(out.metrics.gesture_requests_applied, 3);
}

TEST(MetricsAccumulatorTest, EstimateErrorAndVisibilityFromCameraFrames) {
  const BoxWorld w;
  const auto cfg = openField();
  MetricsAccumulator acc(cfg, w.exact(), 1);
  const Eigen::Vector3d truth(1, 2, 3), off(1, 2, 3.3);
  acc.cameraFrame(false, nullptr, truth);  // before the estimator's first fix: not counted
  acc.cameraFrame(true, &off, truth);
  acc.cameraFrame(true, &off, truth);
  acc.cameraFrame(false, &truth, truth);
  const auto out = acc.finish({}, 1.0, 1.0);
  EXPECT_NEAR(out.metrics.human_estimate_error_rms_m, std::sqrt(2.0 * 0.09 / 3.0), 1e-12);
  EXPECT_DOUBLE_EQ(out.metrics.visible_fraction, 0.5);
}

// ---- metrics.json -----------------------------------------------------------------------

TEST(MetricsJsonTest, Design84KeysFirstAndUnmeasuredOnesNull) {
  gf::sim::MissionMetrics m;
  m.plans_hold = 4;
  m.messages_sent = 10;
  std::string j = gf::sim::metricsJson(m);
  const char* keys[] = {"min_mutual_distance_m", "min_obstacle_distance_m", "min_human_distance_m", "collisions",
                        "distance_error_rms_m", "angle_error_rms_deg", "requests_applied", "gesture_success_rate",
                        "gesture_mean_latency_s", "false_adaptations", "planning_ms_median", "planning_ms_p99",
                        "human_estimate_error_rms_m"};
  std::size_t last = 0;
  for (const char* k : keys) {
    const auto at = j.find(std::string("\"") + k + "\": ");
    ASSERT_NE(at, std::string::npos) << k;
    EXPECT_GT(at, last) << k << " out of docs/design.md §8.4 order";
    last = at;
  }
  EXPECT_NE(j.find("\"plans_hold\": 4,"), std::string::npos);
  EXPECT_EQ(j.find("not_measured_keys"), std::string::npos);
  m.not_measured = {"plans_hold", "messages_sent"};
  j = gf::sim::metricsJson(m);
  EXPECT_NE(j.find("\"plans_hold\": null,"), std::string::npos) << j;
  EXPECT_NE(j.find("\"messages_sent\": null,"), std::string::npos) << j;
  EXPECT_NE(j.find("\"plans_fallback_brake\": 0,"), std::string::npos) << j;
  EXPECT_NE(j.find("\"not_measured_keys\": [\"plans_hold\", \"messages_sent\"],"), std::string::npos) << j;
}

// ---- step schedule ----------------------------------------------------------------------

TEST(StepScheduleTest, FiresAtTheRoundedMultiplesOfThePeriod) {
  gf::sim::StepSchedule s(1.0 / 15.0, 0.01);  // a 15 Hz camera on a 10 ms clock
  std::set<long> due;
  for (long k = 0; k <= 300; ++k) {
    if (s.due(k)) due.insert(k);
  }
  std::set<long> expected;  // round(n · 100 / 15) = round(20 n / 3): fractions are 0, 1/3, 2/3
  for (long n = 0; (20 * n + 1) / 3 <= 300; ++n) expected.insert((20 * n + 1) / 3);
  EXPECT_EQ(due, expected);
  EXPECT_EQ(due.count(7), 1u);
  EXPECT_EQ(due.count(6), 0u);
}

// ---- the leader's camera ----------------------------------------------------------------

namespace {

/// Test-only classifier: always gesture 3; counts its calls.
class FixedClassifier : public gf::sim::MissionClassifier {
 public:
  gf::common::Result<gf::gesture::Classification> classify(const gf::gesture::SkeletonWindow&) override {
    ++calls;
    gf::gesture::Classification c;
    c.gesture_id = 3;
    return gf::common::Result<gf::gesture::Classification>::ok(c);
  }
  int calls = 0;
};

/// The leader at its formation reference around the worker at t (it sees the worker).
gf::sim::MultirotorState leaderAt(const gf::sim::MissionConfig& cfg, const gf::sim::WorkerState& ws) {
  const auto ref = gf::formation::leaderReference(ws.p_world, 0.0, cfg.formation.params.leader);
  gf::sim::MultirotorState s;
  s.p_world = ref.p_world;
  s.heading_rad = ref.heading_rad;
  s.pitch_rad = ref.pitch_rad;
  return s;
}

gf::sim::WorkerModel workerModel(const gf::sim::MissionConfig& cfg, std::uint64_t seed) {
  return gf::sim::WorkerModel(cfg.worker, gf::sim::mixSeed(seed ^ static_cast<std::uint64_t>(gf::sim::Stream::kWorker)));
}

}  // namespace

TEST(LeaderCameraTest, DeterministicForTheSeedAndSeesTheWorkerFromTheReference) {
  const auto cfg = openField();
  gf::sim::LeaderCamera a(cfg, nullptr, 5), b(cfg, nullptr, 5), c(cfg, nullptr, 6);
  auto wa = workerModel(cfg, 5), wb = workerModel(cfg, 5), wc = workerModel(cfg, 6);
  int visible = 0, differs = 0;
  for (int k = 0; k < 60; ++k) {
    const double t = k / cfg.camera.rate_hz;
    const auto ws = wa.stateAt(t);
    const auto fa = a.frame(t, leaderAt(cfg, ws), ws, wa, nullptr);
    const auto fb = b.frame(t, leaderAt(cfg, ws), ws, wb, nullptr);
    const auto fc = c.frame(t, leaderAt(cfg, ws), ws, wc, nullptr);
    ASSERT_EQ(fa.sensors.visibility, fb.sensors.visibility);
    ASSERT_EQ(fa.sensors.box.u, fb.sensors.box.u);
    ASSERT_EQ(std::isnan(fa.sensors.d_uwb_m), std::isnan(fb.sensors.d_uwb_m));
    if (!std::isnan(fa.sensors.d_uwb_m)) {
      ASSERT_EQ(fa.sensors.d_uwb_m, fb.sensors.d_uwb_m);
    }
    visible += fa.sensors.visible() ? 1 : 0;
    differs += fa.sensors.box.u != fc.sensors.box.u ? 1 : 0;
  }
  EXPECT_GE(visible, 50);  // 5 % dropout
  EXPECT_GT(differs, 10);  // another seed, other noise
}

TEST(LeaderCameraTest, InjectedRangeOutliersAndBlackouts) {
  auto cfg = openField();
  cfg.faults.range_outliers.probability = 1.0;
  gf::sim::LeaderCamera cam(cfg, nullptr, 2);
  auto worker = workerModel(cfg, 2);
  int ranges = 0, outliers = 0;
  for (int k = 0; k < 40; ++k) {
    const double t = k / cfg.camera.rate_hz;
    const auto ws = worker.stateAt(t);
    const auto f = cam.frame(t, leaderAt(cfg, ws), ws, worker, nullptr);
    outliers += f.range_outliers;
    for (const double d : {f.sensors.d_uwb_m, f.sensors.d_stereo_m}) {
      if (std::isnan(d)) continue;
      ++ranges;
      // min_error_m 3 m, minus the sensors' noise (UWB 0.1 m, stereo 0.3 m: 5σ)
      EXPECT_GT(std::abs(d - f.sensors.true_range_m), cfg.faults.range_outliers.min_error_m - 1.5) << t;
    }
  }
  EXPECT_GT(ranges, 40);
  EXPECT_EQ(outliers, ranges);

  auto dark = openField();
  dark.faults.camera_blackouts = {{0.0, 100.0}};
  gf::sim::LeaderCamera blind(dark, nullptr, 2);
  auto w2 = workerModel(dark, 2);
  const auto ws = w2.stateAt(0.0);
  const auto f = blind.frame(0.0, leaderAt(dark, ws), ws, w2, nullptr);
  EXPECT_EQ(f.sensors.visibility, gf::sim::Visibility::kBlackout);
  EXPECT_DOUBLE_EQ(blind.lastVisibleS(), -1e9);
}

TEST(LeaderCameraTest, ClassifiesFullWindowsAndRestartsTheFifoAfterAGap) {
  auto cfg = openField();
  cfg.camera.detection_dropout = 0.0;
  const double gap_from = 20.0 / cfg.camera.rate_hz;  // frames 20..: a 1 s blackout
  cfg.faults.camera_blackouts = {{gap_from, gap_from + 1.0}};
  gf::sim::LeaderCamera cam(cfg, nullptr, 3);
  auto worker = workerModel(cfg, 3);
  FixedClassifier lstm;
  std::vector<int> classified;  // frame indices with a classification
  std::vector<int> seen;
  for (int k = 0; k < 60; ++k) {
    const double t = k / cfg.camera.rate_hz;
    const auto ws = worker.stateAt(t);
    const auto f = cam.frame(t, leaderAt(cfg, ws), ws, worker, &lstm);
    if (f.sensors.visible()) seen.push_back(k);
    if (f.classification) {
      EXPECT_EQ(f.classification->gesture_id, 3);
      classified.push_back(k);
    }
  }
  ASSERT_GE(seen.size(), 40u);
  ASSERT_EQ(seen.front(), 0);
  // The first classification on the 9th visible frame; after the gap, 9 visible frames again.
  const int window = static_cast<int>(gf::gesture::kWindowFrames);
  ASSERT_FALSE(classified.empty());
  EXPECT_EQ(classified.front(), seen[static_cast<std::size_t>(window - 1)]);
  const auto after = std::find_if(seen.begin(), seen.end(), [&](int k) { return k / cfg.camera.rate_hz > gap_from; });
  ASSERT_NE(after, seen.end());
  ASSERT_LT(after + window - 1, seen.end());
  const int first_after_gap = *(after + window - 1);
  for (const int k : classified) EXPECT_FALSE(k >= *after && k < first_after_gap) << k;
  EXPECT_NE(std::find(classified.begin(), classified.end(), first_after_gap), classified.end());
  EXPECT_EQ(lstm.calls, static_cast<int>(classified.size()));
}

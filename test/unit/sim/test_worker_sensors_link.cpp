// Worker model, synthetic sensors, links and the mission loader (issue 7 steps 2, 3, 5).
#include <gtest/gtest.h>

#include <cmath>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/estimation/measurement_model.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/sim/link.hpp"
#include "gesture_formation/sim/mission_config.hpp"
#include "gesture_formation/sim/random.hpp"
#include "gesture_formation/sim/synthetic_sensors.hpp"
#include "gesture_formation/sim/worker_model.hpp"

namespace gf = gesture_formation;
using gf::sim::RouteLeg;

namespace {
gf::sim::WorkerConfig simpleWorker() {
  gf::sim::WorkerConfig w;
  w.start_feet_world = Eigen::Vector3d(0, 0, 0);
  RouteLeg walk;
  walk.kind = RouteLeg::Kind::kWalk;
  walk.to_feet_world = Eigen::Vector3d(10, 0, 0);
  walk.speed_mps = 1.0;
  RouteLeg climb;
  climb.kind = RouteLeg::Kind::kClimb;
  climb.to_feet_world = Eigen::Vector3d(10, 0, 5);
  climb.speed_mps = 0.5;
  RouteLeg work;
  work.kind = RouteLeg::Kind::kWork;
  work.duration_s = 40.0;
  w.route = {walk, climb, work};
  w.gestures = {{25.0, 2}};
  return w;
}
}  // namespace

TEST(WorkerModelTest, FollowsRouteWithMidBodyPosition) {
  const auto cfg = simpleWorker();
  ASSERT_TRUE(cfg.validate().empty());
  EXPECT_DOUBLE_EQ(cfg.routeDuration(), 10.0 + 10.0 + 40.0);
  gf::sim::WorkerModel w(cfg, 1);
  const auto s5 = w.stateAt(5.0);
  EXPECT_NEAR(s5.feet_world.x(), 5.0, 1e-12);
  EXPECT_NEAR(s5.p_world.z(), 0.5 * cfg.height_m, 1e-12);
  EXPECT_NEAR(s5.v_world.x(), 1.0, 1e-12);
  EXPECT_NEAR(s5.heading_rad, 0.0, 1e-12);  // faces the walking direction
  const auto s15 = w.stateAt(15.0);
  EXPECT_EQ(s15.kind, RouteLeg::Kind::kClimb);
  EXPECT_NEAR(s15.feet_world.z(), 2.5, 1e-12);
  const auto s100 = w.stateAt(100.0);
  EXPECT_NEAR(s100.feet_world.z(), 5.0, 1e-12);
  EXPECT_EQ(s100.v_world.norm(), 0.0);
}

TEST(WorkerModelTest, PerformsScheduledGestureAndWorkMotionsOtherwise) {
  gf::sim::WorkerModel w(simpleWorker(), 4);
  const Eigen::Vector3d cam(10, 8, 7);
  int gesture_frames = 0, other_nonzero = 0;
  for (int k = 0; k < 15 * 60; ++k) {
    const double t = k / 15.0;
    const auto f = w.skeletonAt(t, cam);
    EXPECT_GT(f.skeleton.h, 5.0);
    if (f.label == 2) ++gesture_frames;
    if (f.label != 0 && f.label != 2) ++other_nonzero;
  }
  ASSERT_EQ(w.episodes().size(), 1u);
  const auto& ep = w.episodes()[0];
  EXPECT_EQ(ep.gesture_id, 2);
  EXPECT_GE(ep.start_s, 25.0);
  EXPECT_GE(ep.end_s - ep.start_s, 3.0);  // held ≥ gesture_hold_min_s
  EXPECT_GT(gesture_frames, 15 * 3 - 5);
  EXPECT_EQ(other_nonzero, 0);  // work motions are never labelled as gestures
  EXPECT_EQ(w.performingAt(0.5 * (ep.start_s + ep.end_s)), 2);
  EXPECT_EQ(w.performingAt(ep.end_s + 1.0), 0);
}

TEST(WorkerModelTest, ValidateRejectsGestureWhileWalkingAndNamesFields) {
  auto cfg = simpleWorker();
  cfg.gestures = {{3.0, 2}, {30.0, 7}};
  cfg.route[0].speed_mps = -1.0;
  const auto e = cfg.validate("mission.worker.");
  std::string all;
  for (const auto& s : e) all += s + "\n";
  EXPECT_NE(all.find("mission.worker.route[0].speed_mps must be in (0, 3], got -1"), std::string::npos) << all;
  EXPECT_NE(all.find("mission.worker.gestures[0].t_s 3 must lie in a work or wait leg"), std::string::npos) << all;
  EXPECT_NE(all.find("mission.worker.gestures[1].gesture must be in [1, 4], got 7"), std::string::npos) << all;
}

TEST(SyntheticSensorsTest, CameraPoseLooksAlongHeadingAndPitch) {
  const auto pose = gf::sim::cameraPose(Eigen::Vector3d(1, 2, 3), gf::common::degToRad(90), gf::common::degToRad(-30));
  const Eigen::Matrix3d R = pose.q_world_camera.toRotationMatrix();
  EXPECT_NEAR((R.col(2) - Eigen::Vector3d(0, std::cos(0.5236), -0.5)).norm(), 0.0, 1e-3);  // forward
  EXPECT_NEAR(R.col(0).z(), 0.0, 1e-12);   // x right stays horizontal
  EXPECT_LT(R.col(1).z(), 0.0);            // y points down
}

TEST(SyntheticSensorsTest, BoxFeedsEstimatorToWithinNoise) {
  gf::sim::CameraSensorConfig cc;
  cc.detection_dropout = 0.0;
  cc.pixel_noise_px = 0.0;
  gf::sim::RangeSensorConfig clean{0.0, 50.0, 0.0};
  gf::sim::SyntheticSensors s(cc, clean, clean, nullptr, std::mt19937_64(1), std::mt19937_64(2), std::mt19937_64(3));
  const Eigen::Vector3d feet(10, 0, 0), mid(10, 0, 0.89);
  const Eigen::Vector3d cam(0, 0, 3);
  const Eigen::Vector3d d = mid - cam;
  const auto pose = gf::sim::cameraPose(cam, std::atan2(d.y(), d.x()), std::asin(d.z() / d.norm()));
  const auto f = s.observe(pose, feet, mid, 1.78);
  ASSERT_TRUE(f.visible()) << toString(f.visibility);
  EXPECT_NEAR(f.d_uwb_m, d.norm(), 1e-12);
  EXPECT_NEAR(f.d_stereo_m, d.norm(), 1e-12);
  const auto m = gf::estimation::makeMeasurement(s.camera(), pose, f.box, f.d_uwb_m, f.d_stereo_m, 1.78,
                                                 gf::estimation::MeasurementNoise{}, 40.0);
  ASSERT_TRUE(m);
  EXPECT_LT((m->z_world - mid).norm(), 0.1);  // box centre ≈ mid-body (perspective only)
  // Behind the camera / out of the field of view: no box.
  const auto away = gf::sim::cameraPose(cam, std::atan2(d.y(), d.x()) + 3.14159, 0.0);
  EXPECT_EQ(s.observe(away, feet, mid, 1.78).visibility, gf::sim::Visibility::kOutOfView);
  EXPECT_EQ(s.observe(pose, feet, mid, 1.78, true).visibility, gf::sim::Visibility::kBlackout);
}

TEST(SyntheticSensorsTest, WallOccludesThinWireDoesNot) {
  gf::planning::MapConfig mc;
  mc.bounds = gf::planning::Aabb{Eigen::Vector3d(-2, -5, 0), Eigen::Vector3d(14, 5, 6)};
  gf::planning::PrimitiveSet solids;
  gf::planning::OrientedBox wall;
  wall.center_world = Eigen::Vector3d(5, 0, 1.5);
  wall.size_m = Eigen::Vector3d(0.2, 4, 3);
  solids.boxes.push_back(wall);
  const auto map = gf::planning::OccupancyMap::fromPrimitives(mc, solids, gf::planning::GroundSpec{});
  gf::planning::PrimitiveSet wire_solids;
  wire_solids.cylinders.push_back(gf::planning::Cylinder{Eigen::Vector3d(5, -4, 2.0), Eigen::Vector3d(5, 4, 2.0), 0.015});
  const auto wire_map = gf::planning::OccupancyMap::fromPrimitives(mc, wire_solids, gf::planning::GroundSpec{});
  gf::sim::CameraSensorConfig cc;
  cc.detection_dropout = 0.0;
  const Eigen::Vector3d feet(10, 0, 0), mid(10, 0, 0.89), cam(0, 0, 2.0);
  const Eigen::Vector3d d = mid - cam;
  const auto pose = gf::sim::cameraPose(cam, 0.0, std::asin(d.z() / d.norm()));
  gf::sim::RangeSensorConfig rs;
  gf::sim::SyntheticSensors walled(cc, rs, rs, &map, std::mt19937_64(1), std::mt19937_64(2), std::mt19937_64(3));
  gf::sim::SyntheticSensors wired(cc, rs, rs, &wire_map, std::mt19937_64(1), std::mt19937_64(2), std::mt19937_64(3));
  EXPECT_EQ(walled.observe(pose, feet, mid, 1.78).visibility, gf::sim::Visibility::kOccluded);
  EXPECT_EQ(wired.observe(pose, feet, mid, 1.78).visibility, gf::sim::Visibility::kVisible);
}

TEST(SyntheticSensorsTest, RangeNoiseAndDropoutRates) {
  gf::sim::CameraSensorConfig cc;
  cc.detection_dropout = 0.1;
  gf::sim::RangeSensorConfig uwb{0.1, 40.0, 0.2};
  gf::sim::SyntheticSensors s(cc, uwb, uwb, nullptr, gf::sim::makeRng(1, gf::sim::Stream::kCamera),
                              gf::sim::makeRng(1, gf::sim::Stream::kStereo), gf::sim::makeRng(1, gf::sim::Stream::kUwb));
  const Eigen::Vector3d feet(8, 0, 0), mid(8, 0, 0.89), cam(0, 0, 2);
  const Eigen::Vector3d d = mid - cam;
  const auto pose = gf::sim::cameraPose(cam, 0.0, std::asin(d.z() / d.norm()));
  int visible = 0, uwb_n = 0;
  double sq = 0.0;
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const auto f = s.observe(pose, feet, mid, 1.78);
    visible += f.visible();
    if (std::isfinite(f.d_uwb_m)) {
      ++uwb_n;
      sq += std::pow(f.d_uwb_m - d.norm(), 2);
    }
  }
  EXPECT_NEAR(visible / double(n), 0.9, 0.01);
  EXPECT_NEAR(uwb_n / double(n), 0.8, 0.01);
  EXPECT_NEAR(std::sqrt(sq / uwb_n), 0.1, 0.005);
}

TEST(LinkTest, DelayLossAndOrder) {
  gf::sim::LinkConfig c;
  c.delay_s = 0.1;
  gf::sim::Link<int> clean(c, std::mt19937_64(1));
  clean.send(0.0, 1);
  clean.send(0.01, 2);
  EXPECT_TRUE(clean.receive(0.05).empty());
  EXPECT_EQ(clean.receive(0.105), std::vector<int>({1}));
  EXPECT_EQ(clean.receive(1.0), std::vector<int>({2}));
  c.loss_probability = 0.3;
  c.jitter_s = 0.05;
  gf::sim::Link<int> lossy(c, std::mt19937_64(9));
  for (int i = 0; i < 10000; ++i) lossy.send(i * 0.01, i);
  const auto got = lossy.receive(1e9);
  EXPECT_NEAR(got.size() / 10000.0, 0.7, 0.02);
  EXPECT_EQ(lossy.counters().lost + lossy.counters().delivered, 10000u);
}

TEST(MissionConfigTest, ShippedScenariosLoad) {
  for (const char* name : {"power_towers", "open_field", "dense_pillars"}) {
    const auto m = gf::sim::loadMissionConfig(std::string(GF_SOURCE_DIR) + "/config/scenarios/" + name + ".yaml");
    ASSERT_TRUE(m) << m.reason();
    EXPECT_EQ(m->uavs.size(), 3u);
  }
  const auto pt = gf::sim::loadMissionConfig(std::string(GF_SOURCE_DIR) + "/config/scenarios/power_towers.yaml");
  ASSERT_TRUE(pt);
  EXPECT_EQ(pt->requests.size() + pt->worker.gestures.size(), 25u);  // the paper's 25 requests
  EXPECT_GT(pt->requests.size(), pt->worker.gestures.size());        // most from the operator
  EXPECT_DOUBLE_EQ(pt->formation.params.leader.beta_deg, 90.0);      // Table II
  EXPECT_DOUBLE_EQ(pt->formation.params.followers[1].beta_deg, -60.0);
  EXPECT_DOUBLE_EQ(pt->formation.limits.safety_distance_m, 2.5);
}

// A formation whose cameras sit outside the classifier's validated envelope cannot accept a
// gesture (docs/gestures.md 4.1): gfctl simulate and SimWorld say so at the start.
TEST(MissionConfigTest, WarnsWhenTooFewCamerasAreInsideTheGestureEnvelope) {
  const auto pt = gf::sim::loadMissionConfig(std::string(GF_SOURCE_DIR) + "/config/scenarios/power_towers.yaml");
  ASSERT_TRUE(pt) << pt.reason();
  EXPECT_TRUE(gf::sim::gestureReadabilityWarnings(*pt).empty());  // Table II: 10 m at 11 deg, followers 8 m
  gf::sim::MissionConfig close = *pt;
  close.formation.params.followers[0].distance_m = 4.5;
  EXPECT_TRUE(gf::sim::gestureReadabilityWarnings(close).empty());  // leader + follower 2: 2 of 3, enough
  close.formation.params.followers[1].distance_m = 4.5;
  const auto w = gf::sim::gestureReadabilityWarnings(close);
  ASSERT_EQ(w.size(), 1u);
  for (const char* want : {"1 of 3 cameras", "follower 1 at 4.5 m, 11 deg", "follower 2 at 4.5 m", "5-20 m",
                           "2 needed", "3-D confirmation"}) {
    EXPECT_NE(w[0].find(want), std::string::npos) << "missing '" << want << "' in " << w[0];
  }
  close.view_fusion.gate_envelope = false;  // every camera votes: nothing to say
  EXPECT_TRUE(gf::sim::gestureReadabilityWarnings(close).empty());
  gf::sim::MissionConfig single = *pt;      // the paper's single camera: only the leader's counts
  single.view_fusion.min_agreeing_views = 1;
  single.formation.params.followers[0].distance_m = 4.5;
  EXPECT_TRUE(gf::sim::gestureReadabilityWarnings(single).empty());
  single.formation.params.leader.gamma_deg = 50.0;
  const auto ws = gf::sim::gestureReadabilityWarnings(single);
  ASSERT_EQ(ws.size(), 1u);
  EXPECT_NE(ws[0].find("0 of 1 cameras"), std::string::npos) << ws[0];
  EXPECT_NE(ws[0].find("the leader at 10 m, 50 deg"), std::string::npos) << ws[0];
  single.gesture_model.clear();             // no gestures read at all: nothing to say
  EXPECT_TRUE(gf::sim::gestureReadabilityWarnings(single).empty());
}

TEST(MissionConfigTest, ListsEveryProblem) {
  const std::string yaml = R"(
mission:
  step_s: 0.5
  worker: {start: [0, 0, 0], route: [{walk_to: [5, 0, 0], speed_mps: 9}]}
  uavs:
    - {plant: {mass_kg: 1.0}}
  requests:
    - {t_s: 1, target: follower9, parameter: beta_deg, increment: 3}
    - {t_s: 2, target: all, parameter: zeta_deg, increment: 3, set: 1}
  formation: {leader: {gamma_deg: 95}}
  typo: 3
)";
  const auto m = gf::sim::parseMissionConfig(yaml, "t.yaml", ".");
  ASSERT_FALSE(m);
  for (const char* want : {"mission.step_s: value 0.5 is out of range", "route[0].speed_mps: value 9",
                           "mission.uavs[0].plant.max_tilt_deg: missing", "follower9",
                           "mission.requests[1].parameter", "needs exactly one of increment, set",
                           "mission.formation.leader.gamma_deg", "mission.typo: unknown key",
                           "has 1 entries but mission.formation has 3 UAVs"}) {
    EXPECT_NE(m.reason().find(want), std::string::npos) << "missing '" << want << "' in\n" << m.reason();
  }
}

// bodyAt is the 3-D body whose projection skeletonsAt returned (the rendered camera poses the
// worker mesh from it): projected through the view's camera (WorkerModel::calibrated), it lies on
// the synthetic skeleton to within its keypoint noise, and it performs the gesture (the extended
// arm's wrist far to the side at shoulder height) during the episode.
TEST(WorkerModelTest, BodyAtIsTheBodyTheSkeletonShows) {
  gf::sim::WorkerModel w(simpleWorker(), 4);
  const Eigen::Vector3d cam(10, 8, 7);
  double max_median_frac = 0.0, max_shift_frac = 0.0;
  int frames = 0;
  double widest_wrist_m = 0.0;
  for (int k = 0; k < 15 * 60; k += 7) {
    const double t = k / 15.0;
    const auto f = w.skeletonAt(t, cam);
    const auto ws = w.stateAt(t);
    const gf::gesture::Body3D body = w.bodyAt(t);
    const auto cal = w.calibrated(0, f.skeleton, ws);
    const gf::estimation::CameraModel model(cal.intrinsics);
    const Eigen::Matrix3d R_world_body = Eigen::AngleAxisd(ws.heading_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    std::vector<Eigen::Vector2d> d;
    for (std::size_t i = 0; i < body.p.size(); ++i) {
      if (f.skeleton.c[i] <= 0.0) continue;
      const Eigen::Vector3d p_world = ws.feet_world + R_world_body * body.p[i];
      const auto px = model.project(cal.R_world_camera.transpose() * (p_world - cal.p_world_camera));
      ASSERT_TRUE(px.has_value());
      d.emplace_back(f.skeleton.x[i] - px->x(), f.skeleton.y[i] - px->y());
    }
    ASSERT_GE(d.size(), 8u);
    // The generator's aim jitter (σ 3 % of the height, left out of `calibrated`) shifts the whole
    // figure; what is left is the keypoint noise.
    Eigen::Vector2d shift = Eigen::Vector2d::Zero();
    for (const auto& v : d) shift += v / static_cast<double>(d.size());
    std::vector<double> err;
    for (const auto& v : d) err.push_back((v - shift).norm());
    max_shift_frac = std::max(max_shift_frac, shift.norm() / f.skeleton.h);
    std::nth_element(err.begin(), err.begin() + static_cast<long>(err.size() / 2), err.end());
    max_median_frac = std::max(max_median_frac, err[err.size() / 2] / f.skeleton.h);
    ++frames;
    if (w.performingAt(t) == 2 && f.label == 2) {
      for (const int wrist : {gf::gesture::kLeftWrist, gf::gesture::kRightWrist}) {
        const auto& p = body.p[static_cast<std::size_t>(wrist)];
        widest_wrist_m = std::max(widest_wrist_m, std::abs(p.y()));
      }
    }
  }
  EXPECT_GT(frames, 100);
  // keypoint noise σ ≤ 2.5 % of the box height (SynthConfig defaults): the median 2-D error of a
  // Gaussian is 1.18 σ ≤ 3 %; the shift is the aim jitter (σ 3 % of the height per axis)
  EXPECT_LT(max_median_frac, 0.05);
  EXPECT_LT(max_shift_frac, 0.15);
  EXPECT_GT(widest_wrist_m, 0.5);  // the arm extended to the side
}

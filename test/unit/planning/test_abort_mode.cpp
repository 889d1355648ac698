// planning::AbortPlanner and its goals (docs/safety.md §2.8): the retreat goal's properties —
// far enough from the worker, clear of obstacles, in the UAV's own layer (so distinct across
// UAVs), deterministic — the landing spot, the phases, the command's acceptance, the settings'
// validation, and the replanning step in abort (from track and from hold; listening first).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/planning/abort_mode.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/replan_step.hpp"
#include "gesture_formation/planning/scenario.hpp"

namespace gf = gesture_formation;
namespace pl = gf::planning;

namespace {

/// A 60 × 60 × 30 m world with ground at z = 0 and a thick wall east of the worker (x in [12, 22],
/// y in [-30, 30], up to 25 m): a UAV east of the worker cannot retreat straight out.
struct WallWorld {
  pl::PrimitiveSet solids;
  pl::OccupancyMap map;
  pl::DistanceField field;
  WallWorld() : WallWorld(makeSolids()) {}
  explicit WallWorld(pl::PrimitiveSet s) : solids(std::move(s)), map(makeMap(solids)), field(map) {}
  static pl::PrimitiveSet makeSolids() {
    pl::PrimitiveSet s;
    pl::OrientedBox wall;
    wall.center_world = Eigen::Vector3d(17.0, 0.0, 12.5);
    wall.size_m = Eigen::Vector3d(10.0, 60.0, 25.0);
    s.boxes.push_back(wall);
    pl::OrientedBox pillar;  // a pillar west of the worker, for the landing column
    pillar.center_world = Eigen::Vector3d(-20.0, 0.0, 2.0);
    pillar.size_m = Eigen::Vector3d(2.0, 2.0, 4.0);
    s.boxes.push_back(pillar);
    return s;
  }
  static pl::OccupancyMap makeMap(const pl::PrimitiveSet& s) {
    pl::MapConfig mc;
    mc.resolution_m = 0.4;
    mc.bounds = pl::Aabb{Eigen::Vector3d(-30, -30, 0), Eigen::Vector3d(30, 30, 30)};
    return pl::OccupancyMap::fromPrimitives(mc, s, pl::GroundSpec{true, 0.0});
  }
  pl::RetreatSpace space() const {
    pl::RetreatSpace r;
    r.field = &field;
    r.bounds = map.gridBounds();
    r.resolution_m = map.resolution();
    r.ground_height_m = 0.0;
    return r;
  }
};

const WallWorld& world() {
  static const WallWorld w;
  return w;
}

const Eigen::Vector3d kWorker(0.0, 0.0, 1.0);

}  // namespace

// ---- the retreat goal -----------------------------------------------------------------------

class RetreatGoalAroundTheWorker : public ::testing::TestWithParam<int> {};

TEST_P(RetreatGoalAroundTheWorker, IsFarFromTheWorkerClearOfObstaclesAndInTheUavsLayer) {
  const pl::AbortConfig c;
  const double bearing = GetParam() * M_PI / 8.0;  // UAVs all around the worker, also towards the wall
  for (int uav = 0; uav < 3; ++uav) {
    const Eigen::Vector3d p_uav = kWorker + Eigen::Vector3d(8.0 * std::cos(bearing), 8.0 * std::sin(bearing), 5.0);
    const auto g = pl::chooseRetreatGoal(uav, 3, p_uav, kWorker, world().space(), c);
    ASSERT_TRUE(g) << g.reason();
    // On one of its own rings: retreat_distance_m + (uav + k·3)·layer_spacing_m.
    const double ring = ((*g - kWorker).head<2>().norm() - c.retreat_distance_m - uav * c.layer_spacing_m) /
                        (3 * c.layer_spacing_m);
    EXPECT_GE(ring, -1e-9) << "uav " << uav;
    EXPECT_NEAR(ring, std::round(ring), 1e-9) << "uav " << uav;
    EXPECT_GE(world().field.clearance(*g), c.goal_clearance_m) << "uav " << uav;
    // Independently of the field: the exact distance to the solids and the ground.
    EXPECT_GE(world().solids.distance(*g), c.goal_clearance_m - world().map.resolution()) << "uav " << uav;
    EXPECT_GE(g->z(), c.goal_clearance_m);
    EXPECT_DOUBLE_EQ(g->z(), c.retreat_height_m + uav * c.layer_spacing_m);
    EXPECT_TRUE(world().map.gridBounds().inflated(-c.goal_clearance_m).contains(*g));
  }
}

INSTANTIATE_TEST_SUITE_P(Bearings, RetreatGoalAroundTheWorker, ::testing::Range(0, 16));

TEST(RetreatGoalTest, GoalsAndLandingSpotsOfDifferentUavsKeepGammaDisEvenFromOnePoint) {
  // Worst case: every UAV chooses from the same position (no negotiation between them).
  const pl::AbortConfig c;
  const Eigen::Vector3d p_uav = kWorker + Eigen::Vector3d(-6.0, 3.0, 4.0);
  std::vector<Eigen::Vector3d> goals;
  for (int uav = 0; uav < 4; ++uav) {
    const auto g = pl::chooseRetreatGoal(uav, 4, p_uav, kWorker, world().space(), c);
    ASSERT_TRUE(g) << g.reason();
    goals.push_back(*g);
  }
  for (std::size_t i = 0; i < goals.size(); ++i) {
    for (std::size_t j = i + 1; j < goals.size(); ++j) {
      EXPECT_GE((goals[i] - goals[j]).norm(), c.layer_spacing_m - 1e-9) << i << " " << j;
      EXPECT_GE((goals[i] - goals[j]).norm(), 2.5) << "Gamma_dis";
      // Horizontally too (the rings): the spots below them, where they would land, keep Γ_dis.
      EXPECT_GE((goals[i] - goals[j]).head<2>().norm(), c.layer_spacing_m - 1e-9) << i << " " << j;
    }
  }
}

TEST(RetreatGoalTest, IsDeterministic) {
  const pl::AbortConfig c;
  const Eigen::Vector3d p_uav = kWorker + Eigen::Vector3d(7.0, 1.0, 3.0);
  const auto a = pl::chooseRetreatGoal(1, 3, p_uav, kWorker, world().space(), c);
  const WallWorld other;  // another copy of the same map: the same goal
  pl::RetreatSpace s = other.space();
  const auto b = pl::chooseRetreatGoal(1, 3, p_uav, kWorker, s, c);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(*a, *b);
}

TEST(RetreatGoalTest, AUavFacingTheWallTurnsAsideAndAUavInTheOpenGoesStraightOut) {
  const pl::AbortConfig c;
  // East of the worker: straight out (bearing 0) lies in or beside the wall up to max_distance_m.
  const auto east = pl::chooseRetreatGoal(0, 3, kWorker + Eigen::Vector3d(8.0, 0.0, 5.0), kWorker, world().space(), c);
  ASSERT_TRUE(east) << east.reason();
  EXPECT_GT(std::abs(std::atan2(east->y(), east->x())), 0.1) << east->transpose();
  EXPECT_LT(east->x(), 12.0 - c.goal_clearance_m) << "not in or behind the wall: " << east->transpose();
  // West of the worker in the open: straight out, at the nearest allowed distance.
  const auto west = pl::chooseRetreatGoal(0, 3, kWorker + Eigen::Vector3d(-8.0, 0.0, 5.0), kWorker, world().space(), c);
  ASSERT_TRUE(west) << west.reason();
  EXPECT_NEAR(west->x(), -c.retreat_distance_m, 1e-9);
  EXPECT_NEAR(west->y(), 0.0, 1e-9);
}

// A map lower than the layers (the construction site's 16 m, the pillars' 14 m): the upper layers
// are put at the map's top less goal_clearance_m instead of leaving those UAVs without a goal
// (they stayed in formation beside the worker); the goals still keep layer_spacing_m horizontally.
TEST(RetreatGoalTest, LayersAboveTheMapAreKeptInsideItAndTheGoalsStillApart) {
  pl::AbortConfig c;
  c.retreat_height_m = 25.0;  // layers at 25, 29, 33 m: the map's top is 30 m
  const Eigen::Vector3d p_uav = kWorker + Eigen::Vector3d(-8, 0, 5);
  std::vector<Eigen::Vector3d> goals;
  for (int uav = 0; uav < 3; ++uav) {
    const auto g = pl::chooseRetreatGoal(uav, 3, p_uav, kWorker, world().space(), c);
    ASSERT_TRUE(g) << "UAV " << uav << ": " << g.reason();
    goals.push_back(*g);
  }
  EXPECT_NEAR(goals[0].z(), 25.0, 1e-9);
  EXPECT_NEAR(goals[1].z(), 30.0 - c.goal_clearance_m, 1e-9);
  EXPECT_NEAR(goals[2].z(), 30.0 - c.goal_clearance_m, 1e-9);
  for (std::size_t i = 0; i < goals.size(); ++i) {
    for (std::size_t j = i + 1; j < goals.size(); ++j) {
      EXPECT_GE((goals[i] - goals[j]).head<2>().norm(), c.layer_spacing_m - 1e-9) << i << " " << j;
    }
  }
}

TEST(RetreatGoalTest, FailsNamingWhyWhenNothingFitsOrTheMapIsTooThin) {
  pl::AbortConfig c;
  c.goal_clearance_m = 16.0;  // 2 × 16 m > the 30 m map: no height is 16 m inside it
  const auto thin = pl::chooseRetreatGoal(0, 3, kWorker + Eigen::Vector3d(-8, 0, 5), kWorker, world().space(), c);
  ASSERT_FALSE(thin);
  EXPECT_NE(thin.reason().find("no retreat layer fits"), std::string::npos) << thin.reason();
  c = pl::AbortConfig{};
  c.retreat_distance_m = 40.0;  // every point ≥ 40 m away lies outside the 60 m map
  c.max_distance_m = 45.0;
  const auto far = pl::chooseRetreatGoal(0, 3, kWorker + Eigen::Vector3d(-8, 0, 5), kWorker, world().space(), c);
  ASSERT_FALSE(far);
  EXPECT_NE(far.reason().find("no point"), std::string::npos) << far.reason();
  EXPECT_FALSE(pl::chooseRetreatGoal(0, 3, kWorker, kWorker, pl::RetreatSpace{}, pl::AbortConfig{}));
}

TEST(LandingPointTest, BelowTheGoalWhenItsColumnIsClearElseBelowHomeElseNone) {
  const pl::AbortConfig c;
  const Eigen::Vector3d open(-15.0, 10.0, 10.0), above_pillar(-20.0, 0.0, 10.0), home(-10.0, -10.0, 6.0);
  const auto a = pl::chooseLandingPoint(open, home, world().space(), c);
  ASSERT_TRUE(a) << a.reason();
  EXPECT_EQ(*a, Eigen::Vector3d(-15.0, 10.0, c.land_height_m));
  const auto b = pl::chooseLandingPoint(above_pillar, home, world().space(), c);
  ASSERT_TRUE(b) << b.reason();
  EXPECT_EQ(*b, Eigen::Vector3d(-10.0, -10.0, c.land_height_m));  // the pillar is under the goal: home
  EXPECT_FALSE(pl::chooseLandingPoint(above_pillar, above_pillar, world().space(), c));
  EXPECT_FALSE(pl::chooseLandingPoint(above_pillar, std::nullopt, world().space(), c));  // no home to fall back on
}

TEST(LandingPointTest, ATakeOffPointBesideTheWorkerOrOutsideTheMapIsRefusedNamingWhy) {
  const pl::AbortConfig c;  // retreat_distance_m 15
  EXPECT_EQ(pl::homeProblem(Eigen::Vector3d(-12.0, -12.0, 6.0), kWorker, world().space(), c), "");
  EXPECT_EQ(pl::homeProblem(Eigen::Vector3d(-12.0, -12.0, 0.0), kWorker, world().space(), c), "");  // on the pad
  const std::string beside = pl::homeProblem(Eigen::Vector3d(5.0, 3.0, 6.0), kWorker, world().space(), c);
  EXPECT_NE(beside.find("retreat_distance_m"), std::string::npos) << beside;
  EXPECT_NE(beside.find("5.83"), std::string::npos) << beside;  // its distance from the worker estimate
  const Eigen::Vector3d nan = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  EXPECT_NE(pl::homeProblem(nan, kWorker, world().space(), c), "");
  EXPECT_NE(pl::homeProblem(Eigen::Vector3d(-12.0, -12.0, 6.0), nan, world().space(), c), "");  // no worker estimate
  EXPECT_NE(pl::homeProblem(Eigen::Vector3d(500.0, 0.0, 6.0), kWorker, world().space(), c).find("inside the map"),
            std::string::npos);
}

// ---- the phases ---------------------------------------------------------------------------

namespace {

pl::AbortPlanner::Situation at(double t, const Eigen::Vector3d& p, const Eigen::Vector3d& v = Eigen::Vector3d::Zero()) {
  pl::AbortPlanner::Situation s;
  s.t_s = t;
  s.dt_s = 0.2;
  s.steps = 10;
  s.p_world = p;
  s.v_world = v;
  s.worker_world = kWorker;
  s.home_world = Eigen::Vector3d(-12.0, -12.0, 6.0);  // 17 m from the worker: a take-off point it may return to
  return s;
}

pl::AbortCommand command(double sent_s) { return pl::AbortCommand{{"gcs", 7}, pl::AbortSource::kOperator, sent_s}; }

}  // namespace

TEST(AbortPlannerTest, AcceptsOnceRefusesStaleCommandsAndCopiesChangeNothing) {
  pl::AbortConfig c;
  c.max_command_age_s = 10.0;
  pl::AbortPlanner a(0, 3, c, world().space());
  EXPECT_EQ(a.receive(command(0.0), 10.5), pl::AbortAcceptance::kStale);
  EXPECT_FALSE(a.aborting());
  // A copy of the old timeline after ROS time went back (the simulation restarted at 0 s): refused;
  // a sender clock a few seconds ahead is not (a real abort must not be lost to clock skew).
  EXPECT_EQ(a.receive(command(300.0), 10.5), pl::AbortAcceptance::kFromTheFuture);
  EXPECT_EQ(a.receive(command(std::numeric_limits<double>::quiet_NaN()), 10.5), pl::AbortAcceptance::kStale);
  EXPECT_FALSE(a.aborting());
  {
    pl::AbortPlanner ahead(0, 3, c, world().space());
    EXPECT_EQ(ahead.receive(command(20.5 + 1e-6), 10.5), pl::AbortAcceptance::kFromTheFuture);
    EXPECT_EQ(ahead.receive(command(20.5), 10.5), pl::AbortAcceptance::kAccepted);  // exactly max_command_age_s ahead
    pl::AbortPlanner skewed(0, 3, c, world().space());
    EXPECT_EQ(skewed.receive(command(13.0), 10.5), pl::AbortAcceptance::kAccepted);  // a sender clock 2.5 s ahead
  }
  EXPECT_EQ(a.receive(command(5.0), 10.5), pl::AbortAcceptance::kAccepted);
  EXPECT_TRUE(a.aborting());
  EXPECT_DOUBLE_EQ(a.acceptedAt(), 10.5);
  EXPECT_EQ(a.receive(command(5.2), 10.7), pl::AbortAcceptance::kAlreadyAborting);  // a repeat
  EXPECT_DOUBLE_EQ(a.acceptedAt(), 10.5);
}

TEST(AbortPlannerTest, RetreatsThenHovers) {
  pl::AbortPlanner a(1, 3, pl::AbortConfig{}, world().space());
  a.receive(command(0.0), 0.0);
  const Eigen::Vector3d p0(-8.0, 0.0, 6.0);
  const auto d0 = a.decide(at(0.0, p0));
  EXPECT_EQ(d0.phase, pl::AbortPhase::kRetreat);
  EXPECT_TRUE(d0.phase_changed);
  ASSERT_TRUE(a.retreatGoal());
  const Eigen::Vector3d goal = *a.retreatGoal();
  // The reference leaves from the UAV towards the goal at speed_mps, camera on the worker.
  EXPECT_EQ(Eigen::Vector3d(d0.reference.p_world.col(0)), p0);
  const double moved = (Eigen::Vector3d(d0.reference.p_world.col(9)) - p0).norm();
  EXPECT_NEAR(moved, pl::AbortConfig{}.speed_mps * 9 * 0.2, 1e-9);
  EXPECT_LT((Eigen::Vector3d(d0.reference.p_world.col(9)) - goal).norm(), (p0 - goal).norm());
  EXPECT_NEAR(d0.reference.heading_rad(0), std::atan2(kWorker.y() - p0.y(), kWorker.x() - p0.x()), 1e-9);
  // Near the goal but still fast: not arrived.
  EXPECT_EQ(a.decide(at(5.0, goal + Eigen::Vector3d(0.5, 0, 0), Eigen::Vector3d(1.0, 0, 0))).phase,
            pl::AbortPhase::kRetreat);
  const auto d1 = a.decide(at(6.0, goal + Eigen::Vector3d(0.5, 0, 0)));
  EXPECT_EQ(d1.phase, pl::AbortPhase::kAtRetreat);
  EXPECT_TRUE(d1.phase_changed);
  for (int k = 0; k < d1.reference.steps(); ++k) EXPECT_EQ(Eigen::Vector3d(d1.reference.p_world.col(k)), goal);
  EXPECT_EQ(a.decide(at(7.0, goal)).phase, pl::AbortPhase::kAtRetreat);  // settled for good
  EXPECT_EQ(*a.retreatGoal(), goal);                                      // chosen once
}

TEST(AbortPlannerTest, RetreatsThenReturnsHome) {
  pl::AbortConfig c;
  c.after = pl::AbortAfter::kReturnHome;
  pl::AbortPlanner a(0, 3, c, world().space());
  a.receive(command(0.0), 0.0);
  a.decide(at(0.0, Eigen::Vector3d(-8.0, 0.0, 6.0)));
  const Eigen::Vector3d goal = *a.retreatGoal();
  EXPECT_EQ(a.decide(at(9.0, goal)).phase, pl::AbortPhase::kReturnHome);
  EXPECT_EQ(*a.currentGoal(), at(0, goal).home_world);
  EXPECT_EQ(a.decide(at(15.0, goal)).phase, pl::AbortPhase::kReturnHome);  // not there yet
  EXPECT_EQ(a.decide(at(20.0, at(0, goal).home_world)).phase, pl::AbortPhase::kAtHome);
}

TEST(AbortPlannerTest, ATakeOffPointBesideTheWorkerIsNotReturnedTo) {
  // A planner restarted mid-mission took its slot beside the worker for its take-off point.
  pl::AbortConfig c;
  c.after = pl::AbortAfter::kReturnHome;
  pl::AbortPlanner a(0, 3, c, world().space());
  a.receive(command(0.0), 0.0);
  a.decide(at(0.0, Eigen::Vector3d(-8.0, 0.0, 6.0)));
  const Eigen::Vector3d goal = *a.retreatGoal();
  auto s = at(9.0, goal);
  s.home_world = Eigen::Vector3d(-6.0, 2.0, 5.0);  // 6.3 m from the worker
  const auto d = a.decide(s);
  EXPECT_EQ(d.phase, pl::AbortPhase::kAtRetreat) << d.reason;
  EXPECT_NE(d.reason.find("retreat_distance_m"), std::string::npos) << d.reason;
  EXPECT_EQ(*a.currentGoal(), goal);
}

// Landing: the column below the retreat goal comes first, the take-off point's only when that one is
// blocked — so the goal's column is blocked here (a box 2 m beside it, out of the goal's clearance),
// and a take-off point beside the worker, whose column is clear, must still not be landed below.
TEST(AbortPlannerTest, NoLandingBelowATakeOffPointBesideTheWorker) {
  pl::AbortConfig c;
  c.after = pl::AbortAfter::kLand;
  const Eigen::Vector3d start(-8.0, 0.0, 6.0);
  pl::AbortPlanner first(0, 3, c, world().space());
  first.receive(command(0.0), 0.0);
  first.decide(at(0.0, start));
  const Eigen::Vector3d goal = *first.retreatGoal();
  ASSERT_GE(goal.z() - 3.5, c.land_height_m) << "the box must lie beside the landing column";
  pl::PrimitiveSet solids = WallWorld::makeSolids();
  pl::OrientedBox box;
  box.center_world = Eigen::Vector3d(goal.x() + 2.5, goal.y(), goal.z() - 3.5);
  box.size_m = Eigen::Vector3d(1.0, 1.0, 1.0);
  solids.boxes.push_back(box);
  const WallWorld blocked(solids);
  const Eigen::Vector3d beside(-6.0, 2.0, 5.0), far(-12.0, -12.0, 6.0);  // 6.3 m and 17 m from the worker
  // The scenario: the same retreat goal, its column blocked, the columns below both take-off points clear.
  ASSERT_FALSE(pl::chooseLandingPoint(goal, std::nullopt, blocked.space(), c));
  ASSERT_TRUE(pl::chooseLandingPoint(goal, beside, blocked.space(), c));
  for (const auto& home : {beside, far}) {
    pl::AbortPlanner a(0, 3, c, blocked.space());
    a.receive(command(0.0), 0.0);
    a.decide(at(0.0, start));
    ASSERT_EQ(*a.retreatGoal(), goal) << "the box must not move the retreat goal";
    auto s = at(9.0, goal);
    s.home_world = home;
    const auto d = a.decide(s);
    if (home == beside) {  // nothing verified to land on: it stays at the retreat goal, saying why
      EXPECT_EQ(d.phase, pl::AbortPhase::kAtRetreat) << d.reason;
      EXPECT_NE(d.reason.find("retreat_distance_m"), std::string::npos) << d.reason;
      EXPECT_EQ(*a.currentGoal(), goal);
    } else {  // a take-off point far from the worker: it lands below it
      EXPECT_EQ(d.phase, pl::AbortPhase::kLanding) << d.reason;
      EXPECT_EQ(*a.currentGoal(), Eigen::Vector3d(far.x(), far.y(), c.land_height_m));
    }
  }
}

TEST(AbortPlannerTest, RetreatsThenApproachesAVerifiedLandingSpot) {
  pl::AbortConfig c;
  c.after = pl::AbortAfter::kLand;
  pl::AbortPlanner a(0, 3, c, world().space());
  a.receive(command(0.0), 0.0);
  a.decide(at(0.0, Eigen::Vector3d(-8.0, 0.0, 6.0)));
  const Eigen::Vector3d goal = *a.retreatGoal();
  EXPECT_EQ(a.decide(at(9.0, goal)).phase, pl::AbortPhase::kLanding);
  const Eigen::Vector3d spot = *a.currentGoal();
  EXPECT_EQ(spot, Eigen::Vector3d(goal.x(), goal.y(), c.land_height_m));  // straight below: its column is clear
  EXPECT_EQ(a.decide(at(20.0, spot)).phase, pl::AbortPhase::kLanded);
}

TEST(AbortPlannerTest, WithoutAGoalItHoldsAtItsBrakingPointAndSaysWhy) {
  pl::AbortPlanner a(0, 3, pl::AbortConfig{}, pl::RetreatSpace{});  // no map
  a.receive(command(0.0), 0.0);
  const auto d = a.decide(at(0.0, Eigen::Vector3d(0, 0, 5), Eigen::Vector3d(2.0, 0, 0)));
  EXPECT_EQ(d.phase, pl::AbortPhase::kNoGoal);
  EXPECT_NE(d.reason.find("no map"), std::string::npos) << d.reason;
  const Eigen::Vector3d brake = pl::brakingPoint(Eigen::Vector3d(0, 0, 5), Eigen::Vector3d(2.0, 0, 0), 4.0);
  for (int k = 0; k < d.reference.steps(); ++k) EXPECT_EQ(Eigen::Vector3d(d.reference.p_world.col(k)), brake);
}

// ---- settings -----------------------------------------------------------------------------

TEST(AbortConfigTest, DefaultsAreValidAndTheReaderNamesEveryBadKey) {
  EXPECT_TRUE(pl::AbortConfig{}.validate().empty());
  auto r = gf::common::ConfigReader::fromString(
      "retreat_distance_m: -1\nbearing_step_deg: 0\nrepeats: 0\nmax_distance_m: 10\nafter: fly_away\n", "abort.yaml",
      gf::common::ConfigReader::MissingKeys::kUseDefaults);
  const pl::AbortConfig c = pl::readAbortConfig(r);
  std::string all;
  for (const auto& e : r.errors()) all += e + "\n";
  for (const char* needle : {"retreat_distance_m", "-1", "bearing_step_deg", "repeats", "max_distance_m", "after",
                             "fly_away"}) {
    EXPECT_NE(all.find(needle), std::string::npos) << needle << "\n" << all;
  }
  EXPECT_EQ(c.after, pl::AbortAfter::kHover);  // a bad value keeps the default
  auto ok = gf::common::ConfigReader::fromString("after: land\nretreat_distance_m: 20\n", "abort.yaml",
                                                 gf::common::ConfigReader::MissingKeys::kUseDefaults);
  const pl::AbortConfig l = pl::readAbortConfig(ok);
  EXPECT_TRUE(ok.ok());
  EXPECT_EQ(l.after, pl::AbortAfter::kLand);
  EXPECT_DOUBLE_EQ(l.retreat_distance_m, 20.0);
}

TEST(AbortConfigTest, LayersMustKeepGammaDisAndTheSpeedTheLimit) {
  pl::AbortConfig c;
  c.layer_spacing_m = 2.0;
  c.speed_mps = 6.0;
  const auto e = pl::abortPlannerProblems(c, 2.5, 5.0, "mission.abort.");
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].key, "mission.abort.layer_spacing_m");
  EXPECT_EQ(e[1].key, "mission.abort.speed_mps");
  EXPECT_TRUE(pl::abortPlannerProblems(pl::AbortConfig{}, 2.5, 5.0, "").empty());
}

// ---- the replanning step in abort ---------------------------------------------------------

namespace {

/// Test-only planner: records every request and flies its reference.
class RecordingPlanner : public pl::Planner {
 public:
  explicit RecordingPlanner(std::shared_ptr<std::vector<pl::PlanRequest>> log) : log_(std::move(log)) {}
  pl::PlanResult plan(const pl::PlanRequest& r) override {
    log_->push_back(r);
    pl::PlanResult res;
    res.status = pl::PlanStatus::kOptimized;
    res.trajectory.uav_index = r.uav_index;
    res.trajectory.t0_s = r.t_now_s;
    res.trajectory.dt_s = r.dt_s;
    for (int k = 0; k < r.reference.steps(); ++k) {
      pl::TrajectorySample s;
      s.p_world = r.reference.p_world.col(k);
      res.trajectory.samples.push_back(s);
    }
    return res;
  }

 private:
  std::shared_ptr<std::vector<pl::PlanRequest>> log_;
};

pl::ReceivedPlan planOf(int uav, double t0) {
  pl::ReceivedPlan m;
  m.plan.uav_index = uav;
  m.plan.t0_s = t0;
  m.plan.dt_s = 0.2;
  m.plan.samples.resize(3);
  return m;
}

struct Follower {
  std::shared_ptr<std::vector<pl::PlanRequest>> log = std::make_shared<std::vector<pl::PlanRequest>>();
  pl::ReplanStep step;
  gf::formation::FormationParams params;
  std::vector<std::optional<pl::ReceivedPlan>> received;
  Follower()
      : step(config(), std::make_unique<RecordingPlanner>(log), world().space()),
        received(3) {}
  static pl::ReplanConfig config() {
    pl::ReplanConfig c;
    c.uav_index = 1;
    c.uav_count = 3;
    c.steps = 10;
    c.freshness = pl::FreshnessLimits{2.0, 3.0};
    c.rule = pl::AvoidanceRule{true, 1.0};
    return c;
  }
  pl::ReplanOutcome at(double t, double share_stamp) {
    received[2] = planOf(2, t - 0.1);
    pl::WorkerKnowledge w;
    w.stamp_s = share_stamp;
    w.fused_s = share_stamp;
    w.p_world = kWorker;
    w.v_world = Eigen::Vector3d(1.0, 0.0, 0.0);
    pl::ReplanInputs in;
    in.t_s = t;
    in.state.p_world = Eigen::Vector3d(-8.0, 2.0, 6.0);
    in.worker = &w;
    in.params = &params;
    pl::PlannedTrajectory leader = planOf(0, t - 0.2).plan;
    in.leader_plan = &leader;
    in.leader_plan_in_share = true;  // as gfctl simulate's share
    in.received = &received;
    return step.step(in);
  }
};

}  // namespace

TEST(ReplanStepAbortTest, FromTrackAndFromHoldTheUavRetreatsAroundEveryPlanFlaggedForRightOfWay) {
  for (const bool stale : {false, true}) {
    Follower f;
    f.at(0.0, 0.0);  // listening ends: follower 2's plan is fresh
    const auto before = f.at(10.0, stale ? 5.0 : 10.0);
    EXPECT_EQ(before.mode, stale ? pl::ReplanMode::kHold : pl::ReplanMode::kTrack);
    EXPECT_EQ(f.step.receiveAbort(command(10.1), 10.2), pl::AbortAcceptance::kAccepted);
    const auto out = f.at(10.4, stale ? 5.0 : 10.0);
    EXPECT_EQ(out.mode, pl::ReplanMode::kAbort) << out.reason;
    EXPECT_EQ(out.abort_phase, pl::AbortPhase::kRetreat);
    EXPECT_TRUE(out.fallback);
    ASSERT_TRUE(f.step.abort().retreatGoal());
    const Eigen::Vector3d goal = *f.step.abort().retreatGoal();
    EXPECT_DOUBLE_EQ(goal.z(), pl::AbortConfig{}.retreat_height_m + pl::AbortConfig{}.layer_spacing_m);
    const pl::PlanRequest& r = f.log->back();
    EXPECT_LT((Eigen::Vector3d(r.reference.p_world.col(9)) - goal).norm(), (r.state.p_world - goal).norm());
    ASSERT_EQ(r.higher_priority_plans.size(), 2u);  // the leader's and follower 2's
    EXPECT_EQ(r.higher_priority_plans[0].uav_index, 0);
    EXPECT_EQ(r.higher_priority_plans[1].uav_index, 2);
    // Stale data: the worker keep-out is frozen where he was last known; fresh: extrapolated.
    EXPECT_NEAR(r.worker.p_world(0, 0), stale ? kWorker.x() : kWorker.x() + 0.4, 1e-9);
    EXPECT_NEAR(r.worker.p_world(0, 5), stale ? kWorker.x() : kWorker.x() + 0.4 + 5 * 0.2, 1e-9);
  }
}

TEST(ReplanStepAbortTest, ARestartedUavListensFirstAndForgetsTheAbortUntilItIsRepeated) {
  Follower f;
  f.at(0.0, 0.0);
  f.step.receiveAbort(command(1.0), 1.0);
  EXPECT_EQ(f.at(1.2, 1.2).mode, pl::ReplanMode::kAbort);
  f.step.restart(std::make_unique<RecordingPlanner>(f.log));
  EXPECT_FALSE(f.step.abort().aborting());
  EXPECT_EQ(f.step.receiveAbort(command(2.0), 2.0), pl::AbortAcceptance::kAccepted);
  f.received[2].reset();  // nothing heard since the restart: it listens before it moves
  pl::WorkerKnowledge w;
  w.stamp_s = w.fused_s = 2.2;
  w.p_world = kWorker;
  pl::ReplanInputs in;
  in.t_s = 2.2;
  in.state.p_world = Eigen::Vector3d(-8.0, 2.0, 6.0);
  in.worker = &w;
  in.params = &f.params;
  in.leader_plan_in_share = true;
  in.received = &f.received;
  const auto out = f.step.step(in);
  EXPECT_EQ(out.mode, pl::ReplanMode::kHold);
  EXPECT_NE(out.reason.find("listening"), std::string::npos) << out.reason;
  EXPECT_EQ(f.at(2.6, 2.6).mode, pl::ReplanMode::kAbort);
}

// Primitives, catenary and lattice tower geometry against closed forms.
#include <gtest/gtest.h>

#include <cmath>

#include "gesture_formation/planning/catenary.hpp"
#include "gesture_formation/planning/lattice_tower.hpp"
#include "gesture_formation/planning/shapes.hpp"

using namespace gesture_formation::planning;

TEST(ShapesTest, OrientedBoxDistance) {
  OrientedBox b;
  b.center_world = Eigen::Vector3d(1, 2, 3);
  b.size_m = Eigen::Vector3d(2, 4, 6);
  b.R_world_box = rotationFromRpy(0, 0, M_PI / 2);  // box x along world y
  EXPECT_DOUBLE_EQ(b.distance(Eigen::Vector3d(1, 2, 3)), 0.0);
  // Along world x the half extent is 2 (box y), along world y it is 1 (box x).
  EXPECT_NEAR(b.distance(Eigen::Vector3d(1 + 2.5, 2, 3)), 0.5, 1e-12);
  EXPECT_NEAR(b.distance(Eigen::Vector3d(1, 2 + 1.5, 3)), 0.5, 1e-12);
  EXPECT_NEAR(b.distance(Eigen::Vector3d(1 + 3, 2 + 2, 3)), std::sqrt(2.0), 1e-12);
  const Aabb bb = b.bounds();
  EXPECT_NEAR(bb.max_world.x(), 3.0, 1e-12);
  EXPECT_NEAR(bb.max_world.y(), 3.0, 1e-12);
  EXPECT_NEAR(bb.min_world.z(), 0.0, 1e-12);
}

TEST(ShapesTest, SlantedCylinderDistance) {
  const Cylinder c{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(3, 4, 0), 0.5};
  EXPECT_DOUBLE_EQ(c.distance(Eigen::Vector3d(1.5, 2, 0)), 0.0);
  const Eigen::Vector3d side = Eigen::Vector3d(1.5, 2, 0) + 2.0 * Eigen::Vector3d(0, 0, 1);
  EXPECT_NEAR(c.distance(side), 1.5, 1e-12);
  EXPECT_NEAR(c.distance(Eigen::Vector3d(-0.6, -0.8, 0)), 1.0, 1e-12);        // beyond the p0 cap
  EXPECT_NEAR(c.distance(Eigen::Vector3d(-0.6, -0.8, 1.5)), std::hypot(1.0, 1.0), 1e-12);  // cap rim
  EXPECT_NEAR(c.volume(), M_PI * 0.25 * 5.0, 1e-12);
  const Aabb bb = c.bounds();
  EXPECT_NEAR(bb.max_world.z(), 0.5, 1e-12);
  EXPECT_NEAR(bb.max_world.x(), 3.0 + 0.5 * 0.8, 1e-12);
}

TEST(CatenaryTest, PassesThroughEndsWithTheRequestedSag) {
  for (const double dh : {0.0, 4.0, -7.0}) {
    const Eigen::Vector3d a(0, 0, 20), b(30, 40, 20 + dh);
    const auto cat = Catenary::fit(a, b, 3.0);
    ASSERT_TRUE(cat) << cat.reason();
    EXPECT_NEAR((cat->point(0.0) - a).norm(), 0.0, 1e-9);
    EXPECT_NEAR((cat->point(1.0) - b).norm(), 0.0, 1e-9);
    const Eigen::Vector3d mid = cat->point(0.5);
    EXPECT_NEAR(0.5 * (a.z() + b.z()) - mid.z(), 3.0, 1e-9);
    EXPECT_NEAR((mid.head<2>() - 0.5 * (a + b).head<2>()).norm(), 0.0, 1e-9);
    EXPECT_GT(cat->length(), (b - a).norm());
  }
  // Level span: the lowest point is mid-span, and a ≈ L²/(8 sag) for small sags.
  const auto level = Catenary::fit(Eigen::Vector3d(0, 0, 10), Eigen::Vector3d(50, 0, 10), 1.0);
  ASSERT_TRUE(level);
  EXPECT_NEAR(level->lowestZ(), 9.0, 1e-9);
  EXPECT_NEAR(level->parameter(), 2500.0 / 8.0, 2.0);
}

TEST(CatenaryTest, RejectsDegenerateInput) {
  EXPECT_FALSE(Catenary::fit(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 10), 1.0));
  EXPECT_FALSE(Catenary::fit(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(10, 0, 0), 0.0));
  EXPECT_FALSE(Catenary::fit(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(10, 0, 0), std::nan("")));
  ConductorSpec spec;
  spec.radius_m = 0.0;
  EXPECT_FALSE(conductorPrimitives(spec));
}

TEST(CatenaryTest, PiecesFollowTheCurve) {
  ConductorSpec spec;
  spec.from_world = Eigen::Vector3d(0, 0, 20);
  spec.to_world = Eigen::Vector3d(50, 0, 20);
  spec.sag_m = 3.0;
  const auto set = conductorPrimitives(spec);
  ASSERT_TRUE(set);
  ASSERT_GE(set->cylinders.size(), 50u);
  for (std::size_t i = 1; i < set->cylinders.size(); ++i) {
    EXPECT_EQ(set->cylinders[i].p0_world, set->cylinders[i - 1].p1_world);  // a chain
    EXPECT_LE((set->cylinders[i].p1_world - set->cylinders[i].p0_world).norm(), 1.05);
  }
}

TEST(LatticeTowerTest, MembersAndArmTips) {
  LatticeTowerSpec t;
  t.base_world = Eigen::Vector3d(10, 0, 0);
  t.yaw_rad = M_PI / 2;
  t.cross_arms = {CrossArmSpec{20.0, 6.0, 0.4}};
  EXPECT_TRUE(t.validate().empty());
  const PrimitiveSet set = towerPrimitives(t);
  EXPECT_EQ(set.cylinders.size(), 4u + 12u * static_cast<std::size_t>(t.panels));
  EXPECT_EQ(set.boxes.size(), 1u);
  // Yaw 90°: the arm (tower y) points along world −x.
  EXPECT_NEAR((t.armTip(0, 1) - Eigen::Vector3d(4, 0, 20)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((t.armTip(0, -1, 2.0) - Eigen::Vector3d(16, 0, 18)).norm(), 0.0, 1e-9);
  EXPECT_NEAR(set.distance(t.armTip(0, 1)), 0.0, 1e-9);
  // The top of the legs is at the tower's height, the footprint is base_width wide.
  double top = 0.0;
  for (const auto& c : set.cylinders) top = std::max({top, c.p0_world.z(), c.p1_world.z()});
  EXPECT_NEAR(top, 30.0, 1e-9);
  EXPECT_NEAR(set.distance(Eigen::Vector3d(13, 3, 0)), 0.0, 1e-9);  // a leg foot
  EXPECT_GT(set.distance(Eigen::Vector3d(10, 0, 5)), 1.0);          // the inside is hollow

  LatticeTowerSpec bad = t;
  bad.top_width_m = 7.0;
  bad.panels = 0;
  bad.cross_arms[0].height_m = 40.0;
  EXPECT_EQ(bad.validate().size(), 3u);
}

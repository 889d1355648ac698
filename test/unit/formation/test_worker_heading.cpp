#include <gtest/gtest.h>

#include <cmath>

#include "gesture_formation/common/angles.hpp"
#include "gesture_formation/formation/worker_heading.hpp"

using namespace gesture_formation::formation;
using gesture_formation::common::kPi;

TEST(WorkerHeadingTest, ConstantModeIgnoresMotion) {
  WorkerHeadingConfig c;
  c.constant_heading_deg = 270.0;
  WorkerHeading h(c);
  EXPECT_NEAR(h.update(Eigen::Vector3d(3.0, 0.0, 0.0)), -kPi / 2, 1e-15);
}

TEST(WorkerHeadingTest, MotionModeHysteresis) {
  WorkerHeadingConfig c;
  c.mode = WorkerHeadingMode::kMotion;
  c.speed_low_mps = 0.2;
  c.speed_high_mps = 0.5;
  WorkerHeading h(c);
  EXPECT_EQ(h.update(Eigen::Vector3d(0.0, 0.4, 0.0)), 0.0);  // below high: not yet following
  EXPECT_FALSE(h.following());
  EXPECT_NEAR(h.update(Eigen::Vector3d(0.0, 0.6, 0.0)), kPi / 2, 1e-15);  // starts following
  EXPECT_NEAR(h.update(Eigen::Vector3d(-0.3, 0.0, 5.0)), kPi, 1e-15);     // between: still follows (z ignored)
  EXPECT_TRUE(h.following());
  EXPECT_NEAR(h.update(Eigen::Vector3d(0.0, -0.1, 0.0)), kPi, 1e-15);     // below low: holds the last
  EXPECT_FALSE(h.following());
  EXPECT_NEAR(h.update(Eigen::Vector3d(0.0, -0.3, 0.0)), kPi, 1e-15);     // between, not following: holds
  EXPECT_NEAR(h.update(Eigen::Vector3d(0.0, -0.5, 0.0)), -kPi / 2, 1e-15);  // at high: follows again
  EXPECT_NEAR(h.update(Eigen::Vector3d(std::nan(""), 1.0, 0.0)), -kPi / 2, 1e-15);  // NaN ignored
}

TEST(WorkerHeadingTest, OperatorMode) {
  WorkerHeadingConfig c;
  c.mode = WorkerHeadingMode::kOperator;
  WorkerHeading h(c);
  EXPECT_EQ(h.heading(), 0.0);
  EXPECT_TRUE(h.setOperatorHeading(7.0));
  EXPECT_NEAR(h.heading(), 7.0 - 2 * kPi, 1e-12);
  EXPECT_FALSE(h.setOperatorHeading(std::nan("")));
  EXPECT_NEAR(h.update(Eigen::Vector3d(5.0, 5.0, 0.0)), 7.0 - 2 * kPi, 1e-12);
}

TEST(WorkerHeadingTest, ValidateNamesFields) {
  WorkerHeadingConfig c;
  c.speed_low_mps = 1.0;
  c.speed_high_mps = 0.5;
  const auto e = c.validate();
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NE(e[0].find("worker_heading.speed_high_mps"), std::string::npos);
}

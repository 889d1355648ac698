#include <gtest/gtest.h>

#include "gesture_formation/common/angles.hpp"

using namespace gesture_formation::common;

TEST(AnglesTest, WrapToHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(wrapAngle(kPi), kPi);
  EXPECT_DOUBLE_EQ(wrapAngle(-kPi), kPi);
  EXPECT_NEAR(wrapAngle(3 * kPi), kPi, 1e-12);
  EXPECT_NEAR(wrapAngle(2 * kPi + 0.1), 0.1, 1e-12);
  EXPECT_NEAR(wrapAngle(-2 * kPi - 0.1), -0.1, 1e-12);
  for (double a = -20.0; a < 20.0; a += 0.37) {
    const double w = wrapAngle(a);
    EXPECT_GT(w, -kPi);
    EXPECT_LE(w, kPi);
    EXPECT_NEAR(std::remainder(w - a, 2 * kPi), 0.0, 1e-12);
  }
  EXPECT_DOUBLE_EQ(degToRad(180.0), kPi);
  EXPECT_DOUBLE_EQ(radToDeg(kPi / 2), 90.0);
}

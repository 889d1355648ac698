// onboard::WindInput (docs/safety.md §4.7): the wind estimate is taken only in the world frame,
// finite and at most 60 m/s (refusals say why and are counted, the held estimate kept), and used
// while no older than its age limit.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "gesture_formation/onboard/wind_input.hpp"

using gesture_formation::onboard::WindInput;

TEST(WindInputTest, TakesAFreshFiniteWorldFrameEstimateAndRefusesTheRest) {
  WindInput wind(2.0);
  EXPECT_FALSE(wind.at(0.0));
  EXPECT_EQ(wind.receive("world", "world", Eigen::Vector3d(3.0, -1.0, 0.0), 10.0), "");
  ASSERT_TRUE(wind.at(11.9));
  EXPECT_DOUBLE_EQ(wind.at(11.9)->x(), 3.0);
  EXPECT_FALSE(wind.at(12.1)) << "older than 2 s";
  const std::string frame = wind.receive("base_link", "world", Eigen::Vector3d(5.0, 0.0, 0.0), 11.0);
  EXPECT_NE(frame.find("frame_id 'base_link', expected 'world'"), std::string::npos) << frame;
  EXPECT_NE(wind.receive("world", "world", Eigen::Vector3d(61.0, 0.0, 0.0), 11.0), "");
  EXPECT_NE(wind.receive("world", "world", Eigen::Vector3d(std::nan(""), 0.0, 0.0), 11.0), "");
  EXPECT_EQ(wind.rejected(), 3u);
  ASSERT_TRUE(wind.at(11.5));
  EXPECT_DOUBLE_EQ(wind.at(11.5)->x(), 3.0) << "the refused estimates left the held one alone";
}

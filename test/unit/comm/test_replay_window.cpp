#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <set>

#include "gesture_formation/comm/replay_window.hpp"

using gesture_formation::comm::ReplayWindow;
using Check = ReplayWindow::Check;

TEST(CommReplayWindowTest, FirstNumberIsNewThenDuplicate) {
  ReplayWindow w(64);
  EXPECT_TRUE(w.empty());
  EXPECT_EQ(w.check(5), Check::kNew);
  w.accept(5);
  EXPECT_EQ(w.check(5), Check::kDuplicate);
  EXPECT_EQ(w.check(4), Check::kNew);  // late but inside the window
  EXPECT_EQ(w.check(6), Check::kNew);
  EXPECT_EQ(w.highest(), 5u);
}

TEST(CommReplayWindowTest, BoundaryOfTheWindow) {
  ReplayWindow w(64);
  w.accept(1000);
  EXPECT_EQ(w.check(1000 - 63), Check::kNew);
  EXPECT_EQ(w.check(1000 - 64), Check::kTooOld);
  w.accept(1000 - 63);
  EXPECT_EQ(w.check(1000 - 63), Check::kDuplicate);
  w.accept(1001);  // slides by one: 937 leaves
  EXPECT_EQ(w.check(1000 - 63), Check::kTooOld);
}

TEST(CommReplayWindowTest, LargeJumpClearsEverything) {
  ReplayWindow w(128);
  for (std::uint64_t s = 1; s <= 100; ++s) w.accept(s);
  w.accept(100000);
  for (std::uint64_t s = 100000 - 127; s < 100000; ++s) EXPECT_EQ(w.check(s), Check::kNew) << s;
  EXPECT_EQ(w.check(100000), Check::kDuplicate);
  EXPECT_EQ(w.check(50), Check::kTooOld);
}

TEST(CommReplayWindowTest, ExtremeSequenceNumbers) {
  ReplayWindow w(64);
  const std::uint64_t max = std::numeric_limits<std::uint64_t>::max();
  w.accept(max - 10);
  w.accept(max);
  EXPECT_EQ(w.check(max), Check::kDuplicate);
  EXPECT_EQ(w.check(max - 10), Check::kDuplicate);
  EXPECT_EQ(w.check(max - 5), Check::kNew);
  EXPECT_EQ(w.check(0), Check::kTooOld);
}

TEST(CommReplayWindowTest, SizeIsRoundedAndClamped) {
  EXPECT_EQ(ReplayWindow(1).size(), 64u);
  EXPECT_EQ(ReplayWindow(65).size(), 128u);
  EXPECT_EQ(ReplayWindow(1u << 30).size(), gesture_formation::comm::kMaxReplayWindow);
}

// Against a reference model (a set of every number accepted and the maximum): random
// reordered streams with duplicates, several window sizes.
TEST(CommReplayWindowTest, MatchesAReferenceModel) {
  for (std::size_t size : {64u, 128u, 1024u}) {
    std::mt19937_64 rng(42 + size);
    ReplayWindow w(size);
    std::set<std::uint64_t> seen;
    std::uint64_t highest = 0;
    std::uint64_t next = 1;
    for (int i = 0; i < 20000; ++i) {
      std::uint64_t s;
      const int kind = static_cast<int>(rng() % 10);
      if (kind < 6) {
        s = next++;
      } else if (kind < 9) {
        const std::uint64_t back = rng() % (2 * size);
        s = next > back ? next - back : 1;
      } else {
        s = next + rng() % (3 * size);
      }
      Check expected;
      if (seen.empty() || s > highest) {
        expected = Check::kNew;
      } else if (highest - s >= w.size()) {
        expected = Check::kTooOld;
      } else {
        expected = seen.count(s) ? Check::kDuplicate : Check::kNew;
      }
      ASSERT_EQ(w.check(s), expected) << "size " << size << " step " << i << " seq " << s;
      if (expected == Check::kNew) {
        w.accept(s);
        seen.insert(s);
        highest = std::max(highest, s);
        next = std::max(next, s + 1);
      }
    }
  }
}

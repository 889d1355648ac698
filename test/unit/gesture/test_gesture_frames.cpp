// gesture::GestureFrames — the frame aggregation of the GestureCommander nodelet and gfctl
// simulate: frames close when every view reported or close_after_s after their stamp, a late
// observation votes only in later frames, the single-camera mode, and a fired gesture's action.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "gesture_formation/gesture/gesture_frames.hpp"

namespace gg = gesture_formation::gesture;

namespace {

gg::ViewFusionConfig fusion(int min_agreeing) {
  gg::ViewFusionConfig c;
  c.min_agreeing_views = min_agreeing;
  c.fusion_lag_s = 0.4;
  c.vote_window_s = 0.0;  // each view votes its newest classification
  return c;
}

gg::GestureFilterConfig filter() {
  gg::GestureFilterConfig c;
  c.window_size = 5;
  c.min_measurements = 5;
  c.ratio_threshold = 0.8;
  c.cooldown_s = 5.0;
  return c;
}

gg::ViewObservation obs(int view, double t, int id) {
  gg::ViewObservation o;
  o.view = view;
  o.t_s = t;
  o.gesture_id = id;
  o.distance_m = 8.0;
  o.elevation_deg = 20.0;
  return o;
}

}  // namespace

TEST(GestureFramesTest, FrameClosesOnceEveryViewReported) {
  gg::GestureFrames frames(filter(), fusion(2), gg::GestureMapping::paperDefault(), 3, 0.1);
  EXPECT_EQ(frames.views(), 3);
  EXPECT_DOUBLE_EQ(frames.closeAfterS(), 0.4);
  EXPECT_TRUE(frames.observe(obs(0, 1.0, 2)).empty());
  EXPECT_TRUE(frames.observe(obs(1, 1.0, 2)).empty());
  const auto closed = frames.observe(obs(2, 1.0, 2));
  ASSERT_EQ(closed.size(), 1u);
  EXPECT_DOUBLE_EQ(closed[0].t_s, 1.0);
  EXPECT_EQ(closed[0].reported, 3);
  EXPECT_EQ(closed[0].fused.gesture_id, 2);
  EXPECT_EQ(closed[0].fused.agreeing_views, 3);
}

TEST(GestureFramesTest, FrameWithAMissingViewClosesAfterTheLagAndALateVoteCountsLater) {
  gg::GestureFrames frames(filter(), fusion(2), gg::GestureMapping::paperDefault(), 3, 0.1);
  EXPECT_TRUE(frames.observe(obs(0, 2.0, 3)).empty());
  EXPECT_TRUE(frames.observe(obs(1, 2.0, 3)).empty());
  EXPECT_TRUE(frames.closeDue(2.39).empty());  // follower 2 may still report
  auto closed = frames.closeDue(2.4);
  ASSERT_EQ(closed.size(), 1u);
  EXPECT_EQ(closed[0].reported, 2);
  EXPECT_EQ(closed[0].fused.gesture_id, 3);  // 2 of 2 voting views agree
  // Follower 2's vote of that frame arrives late: no frame is reopened …
  bool accepted = false;
  EXPECT_TRUE(frames.observe(obs(2, 2.0, 1), &accepted).empty());
  EXPECT_TRUE(accepted);
  EXPECT_TRUE(frames.closeDue(3.0).empty());
}

TEST(GestureFramesTest, FrameWithNoAcceptedObservationIsNotFiltered) {
  gg::GestureFrames frames(filter(), fusion(2), gg::GestureMapping::paperDefault(), 3, 0.1);
  gg::ViewObservation bad = obs(0, 1.0, 9);  // id beyond max_gesture_id: refused by the vote
  bool accepted = true;
  std::string reason;
  frames.observe(bad, &accepted, &reason);
  EXPECT_FALSE(accepted);
  EXPECT_FALSE(reason.empty());
  EXPECT_TRUE(frames.closeDue(5.0).empty());
}

TEST(GestureFramesTest, SingleCameraTakesTheLeadersClassificationAndIgnoresFollowers) {
  gg::GestureFrames frames(filter(), fusion(1), gg::GestureMapping::paperDefault(), 3, 0.1);
  EXPECT_EQ(frames.views(), 1);
  bool accepted = true;
  EXPECT_TRUE(frames.observe(obs(1, 1.0, 4), &accepted).empty());
  EXPECT_FALSE(accepted);
  const auto closed = frames.observe(obs(0, 1.0, 4));
  ASSERT_EQ(closed.size(), 1u);  // its only view reported
  EXPECT_EQ(closed[0].fused.gesture_id, 4);
}

TEST(GestureFramesTest, AHeldGestureFiresOnceWithItsActionThenCoolsDown) {
  gg::GestureFrames frames(filter(), fusion(1), gg::GestureMapping::paperDefault(), 3, 0.0);
  int fired = 0;
  const gg::GestureAction* action = nullptr;
  for (int k = 0; k < 30; ++k) {  // 3 s of gesture 1 at 10 Hz, less than the 5 s cool-down
    for (const auto& f : frames.observe(obs(0, 0.1 * k, 1))) {
      if (f.filter.fired) {
        ++fired;
        action = f.action;
        EXPECT_EQ(f.filter.dominant_id, 1);
      }
    }
  }
  EXPECT_EQ(fired, 1);
  ASSERT_NE(action, nullptr);
  EXPECT_EQ(action, frames.mapping().find(1));
}

// Three views, 2 of 3 to agree: the leader and follower 1 read gesture 1, follower 2 none. The
// command fires; follower 1 is then lost for 3 s (the vote falls short: id 0, but only one view sees
// none) and returns while the worker still holds the gesture: no second command. Once two views see
// none for release_s, the next performance fires.
TEST(GestureFramesTest, AViewLostWhileTheGestureIsHeldIsNoRelease) {
  gg::GestureFilterConfig fc = filter();
  fc.release_s = 1.0;
  gg::GestureFrames frames(fc, fusion(2), gg::GestureMapping::paperDefault(), 3, 0.0);
  std::vector<double> fired;
  double t = 0.0;
  const auto step = [&](int id0, int id1, int id2, bool view1) {
    std::vector<gg::ViewObservation> os{obs(0, t, id0), obs(2, t, id2)};
    if (view1) os.push_back(obs(1, t, id1));
    for (const auto& o : os) {
      for (const auto& f : frames.observe(o)) {
        if (f.filter.fired) fired.push_back(f.t_s);
      }
    }
    for (const auto& f : frames.closeDue(t + 1.0)) {
      if (f.filter.fired) fired.push_back(f.t_s);
    }
    t += 0.1;
  };
  while (t < 2.0) step(1, 1, 0, true);
  ASSERT_EQ(fired.size(), 1u);
  while (t < 5.0) step(1, 1, 0, false);  // follower 1 lost: the vote falls short
  while (t < 12.0) step(1, 1, 0, true);  // back, the gesture still held (past the 5 s cool-down)
  EXPECT_EQ(fired.size(), 1u) << "fired again at " << fired.back() << " s";
  while (t < 14.0) step(0, 0, 0, true);  // released
  while (t < 16.0) step(1, 1, 0, true);
  EXPECT_EQ(fired.size(), 2u);
}

// A new leader's frames (awaitRelease) wait for the gesture in progress to be released.
TEST(GestureFramesTest, ANewLeadersFramesWaitForTheGestureInProgressToBeReleased) {
  gg::GestureFilterConfig fc = filter();
  fc.release_s = 1.0;
  gg::GestureFrames frames(fc, fusion(1), gg::GestureMapping::paperDefault(), 3, 0.0);
  frames.awaitRelease();
  int fired = 0;
  double t = 0.0;
  const auto run = [&](int id, double until) {
    for (; t < until - 1e-9; t += 0.1) {
      for (const auto& f : frames.observe(obs(0, t, id))) fired += f.filter.fired ? 1 : 0;
    }
  };
  run(1, 4.0);
  EXPECT_EQ(fired, 0);
  run(0, 6.0);
  run(1, 9.0);
  EXPECT_EQ(fired, 1);
}

// Unsynchronised cameras (onboard): three 15 Hz cameras whose frames are 0, 20 and 45 ms apart.
// Grouped by exact stamps every observation would be a frame of its own (45 a second, each voted on
// by one fresh view); merged within 50 ms, one frame per camera period holds one observation of each
// view and closes as soon as the third arrives, stamped with the latest of them.
TEST(GestureFramesTest, UnsynchronisedCamerasMergeIntoOneFramePerPeriodOneObservationPerView) {
  const double period = 1.0 / 15.0, offsets[3] = {0.0, 0.020, 0.045};
  auto run = [&](double merge_s, std::vector<gg::GestureFrame>& closed) {
    gg::GestureFrames frames(filter(), fusion(2), gg::GestureMapping::paperDefault(), 3, 0.1, merge_s);
    for (int k = 0; k < 15; ++k) {
      for (int v = 0; v < 3; ++v) {
        for (auto& f : frames.observe(obs(v, 10.0 + k * period + offsets[v], 2))) closed.push_back(f);
      }
    }
    for (auto& f : frames.closeDue(20.0)) closed.push_back(f);
  };
  std::vector<gg::GestureFrame> merged, exact;
  run(0.05, merged);
  run(0.0, exact);
  EXPECT_EQ(exact.size(), 45u);
  ASSERT_EQ(merged.size(), 15u);
  for (std::size_t k = 0; k < merged.size(); ++k) {
    EXPECT_EQ(merged[k].reported, 3) << k;
    EXPECT_NEAR(merged[k].t_s, 10.0 + k * period + 0.045, 1e-9) << k;  // the latest stamp of its three
    EXPECT_EQ(merged[k].fused.agreeing_views, 3) << k;
    if (k > 0) {
      EXPECT_GT(merged[k].t_s, merged[k - 1].t_s);
    }
  }
  // One view's two observations 30 ms apart never share a frame.
  gg::GestureFrames frames(filter(), fusion(2), gg::GestureMapping::paperDefault(), 3, 0.1, 0.05);
  EXPECT_TRUE(frames.observe(obs(0, 1.00, 2)).empty());
  EXPECT_TRUE(frames.observe(obs(0, 1.03, 2)).empty());
  EXPECT_TRUE(frames.observe(obs(1, 1.01, 2)).empty());  // joins the first frame
  const auto first = frames.observe(obs(2, 1.02, 2));    // … which is complete now
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0].reported, 3);
  EXPECT_DOUBLE_EQ(first[0].t_s, 1.02);
  const auto rest = frames.closeDue(2.0);
  ASSERT_EQ(rest.size(), 1u);
  EXPECT_EQ(rest[0].reported, 1);
  EXPECT_DOUBLE_EQ(rest[0].t_s, 1.03);
}

// Merging, out of order (review finding): a follower's observation of an earlier frame arriving
// after the leader opened two later ones opens its own frame before them; frames close and are
// filtered in time order, a completed frame behind an open one is returned with it, and a
// duplicated copy of an observation is not counted twice.
TEST(GestureFramesTest, MergedFramesCloseInTimeOrderWhateverTheArrivalOrder) {
  gg::GestureFrames frames(filter(), fusion(2), gg::GestureMapping::paperDefault(), 3, 0.1, 0.05);
  EXPECT_TRUE(frames.observe(obs(0, 1.000, 2)).empty());  // A
  EXPECT_TRUE(frames.observe(obs(0, 1.067, 2)).empty());  // B
  EXPECT_TRUE(frames.observe(obs(1, 0.940, 2)).empty());  // C: 60 ms before A, its own frame
  EXPECT_TRUE(frames.observe(obs(1, 0.940, 2)).empty());  // a duplicate of it: not counted
  EXPECT_TRUE(frames.observe(obs(2, 0.945, 2)).empty());  // joins C (2 of 3)
  EXPECT_TRUE(frames.observe(obs(1, 1.070, 2)).empty());  // joins B (A is 70 ms away)
  const auto closed = frames.closeDue(10.0);
  ASSERT_EQ(closed.size(), 3u);
  EXPECT_DOUBLE_EQ(closed[0].t_s, 0.945);  // C, its latest stamp
  EXPECT_EQ(closed[0].reported, 2);        // the duplicate not counted
  EXPECT_DOUBLE_EQ(closed[1].t_s, 1.000);  // A
  EXPECT_DOUBLE_EQ(closed[2].t_s, 1.070);  // B with follower 1's 1.070
  EXPECT_EQ(closed[2].reported, 2);
  // A frame completed behind an open one comes out with it, in time order.
  gg::GestureFrames g(filter(), fusion(2), gg::GestureMapping::paperDefault(), 3, 0.1, 0.05);
  EXPECT_TRUE(g.observe(obs(0, 2.000, 2)).empty());  // D
  EXPECT_TRUE(g.observe(obs(1, 1.900, 2)).empty());  // E, before D
  EXPECT_TRUE(g.observe(obs(0, 1.905, 2)).empty());  // joins E
  const auto done = g.observe(obs(2, 1.910, 2));     // completes E (D still open)
  ASSERT_EQ(done.size(), 1u);
  EXPECT_DOUBLE_EQ(done[0].t_s, 1.910);
  EXPECT_EQ(done[0].reported, 3);
}

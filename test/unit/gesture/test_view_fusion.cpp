#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gesture_formation/gesture/view_fusion.hpp"

using namespace gesture_formation::gesture;
using gesture_formation::common::ConfigReader;

namespace {

ViewObservation obs(int view, double t, int id, double d = 10.0, double el = 20.0) {
  ViewObservation o;
  o.view = view;
  o.t_s = t;
  o.gesture_id = id;
  o.distance_m = d;
  o.elevation_deg = el;
  return o;
}

}  // namespace

TEST(ViewFusionTest, TwoOfThreeAgreeingViewsPassAGesture) {
  ViewFusion f(ViewFusionConfig{}, 3, 4);
  ASSERT_TRUE(f.observe(obs(0, 1.0, 2)));
  ASSERT_TRUE(f.observe(obs(1, 1.0, 0)));
  ASSERT_TRUE(f.observe(obs(2, 1.0, 2)));
  const FusedGesture g = f.fuse(1.0);
  EXPECT_EQ(g.gesture_id, 2);
  EXPECT_EQ(g.voting_views, 3);
  EXPECT_EQ(g.agreeing_views, 2);
}

TEST(ViewFusionTest, OneViewSeeingAGestureIsNotEnough) {
  ViewFusion f(ViewFusionConfig{}, 3, 4);
  f.observe(obs(0, 1.0, 2));  // the leader sees "extend arm" (a pointing arm from the wrong side)
  f.observe(obs(1, 1.0, 0));
  f.observe(obs(2, 1.0, 0));
  EXPECT_EQ(f.fuse(1.0).gesture_id, 0);
  EXPECT_EQ(f.fuse(1.0).agreeing_views, 1);
}

TEST(ViewFusionTest, ConflictingGesturesWithEqualVotesFuseToNone) {
  ViewFusionConfig c;
  c.min_agreeing_views = 1;
  ViewFusion f(c, 2, 4);
  f.observe(obs(0, 1.0, 2));
  f.observe(obs(1, 1.0, 4));
  EXPECT_EQ(f.fuse(1.0).gesture_id, 0);  // a tie is no majority
  f.observe(obs(1, 1.1, 2));
  EXPECT_EQ(f.fuse(1.1).gesture_id, 2);
}

TEST(ViewFusionTest, SingleCameraConfigurationIsThePapersPipeline) {
  ViewFusionConfig c;
  c.min_agreeing_views = 1;
  ViewFusion f(c, 1, 4);
  for (int id = 0; id <= 4; ++id) {
    ASSERT_TRUE(f.observe(obs(0, id, id)));
    EXPECT_EQ(f.fuse(id).gesture_id, id);
  }
}

TEST(ViewFusionTest, StaleViewsDoNotVote) {
  ViewFusion f(ViewFusionConfig{}, 3, 4);  // max_age_s 0.25
  f.observe(obs(0, 10.0, 3));
  f.observe(obs(1, 9.70, 3));  // 0.30 s old at t = 10
  f.observe(obs(2, 10.0, 0));
  const FusedGesture g = f.fuse(10.0);
  EXPECT_EQ(g.gesture_id, 0);
  EXPECT_EQ(g.voting_views, 2);
  f.observe(obs(1, 9.80, 3));  // 0.20 s old: votes
  EXPECT_EQ(f.fuse(10.0).gesture_id, 3);
}

TEST(ViewFusionTest, ViewsOutsideTheEnvelopeOrOfUnknownGeometryDoNotVote) {
  ViewFusion f(ViewFusionConfig{}, 3, 4);  // envelope 5–20 m, 0–45°
  f.observe(obs(0, 1.0, 4, 10.0, 20.0));
  f.observe(obs(1, 1.0, 4, 10.0, 55.0));          // too steep
  f.observe(obs(2, 1.0, 4, 24.0, 20.0));          // too far
  EXPECT_EQ(f.fuse(1.0).gesture_id, 0);
  EXPECT_EQ(f.fuse(1.0).voting_views, 1);
  f.observe(obs(2, 1.0, 4, std::nan(""), 20.0));  // unknown distance
  EXPECT_EQ(f.fuse(1.0).voting_views, 1);
  f.observe(obs(2, 1.0, 4, 19.9, 44.9));
  EXPECT_EQ(f.fuse(1.0).gesture_id, 4);
  ViewFusionConfig open;
  open.gate_envelope = false;
  ViewFusion g(open, 2, 4);
  g.observe(obs(0, 1.0, 4, 30.0, 70.0));
  g.observe(obs(1, 1.0, 4, std::nan(""), std::nan("")));
  EXPECT_EQ(g.fuse(1.0).gesture_id, 4);
}

TEST(ViewFusionTest, BadObservationsAreRejectedAndChangeNothing) {
  ViewFusion f(ViewFusionConfig{}, 2, 4);
  ASSERT_TRUE(f.observe(obs(0, 5.0, 1)));
  ASSERT_TRUE(f.observe(obs(1, 5.0, 1)));
  std::string why;
  EXPECT_FALSE(f.observe(obs(2, 5.0, 1), &why));
  EXPECT_NE(why.find("view 2"), std::string::npos) << why;
  EXPECT_FALSE(f.observe(obs(0, std::nan(""), 3), &why));
  EXPECT_NE(why.find("not finite"), std::string::npos) << why;
  EXPECT_FALSE(f.observe(obs(0, 5.1, 7), &why));
  EXPECT_NE(why.find("gesture_id 7"), std::string::npos) << why;
  EXPECT_FALSE(f.observe(obs(1, 4.0, 3), &why));  // older than the stored one
  EXPECT_NE(why.find("older"), std::string::npos) << why;
  EXPECT_EQ(f.fuse(5.0).gesture_id, 1);  // the stored observations are intact
  EXPECT_EQ(f.fuse(5.0).agreeing_views, 2);
}

TEST(ViewFusionTest, ConfigReaderListsEveryBadKey) {
  const std::string yaml =
      "view_fusion: {min_agreeing_views: 0, max_age_s: -1, distance_min_m: 10, distance_max_m: 5, "
      "elevation_min_deg: 30, elevation_max_deg: 10}\n";
  ConfigReader r = ConfigReader::fromString(yaml, "test.yaml", ConfigReader::MissingKeys::kUseDefaults);
  (void)readViewFusionConfig(r);
  EXPECT_FALSE(r.ok());
  const std::string report = r.errorReport();
  for (const char* key : {"view_fusion.min_agreeing_views", "view_fusion.max_age_s", "view_fusion.distance_max_m",
                          "view_fusion.elevation_max_deg"}) {
    EXPECT_NE(report.find(key), std::string::npos) << key << " missing in:\n" << report;
  }
  ViewFusionConfig bad;
  bad.elevation_max_deg = -5.0;
  bad.max_age_s = std::nan("");
  EXPECT_EQ(bad.validate().size(), 2u);
  EXPECT_TRUE(ViewFusionConfig{}.validate().empty());
}

namespace {

/// Feeds view `view` ten classifications at 10 Hz ending at t_end; `ids[k]` is the k-th one's gesture.
void feed(ViewFusion& f, int view, double t_end, const std::vector<int>& ids, double d = 10.0, double el = 20.0) {
  for (std::size_t k = 0; k < ids.size(); ++k) {
    const double t = t_end - 0.1 * static_cast<double>(ids.size() - 1 - k);
    ASSERT_TRUE(f.observe(obs(view, t, ids[k], d, el)));
  }
}

}  // namespace

TEST(ViewFusionTest, OneStrayFrameInTheVoteWindowDoesNotVote) {
  ViewFusionConfig c;  // vote_window_s 1.0, vote_min_fraction 0.5
  c.min_agreeing_views = 1;
  ViewFusion f(c, 1, 4);
  feed(f, 0, 2.0, {0, 0, 0, 0, 0, 0, 0, 0, 0, 2});  // the newest frame reads "extend arm"
  EXPECT_EQ(f.fuse(2.0).gesture_id, 0);
  ViewFusionConfig newest = c;
  newest.vote_window_s = 0.0;  // the newest classification votes: the stray frame fires
  ViewFusion g(newest, 1, 4);
  feed(g, 0, 2.0, {0, 0, 0, 0, 0, 0, 0, 0, 0, 2});
  EXPECT_EQ(g.fuse(2.0).gesture_id, 2);
}

TEST(ViewFusionTest, AGestureReadInPartOfAViewsFramesVotes) {
  ViewFusion f(ViewFusionConfig{}, 3, 4);                 // two agreeing views needed
  feed(f, 0, 3.0, {4, 4, 4, 4, 4, 4, 4, 4, 4, 4});      // a good viewpoint
  feed(f, 1, 3.0, {0, 4, 0, 4, 4, 0, 4, 4, 0, 0});      // along the raised arm: 5 of 10, newest none
  feed(f, 2, 3.0, {0, 0, 0, 0, 0, 0, 0, 0, 0, 0});
  FusedGesture g = f.fuse(3.0);
  EXPECT_EQ(g.gesture_id, 4);
  EXPECT_EQ(g.agreeing_views, 2);
  ViewFusion h(ViewFusionConfig{}, 3, 4);
  feed(h, 0, 3.0, {4, 4, 4, 4, 4, 4, 4, 4, 4, 4});
  feed(h, 1, 3.0, {0, 4, 0, 4, 4, 0, 0, 4, 0, 0});      // 4 of 10 < 0.5: no vote
  feed(h, 2, 3.0, {0, 0, 0, 0, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(h.fuse(3.0).gesture_id, 0);
  EXPECT_EQ(h.fuse(3.0).agreeing_views, 1);
}

// The false adaptation of the fault matrix (worker_lost_5s seed 14, 149.87 s, docs/gestures.md
// §4.1): a work posture the leader reads as none in every frame, follower 2 as "extend an arm" in
// 13 of 14 frames and follower 1 in 6 of 13 (here at 10 Hz: 9 and 4 of the window's 10). With
// vote_min_fraction 0.3 both followers voted and the fused id was the gesture for 1.7 s; a view
// must read it in half its frames.
TEST(ViewFusionTest, AWorkPostureOneViewReadsInLessThanHalfItsFramesDoesNotFire) {
  const std::vector<int> leader(14, 0);
  const std::vector<int> follower1{0, 2, 0, 2, 0, 0, 2, 0, 0, 0, 0, 2, 2};
  const std::vector<int> follower2{2, 2, 2, 2, 2, 0, 2, 2, 2, 2, 2, 2, 2, 2};
  ViewFusion f(ViewFusionConfig{}, 3, 4);
  feed(f, 0, 150.0, leader);
  feed(f, 1, 150.0, follower1);
  feed(f, 2, 150.0, follower2);
  EXPECT_EQ(f.fuse(150.0).gesture_id, 0);
  EXPECT_EQ(f.fuse(150.0).agreeing_views, 1);
  ViewFusionConfig loose;
  loose.vote_min_fraction = 0.3;  // the rule of 29d7fa9
  ViewFusion g(loose, 3, 4);
  feed(g, 0, 150.0, leader);
  feed(g, 1, 150.0, follower1);
  feed(g, 2, 150.0, follower2);
  EXPECT_EQ(g.fuse(150.0).gesture_id, 2);
}

TEST(ViewFusionTest, TheVoteWindowForgetsAndSkipsFramesOutsideTheEnvelope) {
  ViewFusionConfig c;
  c.min_agreeing_views = 1;
  ViewFusion f(c, 1, 4);
  feed(f, 0, 1.0, {3, 3, 3, 3, 3, 3, 3, 3, 3, 3});
  EXPECT_EQ(f.fuse(1.0).gesture_id, 3);
  feed(f, 0, 2.0, {0, 0, 0, 0, 0, 0, 0, 0, 0, 0});  // a second of "none": the gesture has left the window
  EXPECT_EQ(f.fuse(2.0).gesture_id, 0);
  ViewFusion g(c, 1, 4);
  feed(g, 0, 1.0, {1, 1, 1, 1, 1, 1, 1, 1, 1, 1}, 10.0, 60.0);  // too steep: these do not count
  feed(g, 0, 1.5, {0, 0, 0, 0, 0}, 10.0, 20.0);
  EXPECT_EQ(g.fuse(1.5).gesture_id, 0);
  EXPECT_EQ(g.fuse(1.5).voting_views, 1);
}

TEST(ViewFusionTest, VoteWindowKeysAreValidated) {
  const std::string yaml = "view_fusion: {vote_window_s: -0.5, vote_min_fraction: 1.5}\n";
  ConfigReader r = ConfigReader::fromString(yaml, "test.yaml", ConfigReader::MissingKeys::kUseDefaults);
  (void)readViewFusionConfig(r);
  EXPECT_FALSE(r.ok());
  const std::string report = r.errorReport();
  for (const char* key : {"view_fusion.vote_window_s", "view_fusion.vote_min_fraction"}) {
    EXPECT_NE(report.find(key), std::string::npos) << key << " missing in:\n" << report;
  }
  ViewFusionConfig bad;
  bad.vote_window_s = std::nan("");
  bad.vote_min_fraction = 0.0;
  const std::vector<std::string> problems = bad.validate();
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("vote_window_s"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("vote_min_fraction"), std::string::npos) << problems[1];
}

// Link delay (docs/gestures.md §4.1, safety.md §2.1): a follower's classifications arrive 0.35 s
// after their frame, older than max_age_s (0.25 s) by then. Fused at the newest frame that view never
// votes and a gesture seen by the leader and that follower does not pass; fused fusion_lag_s (0.4 s)
// in the past, both views are compared at one moment every report has reached.
TEST(ViewFusionTest, DelayedFollowerVotesCountWhenTheViewsAreFusedAtALag) {
  for (const double lag : {0.0, 0.4}) {
    ViewFusionConfig c;  // two agreeing views needed
    c.fusion_lag_s = lag;
    ViewFusion f(c, 3, 4);
    int fused_gestures = 0, frames = 0;
    for (int k = 0; k <= 30; ++k) {  // 10 Hz frames 0..3 s, the worker extends an arm throughout
      const double t = 0.1 * k;
      ASSERT_TRUE(f.observe(obs(0, t, 2)));
      const int late = k - 4;  // the follower frame stamped 0.35 s ago arrived by now (0.4 s ago: 0.05 s)
      if (late >= 0) {
        ASSERT_TRUE(f.observe(obs(1, 0.1 * late, 2)));
        ASSERT_TRUE(f.observe(obs(2, 0.1 * late, 0)));  // the third view reads none
      }
      if (t < 1.5) continue;
      ++frames;
      const FusedGesture g = f.fuse(t - c.fusion_lag_s);
      fused_gestures += g.gesture_id == 2 ? 1 : 0;
      EXPECT_EQ(g.voting_views, lag > 0.0 ? 3 : 1) << "t " << t << " lag " << lag;
    }
    EXPECT_EQ(fused_gestures, lag > 0.0 ? frames : 0) << "lag " << lag;
  }
}

TEST(ViewFusionTest, ObservationsArriveOutOfOrderOnlyWithinTheLag) {
  ViewFusionConfig c;
  c.min_agreeing_views = 1;
  c.fusion_lag_s = 0.4;
  ViewFusion f(c, 1, 4);
  ASSERT_TRUE(f.observe(obs(0, 1.0, 0)));
  ASSERT_TRUE(f.observe(obs(0, 0.8, 3)));  // reordered by the link: inserted before 1.0
  ASSERT_TRUE(f.observe(obs(0, 0.9, 3)));
  // The newest at 0.6 (+ max_age_s 0.25) is the frame of 0.8, not the last to arrive.
  EXPECT_EQ(f.fuse(0.6).voting_views, 1);
  EXPECT_EQ(f.fuse(1.0).gesture_id, 3);  // two of the window's three frames read 3
  std::string why;
  EXPECT_FALSE(f.observe(obs(0, 0.5, 1), &why));  // 0.5 s before the newest: beyond the lag
  EXPECT_NE(why.find("fusion_lag_s"), std::string::npos) << why;
  EXPECT_EQ(f.fuse(1.0).gesture_id, 3);  // nothing changed
  ViewFusionConfig no_lag;  // (the default is 0.4 s since 2026-12-03)
  no_lag.fusion_lag_s = 0.0;
  ViewFusion strict(no_lag, 1, 4);  // no lag: an older frame is rejected, as before
  ASSERT_TRUE(strict.observe(obs(0, 1.0, 0)));
  EXPECT_FALSE(strict.observe(obs(0, 0.9, 3), &why));
  EXPECT_NE(why.find("older"), std::string::npos) << why;
  ViewFusionConfig nan_lag;  // not validated: clamped to no lag, not "accept anything"
  nan_lag.fusion_lag_s = std::nan("");
  ViewFusion clamped(nan_lag, 1, 4);
  ASSERT_TRUE(clamped.observe(obs(0, 1.0, 0)));
  EXPECT_FALSE(clamped.observe(obs(0, 0.9, 3)));
}

TEST(ViewFusionTest, FusionLagIsValidated) {
  ConfigReader r = ConfigReader::fromString("view_fusion: {fusion_lag_s: 3.5}\n", "test.yaml",
                                            ConfigReader::MissingKeys::kUseDefaults);
  (void)readViewFusionConfig(r);
  EXPECT_FALSE(r.ok());
  EXPECT_NE(r.errorReport().find("view_fusion.fusion_lag_s"), std::string::npos) << r.errorReport();
  ConfigReader ok = ConfigReader::fromString("view_fusion: {fusion_lag_s: 0.4}\n", "test.yaml",
                                             ConfigReader::MissingKeys::kUseDefaults);
  EXPECT_DOUBLE_EQ(readViewFusionConfig(ok).fusion_lag_s, 0.4);
  EXPECT_TRUE(ok.ok()) << ok.errorReport();
  ViewFusionConfig bad;
  bad.fusion_lag_s = -0.1;
  const std::vector<std::string> problems = bad.validate();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_NE(problems[0].find("fusion_lag_s must be in [0, 2], got -0.1"), std::string::npos) << problems[0];
}

// Issue 34: the rules between keys (distance_max > distance_min, elevation_max > elevation_min)
// are reported beside a key already out of range.
TEST(ViewFusionTest, YamlReportsTheRuleBesideAnOutOfRangeKey) {
  ConfigReader r = ConfigReader::fromString(
      "view_fusion: {vote_window_s: 61, distance_min_m: 30, distance_max_m: 20}\n", "v.yaml",
      ConfigReader::MissingKeys::kUseDefaults);
  (void)readViewFusionConfig(r);
  ASSERT_EQ(r.problems().size(), 2u) << r.errorReport();
  EXPECT_EQ(r.problems()[0].key, "view_fusion.vote_window_s");
  EXPECT_EQ(r.problems()[1].key, "view_fusion.distance_max_m");
  EXPECT_NE(r.problems()[1].message.find("20"), std::string::npos) << r.problems()[1].message;
}

// One range per key: the YAML reader and validate() accept and refuse the same boundary values
// (vote_min_fraction: (0, 1] in both; the reader's [1e-9, 1] is gone).
TEST(ViewFusionTest, ValidateAndYamlAgreeOnBoundaries) {
  struct Case {
    const char* text;
    bool valid;
  };
  for (const Case& k : {Case{"1", true}, Case{"1e-12", true}, Case{"0", false}, Case{"1.5", false}}) {
    const std::string yaml = std::string("view_fusion: {vote_min_fraction: ") + k.text + "}\n";
    ConfigReader r = ConfigReader::fromString(yaml, "v.yaml", ConfigReader::MissingKeys::kUseDefaults);
    (void)readViewFusionConfig(r);
    EXPECT_EQ(r.ok(), k.valid) << yaml << r.errorReport();
    ViewFusionConfig c;
    c.vote_min_fraction = std::stod(k.text);
    EXPECT_EQ(c.validate().empty(), k.valid) << yaml;
  }
}

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "gesture_formation/gesture/gesture_filter.hpp"

using namespace gesture_formation::gesture;
using gesture_formation::common::ConfigReader;

namespace {

/// The paper's filter (rearm: repeat): the tests below that pin the window, ratio, tie and
/// cooldown semantics use it; the re-arming on release has its own tests at the end.
GestureFilterConfig config(int k, int min_meas, double max_age, double ratio, double cooldown) {
  GestureFilterConfig c;
  c.rearm = RearmMode::kRepeat;
  c.window_size = k;
  c.min_measurements = min_meas;
  c.max_age_s = max_age;
  c.ratio_threshold = ratio;
  c.cooldown_s = cooldown;
  return c;
}

GestureFilterConfig paperDefaults() {
  GestureFilterConfig c;
  c.rearm = RearmMode::kRepeat;
  return c;
}

/// Feeds (t, id) pairs; returns the times at which the filter fired.
std::vector<double> feed(GestureFilter& f, const std::vector<std::pair<double, int>>& rows) {
  std::vector<double> fired;
  for (const auto& [t, id] : rows) {
    if (f.update(t, id).fired) fired.push_back(t);
  }
  return fired;
}

}  // namespace

TEST(GestureFilterTest, DefaultsAreThePapers) {
  const GestureFilterConfig c;
  EXPECT_EQ(c.window_size, 20);
  EXPECT_EQ(c.min_measurements, 20);
  EXPECT_EQ(c.max_age_s, 20.0);
  EXPECT_EQ(c.ratio_threshold, 0.8);
  EXPECT_EQ(c.cooldown_s, 5.0);
  EXPECT_EQ(c.rearm, RearmMode::kRelease);  // ours: one performance, one command (the paper: repeat)
  EXPECT_EQ(c.release_s, 1.0);
  EXPECT_TRUE(c.validate().empty());
}

TEST(GestureFilterTest, FiresOnceTheWindowIsFullAndDominant) {
  GestureFilter f(GestureFilterConfig{});
  for (int i = 0; i < 19; ++i) {
    const auto o = f.update(0.1 * i, 2);
    EXPECT_TRUE(o.accepted);
    EXPECT_FALSE(o.evaluated);
  }
  const auto o = f.update(1.9, 2);
  EXPECT_TRUE(o.evaluated);
  EXPECT_TRUE(o.fired);
  EXPECT_EQ(o.verdict, FilterVerdict::kFired);
  EXPECT_EQ(o.dominant_id, 2);
  EXPECT_EQ(o.dominant_ratio, 1.0);
  EXPECT_EQ(f.lastFiredTime(), 1.9);
}

TEST(GestureFilterTest, RatioMustStrictlyExceedThreshold) {
  // 16 of 20 = 0.8 exactly: no; 17 of 20 = 0.85: yes.
  GestureFilter h(GestureFilterConfig{});
  std::vector<std::pair<double, int>> rows;
  for (int i = 0; i < 4; ++i) rows.push_back({i, 3});
  for (int i = 4; i < 20; ++i) rows.push_back({i, 1});
  EXPECT_TRUE(feed(h, rows).empty());  // 16/20 = 0.8 is not > 0.8
  EXPECT_EQ(h.update(19.5, 3).verdict, FilterVerdict::kBelowThreshold);  // a 3 replaces the oldest 3: still 16/20
  const auto o = h.update(20.0, 1);    // oldest 3 leaves the window (K): 17/20
  EXPECT_EQ(o.dominant_ratio, 0.85);
  EXPECT_TRUE(o.fired);
}

TEST(GestureFilterTest, TieForMostFrequentFiresNothing) {
  GestureFilter f(config(4, 4, 20.0, 0.4, 0.0));
  f.update(0.0, 1);
  f.update(0.1, 2);
  f.update(0.2, 1);
  const auto o = f.update(0.3, 2);  // 2 × 1, 2 × 2: ratio 0.5 > 0.4 but a tie
  EXPECT_TRUE(o.evaluated);
  EXPECT_FALSE(o.fired);
  EXPECT_EQ(o.dominant_id, -1);
  EXPECT_EQ(o.dominant_ratio, 0.5);
  EXPECT_EQ(o.verdict, FilterVerdict::kTie);
  EXPECT_TRUE(f.update(0.4, 2).fired);  // window 1,2,1,2 → 2,1,2,2: 3/4 of gesture 2
}

TEST(GestureFilterTest, NoneDominanceFiresNothing) {
  GestureFilter f(config(5, 5, 20.0, 0.5, 0.0));
  std::vector<std::pair<double, int>> rows;
  for (int i = 0; i < 30; ++i) rows.push_back({0.1 * i, i % 5 == 0 ? 3 : 0});
  EXPECT_TRUE(feed(f, rows).empty());
  const auto o = f.update(3.0, 0);
  EXPECT_EQ(o.dominant_id, 0);
  EXPECT_EQ(o.verdict, FilterVerdict::kNoneDominant);
}

TEST(GestureFilterTest, EntryExactlyMaxAgeOldIsKept) {
  // t_c = 2: at t = 3 the entry at t = 1 (exactly t_c old) stays, the one at 0.5 goes.
  GestureFilter f(config(10, 3, 2.0, 0.5, 0.0));
  f.update(0.5, 1);
  f.update(1.0, 1);
  const auto o = f.update(3.0, 1);
  EXPECT_EQ(o.window_count, 2u);
  EXPECT_FALSE(o.evaluated);
  EXPECT_EQ(f.update(3.0, 1).window_count, 3u);
  EXPECT_EQ(f.update(3.0000001, 1).window_count, 3u);  // the entry at 1.0 is now older than t − t_c
}

TEST(GestureFilterTest, CooldownBoundaryAndFirstCommandFree) {
  GestureFilter f(config(2, 2, 100.0, 0.5, 5.0));
  f.update(0.0, 4);
  EXPECT_TRUE(f.update(1.0, 4).fired);   // first command: no cooldown
  EXPECT_FALSE(f.update(5.5, 4).fired);  // 4.5 s < 5
  const auto o = f.update(5.75, 4);
  EXPECT_FALSE(o.fired);
  EXPECT_EQ(o.verdict, FilterVerdict::kCooldown);
  EXPECT_TRUE(o.reason.empty());
  EXPECT_TRUE(f.update(6.0, 4).fired);   // exactly 5 s: fires
  EXPECT_EQ(f.lastFiredTime(), 6.0);
}

TEST(GestureFilterTest, WindowLargerThanDataNeverEvaluates) {
  GestureFilter f(GestureFilterConfig{});  // K = min = 20
  std::vector<std::pair<double, int>> rows;
  for (int i = 0; i < 19; ++i) rows.push_back({0.1 * i, 1});
  EXPECT_TRUE(feed(f, rows).empty());
  EXPECT_EQ(f.size(), 19u);
}

TEST(GestureFilterTest, MinMeasurementsBelowWindowSize) {
  GestureFilter f(config(20, 5, 20.0, 0.8, 5.0));
  std::vector<std::pair<double, int>> rows;
  for (int i = 0; i < 5; ++i) rows.push_back({0.1 * i, 3});
  const auto fired = feed(f, rows);
  ASSERT_EQ(fired.size(), 1u);
  EXPECT_DOUBLE_EQ(fired[0], 0.4);
}

TEST(GestureFilterTest, SparseInputIsLimitedByAge) {
  // One measurement every 3 s with t_c = 5: the window never holds more than 2.
  GestureFilter f(config(20, 3, 5.0, 0.5, 0.0));
  for (int i = 0; i < 50; ++i) {
    const auto o = f.update(3.0 * i, 1);
    EXPECT_LE(o.window_count, 2u);
    EXPECT_FALSE(o.fired);
  }
}

TEST(GestureFilterTest, BurstsWithEqualTimesAreAccepted) {
  GestureFilter f(config(6, 6, 1.0, 0.8, 5.0));
  std::vector<std::pair<double, int>> rows;
  for (int i = 0; i < 6; ++i) rows.push_back({10.0, 2});
  const auto fired = feed(f, rows);
  ASSERT_EQ(fired.size(), 1u);
  EXPECT_EQ(f.size(), 6u);
}

TEST(GestureFilterTest, KeepsOnlyTheKNewest) {
  GestureFilter f(config(10, 10, 1000.0, 0.8, 0.0));
  for (int i = 0; i < 100; ++i) f.update(i, 1);
  for (int i = 100; i < 108; ++i) {
    const auto o = f.update(i, 2);
    EXPECT_EQ(o.window_count, 10u);
  }
  const auto o = f.update(108, 2);  // 9 × 2 + 1 × 1
  EXPECT_EQ(o.dominant_id, 2);
  EXPECT_DOUBLE_EQ(o.dominant_ratio, 0.9);
  EXPECT_TRUE(o.fired);
}

TEST(GestureFilterTest, RejectsBadMeasurementsWithoutChangingState) {
  GestureFilter f(config(5, 5, 20.0, 0.5, 0.0));
  f.update(1.0, 1);
  f.update(2.0, 1);
  const struct {
    double t, id;
    const char* why;
  } bad[] = {{1.5, 1, "out of order"},
             {std::nan(""), 1, "non-finite time"},
             {INFINITY, 1, "non-finite time"},
             {3.0, 5, "unknown gesture id"},
             {3.0, -1, "unknown gesture id"},
             {3.0, 1.5, "unknown gesture id"},
             {3.0, std::nan(""), "unknown gesture id"}};
  for (const auto& b : bad) {
    const auto o = f.update(b.t, b.id);
    EXPECT_FALSE(o.accepted);
    EXPECT_NE(o.reason.find(b.why), std::string::npos) << o.reason;
    EXPECT_EQ(f.size(), 2u);
    EXPECT_EQ(f.lastTime(), 2.0);
  }
  EXPECT_TRUE(f.update(2.0, 1).accepted);
}

TEST(GestureFilterTest, NoisyStreamNeverFiresForNonGestureIdsAndRespectsCooldown) {
  std::mt19937 rng(99);
  std::uniform_int_distribution<int> id(0, 4);
  GestureFilter f(paperDefaults());
  double t = 0.0, last = -1e9;
  int fired = 0;
  for (int i = 0; i < 20000; ++i) {
    t += (i % 7 == 0) ? 0.0 : 0.05;
    const int g = (i / 200) % 2 == 0 ? 2 : id(rng);  // long runs of gesture 2 between uniform noise
    const auto o = f.update(t, g);
    if (o.fired) {
      ++fired;
      EXPECT_NE(o.dominant_id, 0);
      EXPECT_GT(o.dominant_ratio, 0.8);
      EXPECT_GE(t - last, 5.0);
      last = t;
    }
  }
  EXPECT_GT(fired, 10);
}

TEST(GestureFilterTest, ResetForgetsEverything) {
  GestureFilter f(config(2, 2, 10.0, 0.5, 100.0));
  f.update(0.0, 1);
  EXPECT_TRUE(f.update(0.1, 1).fired);
  f.reset();
  EXPECT_EQ(f.size(), 0u);
  f.update(0.0, 1);  // earlier time accepted after reset
  EXPECT_TRUE(f.update(0.1, 1).fired);  // no cooldown after reset
}

TEST(GestureFilterTest, ConfigValidationNamesFields) {
  auto c = config(10, 11, 0.0, 1.5, -1.0);
  const auto e = c.validate();
  ASSERT_EQ(e.size(), 4u);
  EXPECT_NE(e[0].find("min_measurements"), std::string::npos);
  EXPECT_NE(e[1].find("max_age_s"), std::string::npos);
  EXPECT_NE(e[2].find("ratio_threshold"), std::string::npos);
  EXPECT_NE(e[3].find("cooldown_s"), std::string::npos);
  EXPECT_FALSE(GestureFilter::create(c));
}

TEST(GestureFilterTest, ReadConfigMinMeasurementsDefaultsToWindowSize) {
  ConfigReader r = ConfigReader::fromString("window_size: 12\nratio_threshold: 0.6\n", "t.yaml",
                                            ConfigReader::MissingKeys::kUseDefaults);
  const auto c = readGestureFilterConfig(r);
  EXPECT_TRUE(r.ok()) << r.errorReport();
  EXPECT_EQ(c.window_size, 12);
  EXPECT_EQ(c.min_measurements, 12);
  EXPECT_EQ(c.ratio_threshold, 0.6);
  ConfigReader bad = ConfigReader::fromString("window_size: 5\nmin_measurements: 6\nmax_age_s: -1\n", "b.yaml",
                                              ConfigReader::MissingKeys::kUseDefaults);
  readGestureFilterConfig(bad);
  EXPECT_NE(bad.errorReport().find("min_measurements"), std::string::npos);
  EXPECT_NE(bad.errorReport().find("max_age_s"), std::string::npos);
}

// ---- rearm: release (default) — one performance, one command ---------------------------

TEST(GestureFilterReleaseTest, AHeldGestureFiresOnceHoweverLongItIsHeld) {
  GestureFilter f(GestureFilterConfig{});  // K 20, t_d 5 s, release
  int fired = 0;
  FilterVerdict last = FilterVerdict::kRejected;
  for (int i = 0; i < 600; ++i) {  // 60 s of "raise an arm" at 10 Hz: the paper would fire 12 times
    const auto o = f.update(0.1 * i, 4);
    fired += o.fired ? 1 : 0;
    last = o.verdict;
  }
  EXPECT_EQ(fired, 1);
  EXPECT_EQ(last, FilterVerdict::kAwaitingRelease);
  EXPECT_STREQ(toString(last), "awaiting_release");
  EXPECT_FALSE(f.armed());
  // The paper's filter on the same stream: every t_d.
  GestureFilter paper(paperDefaults());
  int paper_fired = 0;
  for (int i = 0; i < 600; ++i) paper_fired += paper.update(0.1 * i, 4).fired ? 1 : 0;
  EXPECT_EQ(paper_fired, 12);
}

TEST(GestureFilterReleaseTest, ReleasedForReleaseSThenTheSameGestureFiresAgain) {
  GestureFilterConfig c;
  c.release_s = 1.0;
  GestureFilter f(c);
  double t = 0.0;
  const auto run = [&](int id, double seconds) {
    std::vector<double> fired;
    for (double end = t + seconds; t < end - 1e-9; t += 0.1) {
      if (f.update(t, id).fired) fired.push_back(t);
    }
    return fired;
  };
  EXPECT_EQ(run(2, 8.0).size(), 1u);
  // Arms down for 0.8 s: "none" never dominates the 20-entry window (8 of 20): not released.
  EXPECT_TRUE(run(0, 0.8).empty());
  EXPECT_FALSE(f.armed());
  EXPECT_EQ(run(2, 6.0).size(), 0u);  // the same performance goes on: nothing more
  // Arms down for 3 s: "none" dominates from 1.1 s in (11 of 20) and for release_s after.
  EXPECT_TRUE(run(0, 3.0).empty());
  EXPECT_TRUE(f.armed());
  EXPECT_EQ(run(2, 6.0).size(), 1u);   // a new performance fires once
}

// A measurement of none that saw no release (the vote fell short: a view lost while the worker
// holds the gesture) neither counts toward the release nor lets a held gesture fire again; the
// same measurements seeing none do.
TEST(GestureFilterReleaseTest, NoneThatSawNoReleaseDoesNotReArm) {
  GestureFilterConfig c;
  c.release_s = 1.0;
  GestureFilter f(c);
  double t = 0.0;
  const auto run = [&](int id, double seconds, bool none_seen) {
    std::vector<double> fired;
    for (double end = t + seconds; t < end - 1e-9; t += 0.1) {
      if (f.update(t, id, none_seen).fired) fired.push_back(t);
    }
    return fired;
  };
  EXPECT_EQ(run(2, 3.0, true).size(), 1u);
  EXPECT_TRUE(run(0, 4.0, false).empty());  // 4 s of a vote that fell short: "none" dominates, no release
  EXPECT_FALSE(f.armed());
  EXPECT_TRUE(run(2, 6.0, true).empty());  // the views return: the same performance, nothing more
  EXPECT_TRUE(run(0, 3.0, true).empty());   // released
  EXPECT_TRUE(f.armed());
  EXPECT_EQ(run(2, 6.0, true).size(), 1u);
}

// A new leader's filter (awaitRelease) does not fire for a gesture in progress until it has been
// released: its predecessor may have fired for that performance already.
TEST(GestureFilterReleaseTest, AfterAwaitReleaseAHeldGestureFiresOnlyOnceReleased) {
  GestureFilterConfig c;
  c.release_s = 1.0;
  GestureFilter f(c);
  f.awaitRelease();
  EXPECT_FALSE(f.armed());
  double t = 0.0;
  int fired = 0;
  for (; t < 6.0; t += 0.1) fired += f.update(t, 2).fired ? 1 : 0;
  EXPECT_EQ(fired, 0);
  for (; t < 9.0; t += 0.1) fired += f.update(t, 0).fired ? 1 : 0;
  EXPECT_TRUE(f.armed());
  for (; t < 12.0; t += 0.1) fired += f.update(t, 2).fired ? 1 : 0;
  EXPECT_EQ(fired, 1);
  // rearm: repeat (the paper) stays armed.
  c.rearm = RearmMode::kRepeat;
  GestureFilter repeat(c);
  repeat.awaitRelease();
  EXPECT_TRUE(repeat.armed());
}

TEST(GestureFilterReleaseTest, BothModesFireTwiceForTwoPerformancesAndOnlyRepeatRefiresAHold) {
  for (const RearmMode mode : {RearmMode::kRelease, RearmMode::kRepeat}) {
    SCOPED_TRACE(toString(mode));
    GestureFilterConfig c;  // K 20, t_d 5 s, release_s 1 s
    c.rearm = mode;
    GestureFilter f(c);
    double t = 0.0;
    const auto run = [&](int id, double seconds) {
      int fired = 0;
      for (double end = t + seconds; t < end - 1e-9; t += 0.1) fired += f.update(t, id).fired ? 1 : 0;
      return fired;
    };
    // A held gesture (16 s): release fires once, repeat at 1.9, 6.9, 11.9 s (every t_d).
    EXPECT_EQ(run(1, 16.0), mode == RearmMode::kRelease ? 1 : 3);
    EXPECT_EQ(run(0, 4.0), 0);  // released (arms down 4 s)
    // Performed again for 3 s (shorter than t_d after its first command): once, in both modes.
    EXPECT_EQ(run(1, 3.0), 1);
  }
}

TEST(GestureFilterReleaseTest, ATieOrAnotherGestureRestartsTheRelease) {
  GestureFilterConfig c;  // times are multiples of 0.25 s: exact in binary
  c.window_size = 4;
  c.min_measurements = 4;
  c.cooldown_s = 0.0;
  c.release_s = 0.75;
  GestureFilter f(c);
  int fired = 0;
  for (int i = 0; i < 4; ++i) fired += f.update(0.25 * i, 1).fired ? 1 : 0;  // fires at 0.75
  EXPECT_EQ(fired, 1);
  EXPECT_FALSE(f.armed());
  const auto feedAt = [&f](double t, int id) { f.update(t, id); };
  feedAt(1.0, 0);   // [1 1 1 0]: 1 dominates
  feedAt(1.25, 0);  // [1 1 0 0]: tie
  feedAt(1.5, 0);   // [1 0 0 0]: none dominates from 1.5
  feedAt(1.75, 3);  // [0 0 0 3]: still none (0.25 s)
  EXPECT_FALSE(f.armed());
  feedAt(2.0, 3);   // [0 0 3 3]: a tie restarts the release (else it would re-arm at 2.25)
  feedAt(2.25, 0);  // [0 3 3 0]: tie
  feedAt(2.5, 0);   // [3 3 0 0]: tie
  feedAt(2.75, 0);  // [3 0 0 0]: none dominates from 2.75
  feedAt(3.25, 0);  // 0.5 s
  EXPECT_FALSE(f.armed());
  feedAt(3.5, 0);   // 0.75 s = release_s
  EXPECT_TRUE(f.armed());
}

TEST(GestureFilterReleaseTest, NothingSeenForMaxAgeIsANewPerformance) {
  GestureFilterConfig c;
  c.window_size = 5;
  c.min_measurements = 5;
  c.max_age_s = 2.0;
  c.cooldown_s = 0.0;
  GestureFilter f(c);
  int fired = 0;
  for (int i = 0; i < 10; ++i) fired += f.update(0.1 * i, 4).fired ? 1 : 0;
  EXPECT_EQ(fired, 1);
  EXPECT_FALSE(f.armed());
  // The worker out of view for 3 s (> max_age_s): the same gesture again is a new performance.
  for (int i = 0; i < 10; ++i) fired += f.update(4.0 + 0.1 * i, 4).fired ? 1 : 0;
  EXPECT_EQ(fired, 2);
}

TEST(GestureFilterReleaseTest, ConfigKeysAreReadAndValidated) {
  ConfigReader r = ConfigReader::fromString("rearm: repeat\nrelease_s: 2.5\n", "g.yaml", ConfigReader::MissingKeys::kError);
  const auto c = readGestureFilterConfig(r);
  for (const auto& p : r.problems()) EXPECT_NE(p.key, "rearm") << r.errorReport();  // (the other keys are missing)
  EXPECT_EQ(c.rearm, RearmMode::kRepeat);
  EXPECT_STREQ(toString(c.rearm), "repeat");
  EXPECT_EQ(c.release_s, 2.5);
  ConfigReader rel = ConfigReader::fromString("rearm: release\n", "g.yaml", ConfigReader::MissingKeys::kUseDefaults);
  EXPECT_EQ(readGestureFilterConfig(rel).rearm, RearmMode::kRelease);
  EXPECT_TRUE(rel.ok()) << rel.errorReport();
  ConfigReader bad = ConfigReader::fromString("rearm: sometimes\nrelease_s: -1\n", "g.yaml", ConfigReader::MissingKeys::kUseDefaults);
  EXPECT_EQ(readGestureFilterConfig(bad).rearm, RearmMode::kRelease);  // the bad value is not taken
  ASSERT_EQ(bad.problems().size(), 2u) << bad.errorReport();
  EXPECT_EQ(bad.problems()[0].key, "rearm");
  EXPECT_NE(bad.errorReport().find("sometimes"), std::string::npos) << bad.errorReport();
  EXPECT_NE(bad.errorReport().find("release|repeat"), std::string::npos) << bad.errorReport();
  EXPECT_EQ(bad.problems()[1].key, "release_s");
  // The mode's former name is not a mode.
  ConfigReader old = ConfigReader::fromString("rearm: cooldown\n", "g.yaml", ConfigReader::MissingKeys::kUseDefaults);
  readGestureFilterConfig(old);
  ASSERT_EQ(old.problems().size(), 1u) << old.errorReport();
  EXPECT_EQ(old.problems()[0].key, "rearm");
  GestureFilterConfig v;
  v.release_s = std::nan("");
  ASSERT_EQ(v.validate().size(), 1u);
  EXPECT_NE(v.validate()[0].find("release_s"), std::string::npos);
}

// Issue 34: the rule between keys (min_measurements <= window_size) is reported beside a key
// already out of range, both naming key and value.
TEST(GestureFilterTest, YamlReportsTheRuleBesideAnOutOfRangeKey) {
  ConfigReader r = ConfigReader::fromString("window_size: 5\nmin_measurements: 6\ncooldown_s: -1\n", "g.yaml",
                                            ConfigReader::MissingKeys::kUseDefaults);
  readGestureFilterConfig(r);
  ASSERT_EQ(r.problems().size(), 2u) << r.errorReport();
  EXPECT_EQ(r.problems()[0].key, "cooldown_s");
  EXPECT_NE(r.problems()[0].message.find("-1"), std::string::npos);
  EXPECT_EQ(r.problems()[1].key, "min_measurements");
  EXPECT_NE(r.problems()[1].message.find("6"), std::string::npos);
}

// One range per key: the YAML reader and validate() accept and refuse the same boundary values.
TEST(GestureFilterTest, ValidateAndYamlAgreeOnBoundaries) {
  struct Case {
    const char* key;
    const char* text;
    bool valid;
  };
  for (const Case& k : {Case{"window_size", "100000", true}, Case{"window_size", "100001", false},
                        Case{"ratio_threshold", "1", true}, Case{"ratio_threshold", "1.0000001", false},
                        Case{"cooldown_s", "0", true}, Case{"max_age_s", "0", false}}) {
    const std::string yaml = std::string(k.key) + ": " + k.text + "\nmin_measurements: 1\n";
    ConfigReader r = ConfigReader::fromString(yaml, "g.yaml", ConfigReader::MissingKeys::kUseDefaults);
    readGestureFilterConfig(r);
    EXPECT_EQ(r.ok(), k.valid) << yaml << r.errorReport();
    GestureFilterConfig c;
    c.min_measurements = 1;
    const double v = std::stod(k.text);
    if (std::string(k.key) == "window_size") c.window_size = static_cast<int>(v);
    if (std::string(k.key) == "ratio_threshold") c.ratio_threshold = v;
    if (std::string(k.key) == "cooldown_s") c.cooldown_s = v;
    if (std::string(k.key) == "max_age_s") c.max_age_s = v;
    EXPECT_EQ(c.validate().empty(), k.valid) << yaml;
  }
}

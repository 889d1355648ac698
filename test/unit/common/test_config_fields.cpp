// The shared table of configuration numbers: one range per key, used alike by validate() (a
// struct built in code) and by the YAML reader.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::common {
namespace {

struct Demo {
  double speed_mps = 2.0;
  int window = 5;
  float score = 0.5f;
};

const FieldTable<Demo>& demoFields() {
  static const FieldTable<Demo> t{{
      {"speed_mps", Range::openClosed(0.0, 3.0), [](Demo& d) { return &d.speed_mps; }},
      {"window", Range::atLeast(1), [](Demo& d) { return &d.window; }},
      {"score", Range{0.0, 1.0, true, false}, [](Demo& d) { return &d.score; }},
  }};
  return t;
}

TEST(ConfigFieldsTest, RequirementReadsAsASentence) {
  EXPECT_EQ(rangeRequirement(Range::positive()), "> 0");
  EXPECT_EQ(rangeRequirement(Range::atLeast(1)), ">= 1");
  EXPECT_EQ(rangeRequirement(Range{-std::numeric_limits<double>::infinity(), 90.0, true, false}), "< 90");
  EXPECT_EQ(rangeRequirement(Range::closed(0, 1)), "in [0, 1]");
  EXPECT_EQ(rangeRequirement(Range::any()), "finite");
  EXPECT_EQ(rangeProblem(Range::atLeast(1), 0), "must be >= 1, got 0");
  EXPECT_EQ(rangeProblem(Range::positive(), -0.5), "must be > 0, got -0.5");
}

TEST(ConfigFieldsTest, RangeProblemsNameEveryBadFieldAndItsValue) {
  Demo d;
  EXPECT_TRUE(demoFields().rangeProblems(d).empty());
  d.speed_mps = std::nan("");
  d.window = 0;
  d.score = 1.0f;
  const auto e = demoFields().rangeProblems(d);
  ASSERT_EQ(e.size(), 3u);
  EXPECT_EQ(e[0].key, "speed_mps");
  EXPECT_EQ(e[0].message, "must be in (0, 3], got nan");
  EXPECT_EQ(e[1].key, "window");
  EXPECT_EQ(e[1].message, "must be >= 1, got 0");
  EXPECT_EQ(e[2].key, "score");
  EXPECT_EQ(e[2].message, "must be in [0, 1), got 1");
  EXPECT_EQ(problemLines(e)[1], "window must be >= 1, got 0");
}

// The reader and validate() agree on each boundary: accepted by one ⇔ accepted by the other.
TEST(ConfigFieldsTest, ReaderAndValidateAgreeOnBoundaries) {
  struct Case {
    const char* yaml;
    bool valid;
  };
  for (const Case& k : {Case{"x: {speed_mps: 3}", true}, Case{"x: {speed_mps: 0}", false},
                        Case{"x: {window: 1}", true}, Case{"x: {window: 0}", false}, Case{"x: {score: 0}", true},
                        Case{"x: {score: 1}", false}}) {
    auto r = ConfigReader::fromString(k.yaml, "t.yaml", ConfigReader::MissingKeys::kUseDefaults);
    Demo d;
    demoFields().readFields(r, "x.", d);
    EXPECT_EQ(r.ok(), k.valid) << k.yaml << "\n" << r.errorReport();
    // The same value set in code.
    Demo coded;
    const YAML::Node n = YAML::Load(k.yaml)["x"];
    for (const auto& kv : n) {
      const std::string key = kv.first.Scalar();
      if (key == "speed_mps") coded.speed_mps = kv.second.as<double>();
      if (key == "window") coded.window = kv.second.as<int>();
      if (key == "score") coded.score = kv.second.as<float>();
    }
    EXPECT_EQ(demoFields().rangeProblems(coded).empty(), k.valid) << k.yaml;
    if (!k.valid) {
      EXPECT_EQ(r.problems().front().key.rfind("x.", 0), 0u);
    }
  }
  EXPECT_NE(demoFields().rangeOf("window"), nullptr);
  EXPECT_EQ(demoFields().rangeOf("nope"), nullptr);
}

TEST(ConfigFieldsTest, ProblemsSortInTableOrder) {
  std::vector<ConfigError> e{{"other", "x"}, {"score", "y"}, {"speed_mps", "z"}, {"window", "w"}};
  demoFields().sortByTableOrder(e);
  ASSERT_EQ(e.size(), 4u);
  EXPECT_EQ(e[0].key, "speed_mps");
  EXPECT_EQ(e[1].key, "window");
  EXPECT_EQ(e[2].key, "score");
  EXPECT_EQ(e[3].key, "other");
}

TEST(ConfigFieldsTest, AddProblemsPrefixesKeysAndRulesReportTheValue) {
  std::vector<ConfigError> e;
  checkRule(e, true, "a", 1.0, "must be < b");
  checkRule(e, false, "a", 4.0, "must be < b");
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].message, "must be < b, got 4");
  auto r = ConfigReader::fromString("{}", "t.yaml", ConfigReader::MissingKeys::kUseDefaults);
  addProblems(r, "sec.", e);
  ASSERT_EQ(r.problems().size(), 1u);
  EXPECT_EQ(r.problems()[0].key, "sec.a");
}

}  // namespace
}  // namespace gesture_formation::common

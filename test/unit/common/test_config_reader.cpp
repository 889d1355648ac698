#include <gtest/gtest.h>

#include "gesture_formation/common/config_reader.hpp"

using gesture_formation::common::ConfigReader;
using gesture_formation::common::Range;

namespace {

bool contains(const std::vector<std::string>& v, const std::string& needle) {
  for (const auto& s : v) {
    if (s.find(needle) != std::string::npos) return true;
  }
  return false;
}

}  // namespace

TEST(ConfigReaderTest, DefaultsModeKeepsDefaultsForMissingKeys) {
  auto r = ConfigReader::fromString("a: {b: 2.5}", "cfg.yaml", ConfigReader::MissingKeys::kUseDefaults);
  double b = 1.0, c = 7.0;
  r.readDouble("a.b", b, Range::positive());
  r.readDouble("a.c", c, Range::positive());
  EXPECT_TRUE(r.ok()) << r.errorReport();
  EXPECT_DOUBLE_EQ(b, 2.5);
  EXPECT_DOUBLE_EQ(c, 7.0);
}

TEST(ConfigReaderTest, StrictModeListsEveryMissingAndBadKeyAtOnce) {
  auto r = ConfigReader::fromString("a: {b: -1, d: abc}\nlist: [1, 2]", "cfg.yaml", ConfigReader::MissingKeys::kError);
  double b = 1.0, c = 1.0, d = 1.0;
  std::vector<double> list{0, 0, 0};
  int e = 3;
  r.readDouble("a.b", b, Range::positive());
  r.readDouble("a.c", c, Range::positive());
  r.readDouble("a.d", d, Range::any());
  r.readDoubleList("list", list, 3, 3, Range::any());
  r.readInt("e", e, Range::atLeast(1));
  const auto& errs = r.errors();
  ASSERT_EQ(errs.size(), 5u) << r.errorReport();
  EXPECT_TRUE(contains(errs, "cfg.yaml: a.b: value -1 is out of range (0, inf)"));
  EXPECT_TRUE(contains(errs, "cfg.yaml: a.c: missing"));
  EXPECT_TRUE(contains(errs, "a.d: expected a number, got 'abc'"));
  EXPECT_TRUE(contains(errs, "list: expected 3 numbers, got 2"));
  EXPECT_TRUE(contains(errs, "cfg.yaml: e: missing"));
  // Bad values leave the caller's defaults untouched.
  EXPECT_DOUBLE_EQ(b, 1.0);
  EXPECT_DOUBLE_EQ(d, 1.0);
  EXPECT_EQ(list.size(), 3u);
}

TEST(ConfigReaderTest, IntegersAndBoolsAndStringsAreChecked) {
  auto r = ConfigReader::fromString("n: 2.5\nm: 4\nflag: maybe\nmode: fast\nok: true", "x",
                                    ConfigReader::MissingKeys::kError);
  int n = 0, m = 0;
  bool flag = false, okv = false;
  std::string mode = "slow";
  r.readInt("n", n, Range::any());
  r.readInt("m", m, Range::closed(0, 3));
  r.readBool("flag", flag);
  r.readBool("ok", okv);
  r.readString("mode", mode, {"slow", "medium"});
  EXPECT_EQ(r.errors().size(), 4u) << r.errorReport();
  EXPECT_TRUE(contains(r.errors(), "n: expected an integer, got '2.5'"));
  EXPECT_TRUE(contains(r.errors(), "m: value 4 is out of range [0, 3]"));
  EXPECT_TRUE(contains(r.errors(), "flag: expected true or false"));
  EXPECT_TRUE(contains(r.errors(), "mode: value 'fast' is not one of slow|medium"));
  EXPECT_TRUE(okv);
  EXPECT_EQ(mode, "slow");
}

TEST(ConfigReaderTest, ListIndicesInKeys) {
  auto r = ConfigReader::fromString("followers: [{d: 8}, {d: 9}]", "x", ConfigReader::MissingKeys::kError);
  double d1 = 0;
  r.readDouble("followers[1].d", d1, Range::positive());
  EXPECT_TRUE(r.ok()) << r.errorReport();
  EXPECT_DOUBLE_EQ(d1, 9.0);
  double d2 = 0;
  r.readDouble("followers[2].d", d2, Range::positive());
  EXPECT_TRUE(contains(r.errors(), "followers[2].d: missing"));
}

TEST(ConfigReaderTest, NanAndInfAreOutOfAnyRange) {
  auto r = ConfigReader::fromString("a: .nan\nb: .inf", "x", ConfigReader::MissingKeys::kError);
  double a = 1, b = 1;
  r.readDouble("a", a, Range::any());
  r.readDouble("b", b, Range::any());
  EXPECT_EQ(r.errors().size(), 2u) << r.errorReport();
  EXPECT_DOUBLE_EQ(a, 1.0);
}

TEST(ConfigReaderTest, UnusedKeysUnderReadSectionsAreReported) {
  auto r = ConfigReader::fromString("noise: {sigma_p_m: 1, sigma_p: 2}\nother_component: {x: 1}", "x",
                                    ConfigReader::MissingKeys::kUseDefaults);
  double s = 0;
  r.readDouble("noise.sigma_p_m", s, Range::positive());
  const auto unused = r.unusedKeys();
  ASSERT_EQ(unused.size(), 1u);
  EXPECT_EQ(unused[0], "noise.sigma_p");
}

TEST(ConfigReaderTest, SyntaxErrorAndMissingFileAreReported) {
  auto r = ConfigReader::fromString("a: [1, 2", "bad.yaml", ConfigReader::MissingKeys::kError);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(contains(r.errors(), "bad.yaml:"));
  double a = 0;
  r.readDouble("a", a, Range::any());
  EXPECT_EQ(r.errors().size(), 1u) << "a parse failure must not add a 'missing' line per key";
  auto f = ConfigReader::fromFile("/nonexistent/x.yaml", ConfigReader::MissingKeys::kError);
  EXPECT_TRUE(contains(f.errors(), "/nonexistent/x.yaml: cannot open file"));
}

// Found by fuzz_config: a mapping used as a key made unusedKeys() throw (YAML bad conversion).
TEST(ConfigReaderTest, NonScalarKeysAreReportedNotThrown) {
  auto r = ConfigReader::fromString("a:\n  b: 2.5\n  ? {x: 1}\n  : 3\n  [1, 2]: 4\n", "cfg.yaml", ConfigReader::MissingKeys::kError);
  double b = 0.0;
  r.readDouble("a.b", b, Range::positive());
  EXPECT_TRUE(r.ok()) << r.errorReport();
  EXPECT_DOUBLE_EQ(b, 2.5);
  std::vector<std::string> unused;
  ASSERT_NO_THROW(unused = r.unusedKeys());
  EXPECT_EQ(unused.size(), 2u);
  EXPECT_TRUE(contains(unused, "a.<non-scalar key>"));
}

TEST(ConfigReaderTest, ProblemsAreTypedAndSubReadersRenameTheirKeys) {
  ConfigReader r = ConfigReader::fromString("mission:\n  planner:\n    speed: -1\n    typo_key: 2\n  x: 1\n", "m.yaml",
                                            ConfigReader::MissingKeys::kUseDefaults);
  double x = 0.0;
  r.readDouble("mission.x", x, Range::closed(2.0, 3.0));
  gesture_formation::common::withSubReader(r, "mission.planner", ConfigReader::MissingKeys::kUseDefaults,
                                           [](ConfigReader& s) {
                                             double speed = 1.0;
                                             s.readDouble("speed", speed, Range::positive());
                                           });
  ASSERT_EQ(r.problems().size(), 3u) << r.errorReport();
  EXPECT_EQ(r.problems()[0].key, "mission.x");
  EXPECT_NE(r.problems()[0].message.find("value 1 is out of range"), std::string::npos);
  EXPECT_EQ(r.problems()[1].key, "mission.planner.speed");
  EXPECT_EQ(r.problems()[2].key, "mission.planner.typo_key");
  EXPECT_EQ(r.problems()[2].message, "unknown key");
  EXPECT_EQ(r.errors()[1], "m.yaml: mission.planner.speed: " + r.problems()[1].message);
  // A document-level problem has no key.
  ConfigReader bad = ConfigReader::fromString("a: [1, 2", "b.yaml", ConfigReader::MissingKeys::kUseDefaults);
  ASSERT_EQ(bad.problems().size(), 1u);
  EXPECT_TRUE(bad.problems()[0].key.empty());
  EXPECT_NE(bad.errors()[0].find("b.yaml: line "), std::string::npos) << bad.errors()[0];
}

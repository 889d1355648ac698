#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "gesture_formation/formation/formation_config.hpp"

using namespace gesture_formation::formation;
using gesture_formation::common::ConfigReader;

namespace {

FormationConfig read(const std::string& yaml, ConfigReader::MissingKeys mode, std::string* errors) {
  ConfigReader r = ConfigReader::fromString(yaml, "test.yaml", mode);
  FormationConfig c = readFormationConfig(r);
  *errors = r.errorReport();
  return c;
}

}  // namespace

TEST(FormationConfigTest, EmptyFileGivesTableII) {
  std::string errors;
  const FormationConfig c = read("{}", ConfigReader::MissingKeys::kUseDefaults, &errors);
  EXPECT_EQ(errors, "");
  EXPECT_EQ(c.params.leader.beta_deg, 90.0);
  EXPECT_EQ(c.params.leader.gamma_deg, 11.0);
  EXPECT_EQ(c.params.leader.distance_m, 10.0);
  ASSERT_EQ(c.params.followers.size(), 2u);
  EXPECT_EQ(c.params.followers[0].beta_deg, 60.0);
  EXPECT_EQ(c.params.followers[1].beta_deg, -60.0);
  EXPECT_EQ(c.params.followers[1].distance_m, 8.0);
  EXPECT_EQ(c.limits.safety_distance_m, 2.5);
  EXPECT_EQ(c.worker_heading.mode, WorkerHeadingMode::kConstant);
}

TEST(FormationConfigTest, AnyNumberOfFollowers) {
  std::string errors;
  const FormationConfig c = read(
      "followers: [{beta_deg: 72}, {beta_deg: 144}, {beta_deg: -144, gamma_deg: 5}, {beta_deg: -72, distance_m: 12}, "
      "{beta_deg: 0, distance_m: 20}]",
      ConfigReader::MissingKeys::kUseDefaults, &errors);
  EXPECT_EQ(errors, "");
  ASSERT_EQ(c.params.followers.size(), 5u);
  EXPECT_EQ(c.params.followers[2].gamma_deg, 5.0);
  EXPECT_EQ(c.params.followers[3].distance_m, 12.0);
  EXPECT_EQ(c.params.followers[4].distance_m, 20.0);
  EXPECT_EQ(read("followers: []", ConfigReader::MissingKeys::kUseDefaults, &errors).params.followers.size(), 0u);
  EXPECT_EQ(errors, "");
}

TEST(FormationConfigTest, ThirdFollowerNeedsBeta) {
  std::string errors;
  read("followers: [{}, {}, {gamma_deg: 1}]", ConfigReader::MissingKeys::kUseDefaults, &errors);
  EXPECT_NE(errors.find("followers[2].beta_deg: missing"), std::string::npos) << errors;
}

TEST(FormationConfigTest, OutOfLimitValuesAreErrorsListedTogether) {
  std::string errors;
  read("leader: {gamma_deg: 70, distance_m: 1}\nfollowers: [{distance_m: 40}, {beta_deg: 270}]\n"
       "limits: {distance_min_m: 2}\nworker_heading: {mode: sideways}\n",
       ConfigReader::MissingKeys::kUseDefaults, &errors);
  for (const char* key : {"leader.gamma_deg", "leader.distance_m", "followers[0].distance_m", "followers[1].beta_deg",
                          "limits.distance_min_m", "worker_heading.mode"}) {
    EXPECT_NE(errors.find(key), std::string::npos) << key << " not in:\n" << errors;
  }
}

TEST(FormationConfigTest, FollowerElevationIsCheckedAgainstLeaderGamma) {
  std::string errors;
  read("leader: {gamma_deg: 40}\nfollowers: [{gamma_deg: 25}]\n", ConfigReader::MissingKeys::kUseDefaults, &errors);
  EXPECT_NE(errors.find("followers[0].gamma_deg"), std::string::npos) << errors;
  EXPECT_NE(errors.find("= 65"), std::string::npos) << errors;
}

TEST(FormationConfigTest, ErrorModeRequiresEveryKey) {
  std::string errors;
  read("leader: {beta_deg: 90}", ConfigReader::MissingKeys::kError, &errors);
  for (const char* key : {"leader.gamma_deg", "followers", "limits.safety_distance_m", "worker_heading.mode"}) {
    EXPECT_NE(errors.find(key), std::string::npos) << key << " not in:\n" << errors;
  }
}

TEST(FormationConfigTest, ShippedConfigHasEveryKey) {
  std::vector<std::string> warnings;
  const auto c = loadFormationConfig(std::string(GF_SOURCE_DIR) + "/config/formation.yaml",
                                     ConfigReader::MissingKeys::kError, &warnings);
  ASSERT_TRUE(c) << c.reason();
  EXPECT_TRUE(warnings.empty()) << warnings[0];
  EXPECT_EQ(c->params.followers.size(), 2u);
  EXPECT_EQ(c->params.leader.gamma_deg, 11.0);
}

// Issue 34: a rule between keys (distance_min_m >= safety_distance_m) is reported beside a key
// already out of range, both naming key and value; typed, not re-parsed from text.
TEST(FormationConfigTest, YamlReportsTheRuleBesideAnOutOfRangeKey) {
  ConfigReader r = ConfigReader::fromString("limits: {gamma_min_deg: -95, safety_distance_m: 4.5}\n",
                                            "f.yaml", ConfigReader::MissingKeys::kUseDefaults);
  readFormationConfig(r);
  std::vector<std::string> keys;
  for (const auto& p : r.problems()) keys.push_back(p.key);
  ASSERT_EQ(keys.size(), 2u) << r.errorReport();
  EXPECT_EQ(keys[0], "limits.gamma_min_deg");
  EXPECT_EQ(keys[1], "limits.distance_min_m");
  EXPECT_NE(r.problems()[1].message.find("4.5"), std::string::npos) << r.problems()[1].message;
}

// One range per key: the YAML reader and validate() accept and refuse the same boundary values
// (β: (−180, 180] in both; validate() used to accept any finite β).
TEST(FormationConfigTest, ValidateAndYamlAgreeOnBoundaries) {
  struct Case {
    double beta_deg;
    bool valid;
  };
  for (const Case& k : {Case{180.0, true}, Case{-179.5, true}, Case{-180.0, false}, Case{270.0, false}}) {
    std::string errors;
    read("followers: [{beta_deg: " + std::to_string(k.beta_deg) + "}, {beta_deg: -60}]\n",
         ConfigReader::MissingKeys::kUseDefaults, &errors);
    EXPECT_EQ(errors.empty(), k.valid) << k.beta_deg << ": " << errors;
    FormationConfig c;
    c.params.followers[0].beta_deg = k.beta_deg;
    EXPECT_EQ(c.validate().empty(), k.valid) << k.beta_deg;
  }
}

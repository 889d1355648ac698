#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "gesture_formation/estimation/estimator_config.hpp"

using namespace gesture_formation;
using common::ConfigReader;

namespace {
std::string writeTemp(const std::string& name, const std::string& content) {
  const std::string path = ::testing::TempDir() + name;
  std::ofstream(path) << content;
  return path;
}
}  // namespace

TEST(EstimatorConfigTest, ShippedConfigLoadsInStrictMode) {
  std::vector<std::string> warnings;
  const auto c = estimation::loadEstimatorConfig(std::string(GF_SOURCE_DIR) + "/config/estimator.yaml",
                                                 ConfigReader::MissingKeys::kError, &warnings);
  ASSERT_TRUE(c) << c.reason();
  EXPECT_TRUE(warnings.empty());
  EXPECT_DOUBLE_EQ(c->camera.fx, 615.0);
  EXPECT_EQ(c->camera.width_px, 640);
  EXPECT_DOUBLE_EQ(c->noise.sigma_z_stereo_m, 0.3);
  EXPECT_DOUBLE_EQ(c->filter.gate_chi2, 16.27);
}

TEST(EstimatorConfigTest, PartialConfigTakesDefaultsInGfctlMode) {
  const auto path = writeTemp("est_partial.yaml", "process_noise: {sigma_p_m: 0.2}\ncamera: {cx: 640, cy: 360}\n");
  const auto c = estimation::loadEstimatorConfig(path, ConfigReader::MissingKeys::kUseDefaults);
  ASSERT_TRUE(c) << c.reason();
  EXPECT_DOUBLE_EQ(c->filter.sigma_p_m, 0.2);
  EXPECT_DOUBLE_EQ(c->filter.sigma_v_mps, 0.1);
  EXPECT_EQ(c->camera.width_px, 1280) << "image size defaults to twice the principal point";
  EXPECT_EQ(c->camera.height_px, 720);
  EXPECT_DOUBLE_EQ(c->human_height_m, 1.75);
}

TEST(EstimatorConfigTest, EveryProblemListedAtOnce) {
  const auto path = writeTemp("est_bad.yaml",
                              "camera: {fx: -615, distortion: [0, 0, 0]}\nhuman_height_m: 7\n"
                              "process_noise: {sigma_p_m: 0}\nmeasurement_noise: {sigma_xy_m: nan}\n"
                              "max_consecutive_rejections: 0\nconfirm_measurements: 0\nstereo: {min_depth_m: 5, max_depth_m: 4}\n");
  const auto c = estimation::loadEstimatorConfig(path, ConfigReader::MissingKeys::kUseDefaults);
  ASSERT_FALSE(c);
  for (const char* key : {"camera.fx", "camera.distortion", "human_height_m", "process_noise.sigma_p_m",
                          "measurement_noise.sigma_xy_m", "max_consecutive_rejections", "confirm_measurements",
                          "stereo.max_depth_m"}) {
    EXPECT_NE(c.reason().find(key), std::string::npos) << key << " not named in:\n" << c.reason();
  }
}

TEST(EstimatorConfigTest, StrictModeListsMissingKeys) {
  const auto path = writeTemp("est_missing.yaml", "human_height_m: 1.8\n");
  const auto c = estimation::loadEstimatorConfig(path, ConfigReader::MissingKeys::kError);
  ASSERT_FALSE(c);
  for (const char* key : {"camera.fx", "camera.width", "process_noise.sigma_v_mps", "gate_chi2", "lost_timeout_s"}) {
    EXPECT_NE(c.reason().find(std::string(key) + ": missing"), std::string::npos) << key << "\n" << c.reason();
  }
}

TEST(EstimatorConfigTest, TypoIsWarned) {
  const auto path = writeTemp("est_typo.yaml", "process_noise: {sigma_p: 0.3}\n");
  std::vector<std::string> warnings;
  const auto c = estimation::loadEstimatorConfig(path, ConfigReader::MissingKeys::kUseDefaults, &warnings);
  ASSERT_TRUE(c);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("process_noise.sigma_p"), std::string::npos);
}

TEST(EstimatorConfigTest, RosCameraInfoYaml) {
  const auto info = writeTemp("camera_info.yaml",
                              "image_width: 1280\nimage_height: 720\ncamera_name: d435\n"
                              "camera_matrix: {rows: 3, cols: 3, data: [910.1, 0, 641.2, 0, 909.7, 362.5, 0, 0, 1]}\n"
                              "distortion_model: plumb_bob\n"
                              "distortion_coefficients: {rows: 1, cols: 5, data: [0.1, -0.2, 0.001, 0.002, 0.05]}\n"
                              "rectification_matrix: {rows: 3, cols: 3, data: [1, 0, 0, 0, 1, 0, 0, 0, 1]}\n"
                              "projection_matrix: {rows: 3, cols: 4, data: [910.1, 0, 641.2, 0, 0, 909.7, 362.5, 0, 0, 0, 1, 0]}\n");
  const auto k = estimation::loadCameraInfoYaml(info);
  ASSERT_TRUE(k) << k.reason();
  EXPECT_DOUBLE_EQ(k->fx, 910.1);
  EXPECT_DOUBLE_EQ(k->cy, 362.5);
  EXPECT_EQ(k->width_px, 1280);
  EXPECT_DOUBLE_EQ(k->distortion[4], 0.05);
  const auto cfg_path = writeTemp("est_with_info.yaml", "camera_info_file: " + info + "\n");
  const auto c = estimation::loadEstimatorConfig(cfg_path, ConfigReader::MissingKeys::kUseDefaults);
  ASSERT_TRUE(c) << c.reason();
  EXPECT_DOUBLE_EQ(c->camera.fx, 910.1);
  const auto bad = writeTemp("bad_info.yaml", "image_width: 0\ncamera_matrix: {data: [1, 2]}\n");
  const auto kb = estimation::loadCameraInfoYaml(bad);
  ASSERT_FALSE(kb);
  EXPECT_NE(kb.reason().find("image_width"), std::string::npos);
  EXPECT_NE(kb.reason().find("camera_matrix.data"), std::string::npos);
  EXPECT_NE(kb.reason().find("image_height: missing"), std::string::npos);
}

// Issue 34: the rule between keys (stereo.max_depth_m > stereo.min_depth_m) is reported beside a
// key already out of range, each naming key and value.
TEST(EstimatorConfigTest, YamlReportsTheRuleBesideAnOutOfRangeKey) {
  ConfigReader r = ConfigReader::fromString("gate_chi2: -1\nstereo: {min_depth_m: 5, max_depth_m: 4}\n", "e.yaml",
                                            ConfigReader::MissingKeys::kUseDefaults);
  estimation::readEstimatorConfig(r);
  ASSERT_EQ(r.problems().size(), 2u) << r.errorReport();
  EXPECT_EQ(r.problems()[0].key, "gate_chi2");
  EXPECT_EQ(r.problems()[1].key, "stereo.max_depth_m");
  EXPECT_NE(r.problems()[1].message.find("got 4"), std::string::npos) << r.problems()[1].message;
}

// One range per key: the YAML reader and validate() accept and refuse the same boundary values
// (stereo.depth_scale_m: [1e-6, 1], as the Perception nodelet had it; the estimator had (0, inf)).
TEST(EstimatorConfigTest, ValidateAndYamlAgreeOnBoundaries) {
  struct Case {
    const char* text;
    bool valid;
  };
  for (const Case& k : {Case{"1", true}, Case{"1e-6", true}, Case{"1.5", false}, Case{"1e-7", false}}) {
    const std::string yaml = std::string("stereo: {depth_scale_m: ") + k.text + "}\n";
    ConfigReader r = ConfigReader::fromString(yaml, "e.yaml", ConfigReader::MissingKeys::kUseDefaults);
    estimation::readEstimatorConfig(r);
    EXPECT_EQ(r.ok(), k.valid) << yaml << r.errorReport();
    estimation::EstimatorConfig c;
    c.stereo.depth_scale_m = std::stod(k.text);
    EXPECT_EQ(c.validate().empty(), k.valid) << yaml;
  }
}

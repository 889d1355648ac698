#include "gesture_formation/estimation/estimator_config.hpp"

#include <cmath>

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::estimation {

using common::ConfigReader;
using common::Range;

namespace {

/// EstimatorConfig's own numbers (the camera's, filter's and stereo's have their own tables):
/// key, range — the only place it is written — and place.
const common::FieldTable<EstimatorConfig>& fields() {
  using C = EstimatorConfig;
  static const common::FieldTable<EstimatorConfig> t{{
      {"human_height_m", Range::openClosed(0.5, 2.5), [](C& c) { return &c.human_height_m; }},
      {"max_apparent_distance_m", Range::openClosed(0.0, 1000.0), [](C& c) { return &c.max_apparent_distance_m; }},
      {"measurement_noise.sigma_xy_m", Range::positive(), [](C& c) { return &c.noise.sigma_xy_m; }},
      {"measurement_noise.sigma_z_uwb_m", Range::positive(), [](C& c) { return &c.noise.sigma_z_uwb_m; }},
      {"measurement_noise.sigma_z_stereo_m", Range::positive(), [](C& c) { return &c.noise.sigma_z_stereo_m; }},
      {"measurement_noise.sigma_z_apparent_m", Range::positive(), [](C& c) { return &c.noise.sigma_z_apparent_m; }},
  }};
  return t;
}

/// Every problem of `c` but the camera's: each field outside its range, the rules between fields.
std::vector<common::ConfigError> ownProblems(const EstimatorConfig& c) {
  std::vector<common::ConfigError> e = fields().rangeProblems(c);
  for (auto& p : humanKalmanFields().rangeProblems(c.filter)) e.push_back(p);
  for (auto& p : stereoDistanceProblems(c.stereo)) e.push_back({"stereo." + p.key, p.message});
  return e;
}

}  // namespace

std::vector<std::string> EstimatorConfig::validate() const {
  std::vector<std::string> e = camera.validate();
  for (auto& line : common::problemLines(ownProblems(*this))) e.push_back(line);
  return e;
}

namespace {

void readCameraInfoNode(ConfigReader& r, CameraIntrinsics& k) {
  r.readInt("image_width", k.width_px, Range::atLeast(1));
  r.readInt("image_height", k.height_px, Range::atLeast(1));
  std::vector<double> K;
  r.readDoubleList("camera_matrix.data", K, 9, 9, Range::any());
  if (K.size() == 9) {
    if (!(K[0] > 0) || !(K[4] > 0)) r.addError("camera_matrix.data", "fx and fy (elements 0 and 4) must be > 0");
    k.fx = K[0];
    k.fy = K[4];
    k.cx = K[2];
    k.cy = K[5];
  }
  std::string model = "plumb_bob";
  r.readString("distortion_model", model, {"plumb_bob", "rational_polynomial"});
  std::vector<double> D;
  r.readDoubleList("distortion_coefficients.data", D, 5, 8, Range::any());
  if (model == "rational_polynomial" && D.size() == 8 && (D[5] != 0 || D[6] != 0 || D[7] != 0)) {
    r.addError("distortion_model", "rational_polynomial with non-zero k4..k6 is not supported (plumb_bob only)");
  }
  for (std::size_t i = 0; i < 5 && i < D.size(); ++i) k.distortion[i] = D[i];
}

}  // namespace

common::Result<CameraIntrinsics> loadCameraInfoYaml(const std::string& path) {
  ConfigReader r = ConfigReader::fromFile(path, ConfigReader::MissingKeys::kError);
  CameraIntrinsics k;
  readCameraInfoNode(r, k);
  if (!r.ok()) return common::Result<CameraIntrinsics>::fail(r.errorReport());
  return common::Result<CameraIntrinsics>::ok(k);
}

EstimatorConfig readEstimatorConfig(ConfigReader& r) {
  EstimatorConfig c;
  if (r.has("camera_info_file")) {
    std::string file;
    r.readString("camera_info_file", file);
    const auto k = loadCameraInfoYaml(file);
    if (k) {
      c.camera = *k;
    } else {
      r.addError("camera_info_file", "cannot load '" + file + "': " + k.reason());
    }
  } else {
    for (const char* key : {"camera.fx", "camera.fy", "camera.cx", "camera.cy"}) {
      cameraIntrinsicsFields().readField(r, "", c.camera, key);
    }
    std::vector<double> d(c.camera.distortion.begin(), c.camera.distortion.end());
    r.readDoubleList("camera.distortion", d, 5, 5, Range::any());
    for (std::size_t i = 0; i < 5; ++i) c.camera.distortion[i] = d[i];
    // Image size: docs/design.md §8.1 does not list it; absent → the principal point is the centre.
    c.camera.width_px = static_cast<int>(std::lround(2.0 * c.camera.cx));
    c.camera.height_px = static_cast<int>(std::lround(2.0 * c.camera.cy));
    if (r.has("camera.width") || r.mode() == ConfigReader::MissingKeys::kError) {
      cameraIntrinsicsFields().readField(r, "", c.camera, "camera.width");
    }
    if (r.has("camera.height") || r.mode() == ConfigReader::MissingKeys::kError) {
      cameraIntrinsicsFields().readField(r, "", c.camera, "camera.height");
    }
  }
  fields().readFields(r, "", c);
  humanKalmanFields().readFields(r, "", c.filter);
  stereoDistanceFields().readFields(r, "stereo.", c.stereo);
  // The rules between fields, always (a key outside its range kept its default while reading):
  // the image size derived from the principal point, the stereo depth interval.
  common::addProblems(r, "", cameraIntrinsicsFields().rangeProblems(c.camera));
  common::addProblems(r, "", ownProblems(c));
  return c;
}

common::Result<EstimatorConfig> loadEstimatorConfig(const std::string& path, ConfigReader::MissingKeys mode,
                                                    std::vector<std::string>* warnings) {
  ConfigReader r = ConfigReader::fromFile(path, mode);
  const EstimatorConfig c = readEstimatorConfig(r);
  if (warnings) {
    for (const auto& k : r.unusedKeysOfWholeDocument()) warnings->push_back(path + ": unknown key '" + k + "' ignored");
  }
  if (!r.ok()) return common::Result<EstimatorConfig>::fail(r.errorReport());
  return common::Result<EstimatorConfig>::ok(c);
}

}  // namespace gesture_formation::estimation

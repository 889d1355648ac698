#include "gesture_formation/estimation/estimator_config.hpp"

#include <cmath>

namespace gesture_formation::estimation {

using common::ConfigReader;
using common::Range;

std::vector<std::string> EstimatorConfig::validate() const {
  std::vector<std::string> e = camera.validate();
  if (!(human_height_m > 0.5 && human_height_m <= 2.5)) {
    e.push_back("human_height_m must be in (0.5, 2.5], got " + std::to_string(human_height_m));
  }
  const double s[] = {noise.sigma_xy_m, noise.sigma_z_uwb_m, noise.sigma_z_stereo_m, noise.sigma_z_apparent_m};
  const char* names[] = {"measurement_noise.sigma_xy_m", "measurement_noise.sigma_z_uwb_m",
                         "measurement_noise.sigma_z_stereo_m", "measurement_noise.sigma_z_apparent_m"};
  for (int i = 0; i < 4; ++i) {
    if (!(std::isfinite(s[i]) && s[i] > 0)) e.push_back(std::string(names[i]) + " must be > 0, got " + std::to_string(s[i]));
  }
  for (auto& f : filter.validate()) e.push_back(f);
  if (!(stereo.max_depth_m > stereo.min_depth_m)) {
    e.push_back("stereo.max_depth_m must be > stereo.min_depth_m, got " + std::to_string(stereo.max_depth_m));
  }
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
    r.readDouble("camera.fx", c.camera.fx, Range::positive());
    r.readDouble("camera.fy", c.camera.fy, Range::positive());
    r.readDouble("camera.cx", c.camera.cx, Range::any());
    r.readDouble("camera.cy", c.camera.cy, Range::any());
    std::vector<double> d(c.camera.distortion.begin(), c.camera.distortion.end());
    r.readDoubleList("camera.distortion", d, 5, 5, Range::any());
    for (std::size_t i = 0; i < 5; ++i) c.camera.distortion[i] = d[i];
    // Image size: docs/design.md §8.1 does not list it; absent → the principal point is the centre.
    c.camera.width_px = static_cast<int>(std::lround(2.0 * c.camera.cx));
    c.camera.height_px = static_cast<int>(std::lround(2.0 * c.camera.cy));
    if (r.has("camera.width") || r.mode() == ConfigReader::MissingKeys::kError) {
      r.readInt("camera.width", c.camera.width_px, Range::atLeast(1));
    }
    if (r.has("camera.height") || r.mode() == ConfigReader::MissingKeys::kError) {
      r.readInt("camera.height", c.camera.height_px, Range::atLeast(1));
    }
  }
  r.readDouble("human_height_m", c.human_height_m, Range::openClosed(0.5, 2.5));
  r.readDouble("process_noise.sigma_p_m", c.filter.sigma_p_m, Range::positive());
  r.readDouble("process_noise.sigma_v_mps", c.filter.sigma_v_mps, Range::positive());
  r.readDouble("measurement_noise.sigma_xy_m", c.noise.sigma_xy_m, Range::positive());
  r.readDouble("measurement_noise.sigma_z_uwb_m", c.noise.sigma_z_uwb_m, Range::positive());
  r.readDouble("measurement_noise.sigma_z_stereo_m", c.noise.sigma_z_stereo_m, Range::positive());
  r.readDouble("measurement_noise.sigma_z_apparent_m", c.noise.sigma_z_apparent_m, Range::positive());
  r.readDouble("initial_velocity_std_mps", c.filter.initial_velocity_std_mps, Range::positive());
  r.readDouble("gate_chi2", c.filter.gate_chi2, Range::positive());
  r.readInt("max_consecutive_rejections", c.filter.max_consecutive_rejections, Range::atLeast(1));
  r.readDouble("lost_timeout_s", c.filter.lost_timeout_s, Range::positive());
  r.readInt("confirm_measurements", c.filter.confirm_measurements, Range::atLeast(1));
  r.readDouble("stereo.min_depth_m", c.stereo.min_depth_m, Range::nonNegative());
  r.readDouble("stereo.max_depth_m", c.stereo.max_depth_m, Range::positive());
  r.readInt("stereo.min_valid_pixels", c.stereo.min_valid_pixels, Range::atLeast(1));
  r.readDouble("stereo.min_valid_fraction", c.stereo.min_valid_fraction, Range::closed(0.0, 1.0));
  r.readDouble("stereo.depth_scale_m", c.stereo.depth_scale_m, Range::positive());
  for (const auto& e : c.validate()) {
    // Range checks above already caught single-key problems; add cross-field ones only.
    if (e.rfind("stereo.max_depth_m", 0) == 0 || e.rfind("camera.width", 0) == 0 || e.rfind("camera.height", 0) == 0) {
      r.addError(e.substr(0, e.find(' ')), e.substr(e.find(' ') + 1));
    }
  }
  return c;
}

common::Result<EstimatorConfig> loadEstimatorConfig(const std::string& path, ConfigReader::MissingKeys mode,
                                                    std::vector<std::string>* warnings) {
  ConfigReader r = ConfigReader::fromFile(path, mode);
  const EstimatorConfig c = readEstimatorConfig(r);
  if (warnings) {
    for (const auto& k : r.unusedKeys()) warnings->push_back(path + ": unknown key '" + k + "' ignored");
  }
  if (!r.ok()) return common::Result<EstimatorConfig>::fail(r.errorReport());
  return common::Result<EstimatorConfig>::ok(c);
}

}  // namespace gesture_formation::estimation

#pragma once
/// \file
/// \brief Configuration of the worker position estimator, as read by `gfctl estimate` and
/// the WorkerEstimator nodelet (keys: docs/design.md §8.1, config/estimator.yaml).

#include <string>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/result.hpp"
#include "gesture_formation/estimation/camera_model.hpp"
#include "gesture_formation/estimation/human_kalman.hpp"
#include "gesture_formation/estimation/measurement_model.hpp"
#include "gesture_formation/estimation/stereo_distance.hpp"

namespace gesture_formation::estimation {

/// \brief Everything the estimator needs. Defaults: Table II and a D435 colour camera.
struct EstimatorConfig {
  CameraIntrinsics camera;
  double human_height_m = 1.75;  ///< the worker's height for the apparent distance, (0.5, 2.5] m
  /// Longest apparent distance taken [m], (0, 1000]: a smaller box (a far or partial person, a
  /// spurious detection) gives no distance — a 1 px box would put the worker a kilometre away.
  double max_apparent_distance_m = 40.0;
  MeasurementNoise noise;
  HumanKalmanConfig filter;
  StereoDistanceConfig stereo;

  /// Every problem, each naming the key; empty when valid.
  std::vector<std::string> validate() const;
};

/// \brief Reads an EstimatorConfig from `reader`, starting from the defaults above.
/// Keys: `camera.{fx,fy,cx,cy,distortion,width,height}`, `human_height_m`, `max_apparent_distance_m`,
/// `process_noise.{sigma_p_m,sigma_v_mps,reference_period_s}`,
/// `measurement_noise.{sigma_xy_m,sigma_z_uwb_m,sigma_z_stereo_m,sigma_z_apparent_m}`,
/// `initial_velocity_std_mps`, `gate_chi2`, `max_consecutive_rejections`, `lost_timeout_s`,
/// `confirm_measurements`,
/// `stereo.{min_depth_m,max_depth_m,min_valid_pixels,min_valid_fraction,depth_scale_m}`.
/// `camera` may instead be a ROS camera_info YAML (image_width, camera_matrix, ...) given by
/// `camera_info_file`. When `camera.width/height` are absent they default to 2·cx, 2·cy.
/// Problems are recorded in the reader (all of them).
EstimatorConfig readEstimatorConfig(common::ConfigReader& reader);

/// \brief Reads camera intrinsics from a ROS camera_info YAML file (as written by
/// camera_calibration: image_width, image_height, camera_matrix.data[9],
/// distortion_model plumb_bob, distortion_coefficients.data[5]).
common::Result<CameraIntrinsics> loadCameraInfoYaml(const std::string& path);

/// \brief Loads and validates a config file. On failure the reason lists every problem,
/// one per line. `mode`: see ConfigReader.
common::Result<EstimatorConfig> loadEstimatorConfig(const std::string& path, common::ConfigReader::MissingKeys mode,
                                                    std::vector<std::string>* warnings = nullptr);

}  // namespace gesture_formation::estimation

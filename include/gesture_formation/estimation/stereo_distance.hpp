#pragma once
/// \file
/// \brief Stereo distance: the median of the valid depth values inside the worker's box
/// (paper: "derived from the median of distance measurements within the bounding box"),
/// converted from optical-axis depth to range along the ray through the box centre.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "gesture_formation/common/result.hpp"
#include "gesture_formation/estimation/camera_model.hpp"
#include "gesture_formation/estimation/measurement_model.hpp"

namespace gesture_formation::common {
struct ConfigError;
}  // namespace gesture_formation::common

namespace gesture_formation::estimation {

/// \brief Parameters of the stereo distance. Defaults suit a RealSense D435.
struct StereoDistanceConfig {
  double min_depth_m = 0.2;        ///< depth values below are invalid [m], ≥ 0
  double max_depth_m = 20.0;       ///< depth values above are invalid [m], > min_depth_m
  int min_valid_pixels = 20;       ///< fewer valid pixels → unavailable, ≥ 1
  double min_valid_fraction = 0.05;  ///< fewer than this fraction of the box's pixels valid → unavailable, [0, 1]
  double depth_scale_m = 0.001;    ///< metres per unit for 16-bit depth images (RealSense: mm), > 0
};

/// \brief StereoDistanceConfig's numbers (keys `min_depth_m`, `max_depth_m`, `min_valid_pixels`,
/// `min_valid_fraction`, `depth_scale_m`) with their ranges: the only place they are written, used
/// by the estimator's validate() and YAML reader (under `stereo.`) and by the Perception nodelet's
/// parameters (common/config_fields.hpp).
const common::FieldTable<StereoDistanceConfig>& stereoDistanceFields();
/// \brief Every problem of `config` (keys as in stereoDistanceFields()): each field outside its
/// range, and max_depth_m > min_depth_m.
std::vector<common::ConfigError> stereoDistanceProblems(const StereoDistanceConfig& config);

/// \brief Median valid depth in `box` (clipped to the image) of an aligned depth image
/// (`CV_16UC1` scaled by `depth_scale_m`, or `CV_32FC1` in metres), converted to range
/// along the centre ray: d = depth / d̂_z. Zero, NaN and out-of-range depths are ignored.
/// Fails with a reason when too few pixels are valid, the image type is wrong, or the box
/// does not intersect the image. Thread safety: reentrant.
common::Result<double> stereoDistance(const cv::Mat& depth, const Box& box, const CameraModel& camera,
                                      const StereoDistanceConfig& config);

}  // namespace gesture_formation::estimation

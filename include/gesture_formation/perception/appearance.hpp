#pragma once
/// \file
/// \brief `AppearanceModel`: what the worker looks like, so that the tracker keeps the worker's
/// identity when another person crosses, and finds the worker again after a loss (docs/perception.md,
/// "Identity"). Geometry alone (IoU, centre gates) cannot tell two people apart once their boxes
/// overlap; clothing colours can, and cost ~0.1 ms per box.
///
/// The descriptor is a colour histogram of the body: HSV, `hue_bins` × `sat_bins` × `val_bins`,
/// of the box's inner region (the central 60 % of its width, 10–95 % of its height: mostly the
/// person, little background), L1-normalised. Similarity = 1 − Bhattacharyya distance, in [0, 1]
/// (1: identical histograms). The model is the running mean of the descriptors of frames in which
/// the worker was detected clear of everyone else (no other detection overlapping), so a crossing
/// never teaches it the other person's colours. It is *established* after `min_updates` such frames;
/// before that it rejects nothing.
/// Thread safety: none (one per tracker).

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace gesture_formation::common {
template <class Config>
struct FieldTable;
}  // namespace gesture_formation::common

namespace gesture_formation::perception {

/// \brief Settings (keys `tracker.appearance.*`; ranges in appearanceFields()).
struct AppearanceConfig {
  int enabled = 1;                 ///< 0: geometry only (the association before appearance), {0, 1}
  int hue_bins = 12;               ///< [2, 64]
  int sat_bins = 4;                ///< [1, 32]
  int val_bins = 4;                ///< [1, 32]
  float min_similarity = 0.55f;    ///< a detection less similar than this is not the worker, [0, 1]
  float tracker_min_similarity = 0.45f;  ///< a tracker box less similar counts as a tracker failure, [0, 1]
  float update_rate = 0.1f;        ///< weight of a new clear frame in the running mean, (0, 1]
  int min_updates = 3;             ///< clear frames before the model rejects anything, ≥ 1

  /// \brief Every problem, each naming the key; empty when valid.
  std::vector<std::string> validate() const;
};

/// \brief AppearanceConfig's numbers with their ranges (keys `tracker.appearance.*`).
const common::FieldTable<AppearanceConfig>& appearanceFields();

/// \brief The worker's colour model.
class AppearanceModel {
 public:
  explicit AppearanceModel(AppearanceConfig config = {}) : config_(config) {}

  /// \brief The descriptor of `box_px` in `frame_bgr` (8-bit BGR); empty when the inner region
  /// is smaller than 2 × 2 px or outside the frame.
  cv::Mat describe(const cv::Mat& frame_bgr, const cv::Rect2f& box_px) const;

  /// \brief 1 − Bhattacharyya distance between the model and `descriptor`, in [0, 1]; 1 when the
  /// model is not established or the descriptor is empty (nothing to reject with).
  double similarity(const cv::Mat& descriptor) const;

  /// \brief True when `descriptor` may be the worker: model not established, appearance off, or
  /// similarity ≥ `threshold`.
  bool accepts(const cv::Mat& descriptor, double threshold) const;

  /// \brief Folds a clear frame's descriptor into the model (ignored when empty).
  void update(const cv::Mat& descriptor);

  bool established() const { return config_.enabled != 0 && updates_ >= config_.min_updates; }
  int updates() const { return updates_; }
  void reset() {
    model_.release();
    updates_ = 0;
  }
  const AppearanceConfig& config() const { return config_; }

 private:
  AppearanceConfig config_;
  cv::Mat model_;  ///< CV_32F histogram, L1 = 1
  int updates_ = 0;
};

}  // namespace gesture_formation::perception

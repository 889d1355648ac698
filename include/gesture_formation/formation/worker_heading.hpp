#pragma once
/// \file
/// \brief The worker's heading ^Hφ used by eq. leader_ref (design.md §4; docs/formation.md §5).
///
/// Modes:
/// - kConstant (default, the paper): ^Hφ = constant_heading_rad (default 0).
/// - kMotion: ^Hφ = atan2(v_y, v_x) of the worker's horizontal velocity, with hysteresis:
///   it starts (or resumes) following the motion when the horizontal speed is ≥
///   speed_high_mps, keeps following while the speed is ≥ speed_low_mps, and holds the last
///   heading once the speed drops below speed_low_mps (a worker standing still on a tower
///   does not spin the formation with estimator noise). Before the worker ever moved fast
///   enough, the heading is constant_heading_rad.
/// - kOperator: ^Hφ = the last value given to setOperatorHeading() (initially
///   constant_heading_rad).
/// Along a planning horizon the constant-velocity prediction has one velocity, so one
/// heading serves every step.
/// Thread safety: none; one instance per thread.

#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::formation {

enum class WorkerHeadingMode { kConstant, kMotion, kOperator };

/// \brief "constant", "motion", "operator".
const char* toString(WorkerHeadingMode mode);

/// \brief Configuration (YAML section `worker_heading`).
struct WorkerHeadingConfig {
  WorkerHeadingMode mode = WorkerHeadingMode::kConstant;  ///< `mode`: constant | motion | operator
  double constant_heading_deg = 0.0;  ///< ^Hφ of the constant mode and the initial heading [deg], finite
  double speed_low_mps = 0.2;         ///< below: hold the last heading [m/s], ≥ 0
  double speed_high_mps = 0.5;        ///< at or above: follow the motion [m/s], ≥ speed_low_mps, > 0
  /// \brief Every problem, each naming the key (`worker_heading.<field>`).
  std::vector<std::string> validate() const;
  /// \brief The same problems, typed {key, message}.
  std::vector<common::ConfigError> problems() const;
};

/// \brief WorkerHeadingConfig's numbers (keys `worker_heading.*`) with their ranges: the only
/// place they are written, used by validate() and by the YAML reader.
const common::FieldTable<WorkerHeadingConfig>& workerHeadingFields();

/// \brief Tracks ^Hφ according to WorkerHeadingConfig.
class WorkerHeading {
 public:
  explicit WorkerHeading(const WorkerHeadingConfig& config);

  /// \brief Feeds the worker's estimated velocity (world frame [m/s]) and returns ^Hφ
  /// [rad], wrapped to (−π, π]. Non-finite velocity is ignored (the heading is held).
  double update(const Eigen::Vector3d& v_world_mps);
  /// \brief Operator mode: sets ^Hφ [rad]. Returns false (and changes nothing) for a
  /// non-finite value. In the other modes the value is stored and used once the mode is
  /// switched to kOperator.
  bool setOperatorHeading(double heading_rad);
  /// \brief Switches the mode (the held motion heading is kept).
  void setMode(WorkerHeadingMode mode) { config_.mode = mode; }

  /// \brief The current ^Hφ [rad], (−π, π].
  double heading() const;
  /// \brief Motion mode: true while the heading follows the motion (between the thresholds
  /// after exceeding speed_high_mps).
  bool following() const { return following_; }

 private:
  WorkerHeadingConfig config_;
  double motion_heading_rad_;
  double operator_heading_rad_;
  bool following_ = false;
};

}  // namespace gesture_formation::formation

#include "gesture_formation/formation/worker_heading.hpp"

#include <cmath>

#include "gesture_formation/common/angles.hpp"

namespace gesture_formation::formation {

const char* toString(WorkerHeadingMode mode) {
  switch (mode) {
    case WorkerHeadingMode::kConstant: return "constant";
    case WorkerHeadingMode::kMotion: return "motion";
    case WorkerHeadingMode::kOperator: return "operator";
  }
  return "?";
}

const common::FieldTable<WorkerHeadingConfig>& workerHeadingFields() {
  using C = WorkerHeadingConfig;
  using common::Range;
  static const common::FieldTable<WorkerHeadingConfig> t{{
      {"worker_heading.constant_heading_deg", Range::any(), [](C& c) { return &c.constant_heading_deg; }},
      {"worker_heading.speed_low_mps", Range::nonNegative(), [](C& c) { return &c.speed_low_mps; }},
      {"worker_heading.speed_high_mps", Range::positive(), [](C& c) { return &c.speed_high_mps; }},
  }};
  return t;
}

std::vector<common::ConfigError> WorkerHeadingConfig::problems() const {
  std::vector<common::ConfigError> e = workerHeadingFields().rangeProblems(*this);
  common::checkRule(e, speed_high_mps >= speed_low_mps, "worker_heading.speed_high_mps", speed_high_mps,
                    "must be >= worker_heading.speed_low_mps");
  workerHeadingFields().sortByTableOrder(e);
  return e;
}

std::vector<std::string> WorkerHeadingConfig::validate() const { return common::problemLines(problems()); }

WorkerHeading::WorkerHeading(const WorkerHeadingConfig& config)
    : config_(config),
      motion_heading_rad_(common::wrapAngle(common::degToRad(config.constant_heading_deg))),
      operator_heading_rad_(motion_heading_rad_) {}

double WorkerHeading::update(const Eigen::Vector3d& v_world_mps) {
  if (v_world_mps.allFinite()) {
    const double speed = std::hypot(v_world_mps.x(), v_world_mps.y());
    if (speed >= config_.speed_high_mps) {
      following_ = true;
    } else if (speed < config_.speed_low_mps) {
      following_ = false;
    }
    if (following_ && speed > 0.0) motion_heading_rad_ = common::wrapAngle(std::atan2(v_world_mps.y(), v_world_mps.x()));
  }
  return heading();
}

bool WorkerHeading::setOperatorHeading(double heading_rad) {
  if (!std::isfinite(heading_rad)) return false;
  operator_heading_rad_ = common::wrapAngle(heading_rad);
  return true;
}

double WorkerHeading::heading() const {
  switch (config_.mode) {
    case WorkerHeadingMode::kConstant: return common::wrapAngle(common::degToRad(config_.constant_heading_deg));
    case WorkerHeadingMode::kMotion: return motion_heading_rad_;
    case WorkerHeadingMode::kOperator: return operator_heading_rad_;
  }
  return 0.0;
}

}  // namespace gesture_formation::formation

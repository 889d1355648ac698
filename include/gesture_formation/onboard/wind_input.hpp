#pragma once
/// \file
/// \brief The flight stack's wind estimate as the planner takes it (docs/safety.md §4.7; the
/// FormationPlanner's wind_estimate_in, e.g. MAVROS `wind_estimation`): accepted only in the world
/// frame, finite and at most kMaxWindMps (a larger one is garbage), and used while it is no older
/// than max_age_s. Thread safety: none (the caller's lock).

#include <cstdint>
#include <optional>
#include <string>

#include <Eigen/Core>

namespace gesture_formation::onboard {

class WindInput {
 public:
  static constexpr double kMaxWindMps = 60.0;

  explicit WindInput(double max_age_s = 0.0) : max_age_s_(max_age_s) {}

  /// \brief An estimate `wind_mps` in `frame_id` at `stamp_s`: "" when taken, else why it was
  /// refused (counted in rejected(); the estimate held is kept).
  std::string receive(const std::string& frame_id, const std::string& world_frame, const Eigen::Vector3d& wind_mps,
                      double stamp_s);
  /// The estimate at `t_s` when one is held and no older than max_age_s.
  std::optional<Eigen::Vector3d> at(double t_s) const;
  std::uint64_t rejected() const { return rejected_; }

 private:
  double max_age_s_ = 0.0, stamp_s_ = 0.0;
  std::optional<Eigen::Vector3d> wind_;
  std::uint64_t rejected_ = 0;
};

}  // namespace gesture_formation::onboard

#pragma once
/// \file
/// \brief The fault `faults.worker_approach` (profile worker_approaches_holding_uav,
/// docs/safety.md §3): at t_s the worker leaves his route and walks on the ground, at speed_mps,
/// straight towards the point below where UAV `uav` is at that moment, stops stop_m short of it
/// (horizontally) and stands there for the rest of the mission. With a camera blackout around it
/// he does so unseen, towards a UAV that holds. ApproachRecorder measures, during the unseen
/// phase (from t_s on, while a camera blackout lasts), each UAV's least true distance to him and
/// how often it came closer than Γ_dis.
/// Thread safety: none.

#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/common/config_reader.hpp"

namespace gesture_formation::sim {

/// \brief `faults.worker_approach: {t_s, uav, speed_mps, stop_m}`.
struct WorkerApproach {
  double t_s = 0.0;        ///< when he turns towards the UAV [s], ≥ 0 (required)
  int uav = 1;             ///< the UAV he walks towards (0 = leader), < the UAV count (required)
  double speed_mps = 1.2;  ///< his walking speed [m/s], (0, 3]
  double stop_m = 0.0;     ///< he stops this far (horizontally) short of the point below the UAV [m], [0, 20]
};

/// \brief The ranges of WorkerApproach's numbers.
const common::FieldTable<WorkerApproach>& workerApproachFields();

/// \brief Reads `faults.worker_approach` at `key` (t_s and uav required); absent: `out` stays
/// empty. Problems recorded in `r`, each naming its key.
void readWorkerApproach(common::ConfigReader& r, const std::string& key, std::optional<WorkerApproach>& out);

class WorkerModel;

/// \brief The approach itself, at its time: `worker` leaves his route at t_s and walks on the ground
/// towards the point below `uav_p_world` (where UAV `approach.uav` is then), stopping
/// `approach.stop_m` short of it (horizontally). Shared by gfctl simulate and the ROS SimWorld.
void divertTowards(WorkerModel& worker, double t_s, const WorkerApproach& approach, const Eigen::Vector3d& uav_p_world);

/// \brief One UAV's figures of the unseen approach.
struct UavApproachRecord {
  double min_distance_m = std::numeric_limits<double>::infinity();  ///< least true distance to the worker [m]
  int gamma_dis_violations = 0;  ///< times it came closer than Γ_dis (each entry below counts once)
};

/// \brief The approach of one mission (metrics.json `worker_approach`).
struct ApproachSummary {
  double t_s = 0.0;                 ///< when he turned
  int uav = 0;                      ///< towards which UAV
  double gamma_dis_m = 0.0;         ///< Γ_dis used for the count
  double unseen_from_s = std::numeric_limits<double>::quiet_NaN();  ///< the measured phase
  double unseen_to_s = std::numeric_limits<double>::quiet_NaN();
  std::vector<UavApproachRecord> uavs;
  double minDistance() const;       ///< over the UAVs
  int violations() const;           ///< over the UAVs
};

/// \brief Accumulates an ApproachSummary from the true positions at every step.
class ApproachRecorder {
 public:
  ApproachRecorder(const WorkerApproach& approach, int uav_count, double gamma_dis_m,
                   std::vector<std::pair<double, double>> camera_blackouts);
  void sample(double t_s, const std::vector<Eigen::Vector3d>& p_world, const Eigen::Vector3d& worker_world);
  const ApproachSummary& summary() const { return summary_; }

 private:
  ApproachSummary summary_;
  std::vector<std::pair<double, double>> blackouts_;
  std::vector<bool> inside_;  ///< per UAV: below Γ_dis at the last sample
};

/// \brief The summary as a JSON object (non-finite → null), indented by `indent`.
std::string approachJson(const ApproachSummary& summary, int indent);

}  // namespace gesture_formation::sim

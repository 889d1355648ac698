#pragma once
/// \file
/// \brief The simulated worker (docs/design.md §5): walks a route of legs (walk, climb a tower,
/// work at height, descend, wait), faces the direction of motion (or a leg's `facing_deg`),
/// performs gestures at scheduled times and work motions otherwise, and is seen by the
/// leader's camera as synthetic skeletons (gesture::SkeletonSynthesizer) rendered from the
/// leader's *actual* viewpoint (distance, elevation, azimuth of the camera around the body)
/// at the moment each motion starts.
///
/// Position convention: `feet` is the point on the ground/structure the worker stands on;
/// the worker's position for estimation and metrics is the **mid-body** point
/// feet + (0, 0, height/2) — the point the estimator's ray through the box centre hits.
/// Thread safety: none. Deterministic for its seed.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/gesture/skeleton_synth.hpp"
#include "gesture_formation/gesture/view_triangulation.hpp"
#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::sim {

/// \brief One leg of the worker's route.
struct RouteLeg {
  enum class Kind { kWalk, kClimb, kDescend, kWork, kWait };
  Kind kind = Kind::kWalk;
  Eigen::Vector3d to_feet_world = Eigen::Vector3d::Zero();  ///< walk/climb/descend: end point of the feet
  double speed_mps = 1.0;    ///< walk/climb/descend, > 0
  double duration_s = 0.0;   ///< work/wait, > 0
  std::optional<double> facing_deg;  ///< body heading during the leg; default: motion direction (walk) or kept
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};
const char* toString(RouteLeg::Kind k);

/// \brief A gesture the worker performs at a scheduled time (it must lie in a work or wait
/// leg, checked by the mission loader).
struct ScheduledGesture {
  double t_s = 0.0;
  int gesture_id = 1;  ///< 1..4 (docs/design.md §2)
};

struct WorkerConfig {
  double height_m = 1.78;  ///< [1.0, 2.3]
  Eigen::Vector3d start_feet_world = Eigen::Vector3d::Zero();
  double start_facing_deg = 0.0;
  std::vector<RouteLeg> route;
  std::vector<ScheduledGesture> gestures;  ///< ascending t_s
  /// Motions cycled through during work legs (near-misses and idle; docs/design.md §2).
  std::vector<gesture::Motion> work_motions{gesture::Motion::kReachUpBolt, gesture::Motion::kToolAtWaist,
                                            gesture::Motion::kIdle, gesture::Motion::kArmsFoldedLow,
                                            gesture::Motion::kArmPartwayOrPointing};
  double gesture_hold_min_s = 3.0;  ///< how long a gesture is held at its pose [s]
  double gesture_hold_max_s = 4.5;
  gesture::SynthConfig synth;       ///< noise, camera, tempo (height overridden by height_m)

  std::vector<std::string> validate(const std::string& prefix = "") const;
  /// \brief Total duration of the route [s] (walk legs: length / speed).
  double routeDuration() const;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief The one range of each number of the worker (mission.worker.*; the route's legs and the
/// scheduled gestures have theirs in routeLegFields() / scheduledGestureFields(); the skeleton
/// synthesis in gesture::synthConfigFields()).
const common::FieldTable<WorkerConfig>& workerConfigFields();
/// \brief speed_mps (walk/climb/descend legs) and duration_s (work/wait legs: keys work_s, wait_s).
const common::FieldTable<RouteLeg>& routeLegFields();
/// \brief t_s and gesture (the id, 1..4).
const common::FieldTable<ScheduledGesture>& scheduledGestureFields();
/// \brief A route leg's facing_deg (optional, hence not in a table).
inline const common::Range kFacingDegRange = common::Range::closed(-360.0, 360.0);

/// \brief The worker's true kinematic state at a time.
struct WorkerState {
  Eigen::Vector3d feet_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d p_world = Eigen::Vector3d::Zero();  ///< mid-body (estimation target)
  Eigen::Vector3d v_world = Eigen::Vector3d::Zero();
  double heading_rad = 0.0;  ///< body facing (x forward)
  int leg = 0;               ///< index of the current leg (route.size() after the end)
  RouteLeg::Kind kind = RouteLeg::Kind::kWait;
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
};

/// \brief A performed gesture: when the worker was performing it (rise → hold → lower).
struct GestureEpisode {
  int gesture_id = 0;
  double scheduled_s = 0.0;
  double start_s = 0.0;  ///< the motion leaves the rest pose
  double end_s = 0.0;    ///< back at rest
};

class WorkerModel {
 public:
  /// \brief `config` must be valid.
  WorkerModel(const WorkerConfig& config, std::uint64_t seed);

  /// \brief The true state at `t_s` (pure function of the route; any order of calls).
  WorkerState stateAt(double t_s) const;

  /// \brief The skeleton seen at camera frame time `t_s` by a camera at `camera_world`
  /// (the skeleton's viewpoint is fixed when each motion starts). Call with increasing
  /// times at the camera rate. Also returns the ground-truth gesture label of the frame.
  gesture::SynthFrame skeletonAt(double t_s, const Eigen::Vector3d& camera_world);
  /// \brief The same performance seen at `t_s` by several cameras at once (the formation's:
  /// element 0 the leader's, then the followers'); each viewpoint is fixed when a motion
  /// starts. Element 0 is exactly what skeletonAt(t_s, cameras[0]) would return. Pass the
  /// same number of cameras at every call (≥ 1).
  std::vector<gesture::SynthFrame> skeletonsAt(double t_s, const std::vector<Eigen::Vector3d>& cameras);

  /// \brief The worker's posed 3-D body (body frame: x forward, y left, z up, feet at 0) of the
  /// current motion at `t_s` — the body whose projection skeletonsAt(t_s, …) returned (the same
  /// frame of the same motion, before the camera's keypoint noise). Call after skeletonsAt at
  /// the same `t_s` (rendered camera: the worker mesh is posed from it, docs/simulation.md §8).
  gesture::Body3D bodyAt(double t_s) const;

  /// \brief View `view`'s skeleton `skeleton` (of the current motion, as skeletonsAt returned it)
  /// with the pose of the camera that rendered it, in the world at the worker's true state `ws`:
  /// the motion's viewpoint (distance, elevation, azimuth around the body, fixed when the motion
  /// started) carried along with the worker, aimed at the body's centre (the generator's aim
  /// jitter, ±3 % of the height, is left out: a pose error of ~0.3°). Requires a motion started
  /// with more than `view` cameras.
  gesture::CalibratedSkeleton calibrated(std::size_t view, const gesture::Skeleton2D& skeleton, const WorkerState& ws) const;

  /// \brief From `t_s` on the worker leaves his route: he walks from where he is then straight
  /// to `to_feet_world` at `speed_mps` (on the ground: `to_feet_world`'s height is his feet's at
  /// t_s) and waits there for the rest of the mission (faults.worker_approach). stateAt() before
  /// t_s is unchanged; call it once, at t_s (later calls replace the detour).
  void divert(double t_s, const Eigen::Vector3d& to_feet_world, double speed_mps);

  /// \brief Gestures started so far, in order.
  const std::vector<GestureEpisode>& episodes() const { return episodes_; }
  /// \brief The gesture (id) being performed at `t_s` (0 = none), from the episodes so far.
  int performingAt(double t_s) const;
  const WorkerConfig& config() const { return config_; }

 private:
  void startMotion(double t_s, gesture::Motion motion, const std::vector<Eigen::Vector3d>& cameras, bool is_scheduled,
                   double scheduled_s);
  gesture::Motion motionFor(const WorkerState& s);
  /// Index of the current motion's frame shown at `t_s`.
  std::size_t frameIndex(double t_s) const;

  WorkerConfig config_;
  std::vector<double> leg_start_s_;
  std::vector<Eigen::Vector3d> leg_start_feet_;
  std::vector<double> leg_heading_rad_;
  gesture::SkeletonSynthesizer synth_;         ///< work motions
  gesture::SkeletonSynthesizer gesture_synth_;  ///< gestures (held longer)
  gesture::SynthSequence current_;
  std::vector<gesture::SynthSequence> other_views_;  ///< the same motion from cameras 1..
  double current_start_s_ = -1e9;
  bool has_current_ = false;
  std::size_t next_gesture_ = 0;
  std::size_t next_work_motion_ = 0;
  std::vector<GestureEpisode> episodes_;
  struct Detour {
    double t_s = 0.0;
    Eigen::Vector3d from_feet_world = Eigen::Vector3d::Zero();
    Eigen::Vector3d to_feet_world = Eigen::Vector3d::Zero();
    double speed_mps = 1.0;
    double heading_rad = 0.0;
  };
  std::optional<Detour> detour_;  ///< faults.worker_approach
  WorkerState detourStateAt(double t_s) const;
};

/// \brief The motion of gesture id 1..4 (docs/design.md §2).
gesture::Motion motionOfGesture(int gesture_id);

}  // namespace gesture_formation::sim

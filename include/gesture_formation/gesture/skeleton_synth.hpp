#pragma once
/// \file
/// \brief Synthetic skeleton sequences of the worker's gestures and of work motions that
/// resemble them (issue 6; docs/design.md §2 pose definitions), seen from a drone's camera.
///
/// A parametric 3-D body (random height and segment proportions) is animated through one
/// motion per sequence: the four gestures (rest → raise into the pose → hold → lower) or a
/// "none" motion — the near-misses of docs/design.md §2 (reaching up to a bolt, arms folded low,
/// a tool held at the waist, an arm raised part-way or pointing, walking, climbing a
/// ladder, standing idle; since v3 also an object held or caught in front of the chest and a
/// balancing lunge with the torso leaning and the arms out — since v8 half of them a side kick). Body frame: x forward, y left, z up, feet at z = 0. The body is
/// projected through a `CameraModel` from a viewpoint at distance d, elevation ε above the
/// horizontal and azimuth ψ around the body (ψ = 0: in front), with keypoint noise,
/// missing keypoints and box jitter. The simulator uses the same code with the leader's
/// actual viewpoint. Deterministic for a seed (libstdc++ distributions).

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "gesture_formation/estimation/camera_model.hpp"
#include "gesture_formation/gesture/skeleton.hpp"

namespace gesture_formation::common {
template <class Config>
struct FieldTable;
struct ConfigError;
}  // namespace gesture_formation::common

namespace gesture_formation::gesture {

/// \brief The kinds of motion, each with its ground-truth gesture id.
enum class Motion : int {
  kCrossArms = 0, kExtendArmSide, kPalmsTogether, kRaiseArmUp,        // gestures 1..4
  kReachUpBolt, kArmsFoldedLow, kToolAtWaist, kArmPartwayOrPointing,   // near-misses (0)
  kWalking, kClimbingLadder, kIdle,                                    // work motions (0)
  kHoldObjectAtChest, kBalanceLunge,                                   // work motions (0), v3
  kCount
};
const char* toString(Motion m);
/// Gesture id shown while the motion is at its pose (0 for every non-gesture motion).
int gestureIdOf(Motion m);

/// \brief Ranges of the random draws. Defaults: the training distribution.
struct SynthConfig {
  double fps = 15.0;                          ///< frame rate [1/s]
  double height_min_m = 1.55, height_max_m = 1.95;
  double proportion_jitter = 0.08;            ///< ± relative segment-length variation
  double distance_min_m = 5.0, distance_max_m = 20.0;
  double elevation_min_deg = 0.0, elevation_max_deg = 45.0;
  double azimuth_min_deg = -180.0, azimuth_max_deg = 180.0;  ///< 0 = the camera in front of the worker
  double tempo_min = 0.7, tempo_max = 1.4;    ///< speed factor of raising/lowering and of cyclic motions
  double hold_min_s = 1.0, hold_max_s = 3.0;  ///< time at the pose
  double lead_min_s = 0.3, lead_max_s = 1.5;  ///< rest before the motion, and after it
  double keypoint_noise_min = 0.005, keypoint_noise_max = 0.025;  ///< σ as a fraction of the box height
  double dropout_max = 0.08;                  ///< probability a keypoint is missing, drawn per sequence in [0, max]
  double box_jitter = 0.03;                   ///< σ of box edges as a fraction of the box size
  double gesture_fraction = 0.5;              ///< share of sequences that are gestures (rest: none motions)
  estimation::CameraIntrinsics camera;        ///< D435 colour, 640×480 by default

  /// \brief Every problem (synthConfigProblems() and the camera's), each naming the key.
  std::vector<std::string> validate() const;
};

/// \brief SynthConfig's numbers (keys as the member names: `fps`, `height_min_m`, …) with their
/// ranges: the only place they are written, used by validate(), `gfctl synth-gestures --config`
/// and the simulator's worker (`mission.worker.synth.*`).
const common::FieldTable<SynthConfig>& synthConfigFields();
/// \brief Each number outside its range, and each interval with min > max (key: its `_max`).
std::vector<common::ConfigError> synthConfigProblems(const SynthConfig& config);

/// \brief A posed 3-D body: 17 keypoints in the body frame [m].
struct Body3D {
  std::array<Eigen::Vector3d, kNumKeypoints> p;
  Eigen::Vector3d head_top;
};

/// \brief One generated frame: the skeleton and its ground-truth label.
struct SynthFrame {
  double t_s = 0.0;
  Skeleton2D skeleton;
  int label = 0;       ///< gesture id while at the pose (progress ≥ 0.85), else 0
};

/// \brief One sequence with the parameters that produced it.
struct SynthSequence {
  int id = 0;
  Motion motion = Motion::kIdle;
  bool left_arm = true;   ///< for one-arm motions
  double height_m = 0.0;
  double distance_m = 0.0, elevation_deg = 0.0, azimuth_deg = 0.0;
  /// The motion leaves the rest pose at motion_start_s and is back at rest at motion_end_s
  /// (sequence time [s]); a gesture is "being performed" in between (issue 6/7 latency).
  double motion_start_s = 0.0, motion_end_s = 0.0;
  std::vector<SynthFrame> frames;
  /// The posed 3-D body of each frame (body frame, before projection and noise): what the
  /// rendered camera poses the worker mesh from (sim::WorkerModel::bodyAt).
  std::vector<Body3D> bodies;
};

/// \brief Generates sequences. Thread safety: none (owns its RNG).
class SkeletonSynthesizer {
 public:
  SkeletonSynthesizer(const SynthConfig& config, std::uint64_t seed);

  /// A sequence of a random motion (gesture with probability gesture_fraction).
  SynthSequence next();
  /// A sequence of the given motion.
  SynthSequence generate(Motion motion);
  /// A sequence of the given motion seen from a fixed viewpoint (simulation: the leader's
  /// actual camera). Box and keypoints are in that camera's image.
  SynthSequence generateFrom(Motion motion, double distance_m, double elevation_deg, double azimuth_deg);

  /// \brief One viewpoint around the worker (the formation's other cameras).
  struct View {
    double distance_m = 10.0, elevation_deg = 0.0, azimuth_deg = 0.0;
  };
  /// The same performance (same body, motion, timing and pose variation) seen from several
  /// cameras at once: element 0 is exactly what generateFrom(views[0]…) would have returned
  /// (the same random draws, so single-view datasets stay reproducible); every further view
  /// has its own aim jitter, keypoint noise, dropouts and box jitter, from a random stream
  /// derived from (seed, sequence id, view index) that leaves the main stream untouched.
  std::vector<SynthSequence> generateViewsFrom(Motion motion, const std::vector<View>& views);
  /// A random motion (as next()) seen from a random primary viewpoint and from further
  /// cameras at the given azimuth offsets [deg] from it (same elevation; distance drawn in
  /// the configured range from the view's own stream). Element 0 equals next().
  std::vector<SynthSequence> nextViews(const std::vector<double>& azimuth_offsets_deg);

  /// The body posed for `motion` at progress `s` ∈ [0, 1] (0 rest, 1 full pose) and cycle
  /// phase `phase` [rad] for cyclic motions. Exposed for tests of the pose definitions.
  Body3D pose(Motion motion, double s, double phase, bool left_arm) const;

  const SynthConfig& config() const { return config_; }

 private:
  struct BodyShape {
    double height = 1.75;
    double shoulder_half = 0.0, hip_half = 0.0, upper_arm = 0.0, forearm = 0.0;
    double shoulder_z = 0.0, hip_z = 0.0, knee_z = 0.0, ankle_z = 0.0, nose_z = 0.0;
  };
  struct Variation {  // per-sequence pose variation
    double a = 0.5, b = 0.5, c = 0.5, d = 0.5;
    /// The motion's variant (the balancing lunge: a side kick when < 0.5), from a stream of
    /// its own (seed, sequence id): the main stream, and so every other sequence, is unchanged.
    double variant = 0.5;
  };
  /// The per-sequence draws that do not depend on the camera.
  struct Script {
    Motion motion = Motion::kIdle;
    bool left_arm = true;
    double lead = 0, rise = 0, hold = 0, fall = 0, duration = 0, cycle_hz = 0, phase0 = 0;
    double noise_frac = 0, dropout = 0;
  };
  Script drawScript(Motion motion);
  SynthSequence project(const Script& script, int id, const View& view, std::mt19937_64& rng) const;
  std::vector<SynthSequence> renderViews(Motion motion, const std::vector<View>& views);
  void drawShape();
  // pose() in steps: the arms of a static arm motion (false: not one), of a moving one (walking,
  // climbing, holding, lunging, idle), then the lunge's stance and lean.
  struct ArmTargets;
  bool staticArms(Motion motion, ArmTargets& arms) const;
  void movingArms(Motion motion, double s, double phase, ArmTargets& arms, Body3D& body) const;
  void lungeStance(Motion motion, double s, bool left_arm, Body3D& body) const;

  SynthConfig config_;
  estimation::CameraModel camera_;
  std::mt19937_64 rng_;
  BodyShape shape_;
  Variation var_;
  int next_id_ = 0;
  std::uint64_t seed_ = 0;
};

/// \brief Writes sequences as docs/design.md §8.7 CSV with `label` and `sequence` columns.
bool writeSkeletonCsv(const std::string& path, const std::vector<SynthSequence>& sequences, std::string* error);

}  // namespace gesture_formation::gesture

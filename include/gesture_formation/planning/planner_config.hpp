#pragma once
/// \file
/// \brief Parameters of one UAV's three-stage planner (UavPlanner, docs/planning.md §5–§8),
/// with documented defaults, `validate()` naming every bad field, and a YAML loader
/// (`config/planner.yaml`) on common::ConfigReader that lists every missing or out-of-range
/// key at once.
///
/// Units: SI, names carry them. Distances to obstacles are measured to occupied voxel
/// *centres* (corridors, path search, distance field) unless the name says `cube`.
/// Thread safety: value types and pure functions.

#include <algorithm>
#include <string>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/result.hpp"

namespace gesture_formation::planning {

/// \brief Hard dynamic limits. The QP enforces inner polyhedral approximations so that the
/// true Euclidean norms hold (docs/planning.md §6.3): |v_z| ≤ max_vertical, and the
/// horizontal part inside the octagon inscribed in the disc of radius
/// sqrt(max² − max_vertical²), so ‖v‖ ≤ max everywhere (also between samples).
struct DynamicLimits {
  double max_speed_mps = 5.0;                  ///< ‖v‖ bound, > 0
  double max_vertical_speed_mps = 2.0;         ///< |v_z| bound, in (0, max_speed_mps)
  double max_acceleration_mps2 = 3.0;          ///< ‖a‖ bound, > 0
  double max_vertical_acceleration_mps2 = 2.0; ///< |a_z| bound, in (0, max_acceleration_mps2)
  double max_heading_rate_radps = 1.0;         ///< camera heading rate bound, > 0
  double max_pitch_rate_radps = 0.5;           ///< camera pitch rate bound, > 0
  double min_pitch_rad = -1.4;                 ///< camera pitch range (gimbal), < max
  double max_pitch_rad = 0.5;
};

/// \brief Cost weights of the trajectory QP (dimension-free after scaling by dt, see
/// docs/planning.md §6.2). All ≥ 0; reference > 0 (the QP must be strictly convex).
struct QpWeights {
  double reference = 1.0;          ///< Σ ‖p_k − r_k‖² (r_k: projected reference)
  double acceleration = 0.05;      ///< Σ ‖a_k‖²
  double jerk = 0.01;              ///< Σ ‖(a_{k+1} − a_k)/dt‖²
  double terminal_velocity = 1.0;  ///< ‖v_N‖² (end near hover)
};

struct PlannerConfig {
  DynamicLimits limits;
  QpWeights weights;

  // --- stage 2: references and path ---------------------------------------------------
  /// Distance kept from occupied voxel centres by the corridors (CorridorBuilder
  /// clearance): UAV radius + √3/2·resolution + margin. > 0.
  double obstacle_clearance_m = 0.8;
  /// Clearance a reference point / path segment needs (≥ obstacle_clearance_m): references
  /// closer to a voxel centre are projected to the nearest point with this clearance.
  double path_clearance_m = 1.0;
  /// Tracking allowance (docs/safety.md §2.6): the controller does not fly the plan exactly
  /// (wind gusts), so planning keeps obstacle_clearance_m and path_clearance_m *plus* an
  /// allowance for the tracking error, while verification keeps verify_clearance_m. The
  /// allowance is the largest deviation measured between the state and the plan being flown
  /// (at each replanning), decaying at tracking_allowance_decay_mps, clamped to
  /// [tracking_allowance_min_m, tracking_allowance_max_m] (m, 0 ≤ min ≤ max; decay > 0).
  /// The floor is the tracking error expected in the strongest wind of the mission — a gust
  /// arrives faster than any measurement: 0.3 m kept the F450 followers ≥ 0.5 m from the
  /// towers in 8 m/s gusts (the `gusts` profile, docs/reliability.md), where a fallback plan
  /// was flown while the gust pushed 0.34 m beyond it.
  double tracking_allowance_min_m = 0.3;
  double tracking_allowance_max_m = 0.5;
  double tracking_allowance_decay_mps = 0.02;
  /// Wind allowance (docs/safety.md §4.7): a gust pushes a UAV off its plan before any
  /// deviation can be measured, and the push grows with the air speed it brings (drag). So both
  /// bounds of the tracking allowance grow by
  ///   clamp(wind_allowance_m_per_mps · (v_peak − wind_allowance_from_mps), 0, wind_allowance_max_m),
  /// v_peak = the largest horizontal speed of the flight stack's wind estimate
  /// (PlanRequest::wind_estimate_mps) over the last wind_window_s — the site's gust level, as
  /// a weather report's gust figure is the peak of its window. No estimate: no wind allowance.
  /// (from ≥ 0, m_per_mps ≥ 0, max ≥ 0, window > 0.)
  double wind_allowance_from_mps = 5.0;
  double wind_allowance_m_per_mps = 0.2;
  double wind_allowance_max_m = 1.0;
  double wind_window_s = 120.0;
  /// Largest distance (m) a reference may be moved by the projection; > 0.
  double max_projection_m = 6.0;
  /// Consecutive reference points are merged into one path segment while every merged point
  /// lies within this distance (m) of the segment (fewer, larger corridors). ≥ 0.
  double path_merge_tolerance_m = 0.6;
  /// Graph search (A*, 26-connected, on the distance field): the search box is the blocked
  /// segment's bounding box grown by this margin (m), > 0.
  double search_margin_m = 8.0;
  /// Node budget of one graph search (expanded voxels), ≥ 100.
  int search_max_expansions = 200000;

  // --- stage 3: corridors and QP ----------------------------------------------------------
  /// Corridor local box margin (m) per axis around each path segment, > obstacle distance 0.
  double corridor_box_margin_m = 4.0;
  /// Samples are kept this far (m) inside their polytopes' planes, ≥ 0.
  double corridor_margin_m = 0.05;
  /// Γ_dis: distance (m) kept from every higher-priority UAV's planned position at the same
  /// time (paper Table II: 2.5 m), > 0.
  double mutual_distance_m = 2.5;
  /// An older plan of another UAV gets margin Γ_dis + min(age_margin_speed_mps·age,
  /// age_margin_max_m) (uavKeepOutDistance(): its UAV may have replanned since and moved at up to
  /// this speed), ≥ 0.
  double age_margin_speed_mps = 5.0;
  /// Bound (m) of the age term: a UAV whose plans stopped arriving flies its last verified plan,
  /// then hovers at its end (the fallback contract, docs/safety.md §1 rule 5, "The silent UAV's
  /// keep-out"), so it stays within its tracking error of that plan — at most
  /// tracking_allowance_max_m + wind_allowance_max_m (1.5 m) — and its braking stops are the
  /// braking envelope (brake_envelope_age_s). The default, reached at 1 s of age (the default
  /// faults.max_plan_age_s, after which a silent UAV has right of way), is a conservative cap over
  /// that bound. Finite, ≥ tracking_allowance_max_m + wind_allowance_max_m.
  double age_margin_max_m = 5.0;
  /// Another UAV's plan older than this (s, ≥ 0) may already have been replaced by one that did
  /// not arrive — typically a brake plan lost on the link: its UAV stopped while the old plan
  /// flies on, and the recovery rule (verify.recovery_*), which only asks a UAV already inside
  /// the age margin to get no closer to the old plan, would let it follow the old plan into the
  /// stopped UAV (docs/safety.md §4, loss50 seed 6). So every plan this old also adds its
  /// *braking envelope* (brakeEnvelope(): where its UAV would have stopped had it braked at any
  /// time between the plan's t0 and now), kept Γ_dis away with the same recovery rule.
  /// Default: one replanning period (0.4 s) plus latency.
  double brake_envelope_age_s = 0.5;
  /// Look-ahead of the braking envelope (s, ≥ 0) for the plans of *lower-priority* UAVs (higher
  /// uav_index; avoided under the avoid-all-plans rule): with lead > 0 each of them, however
  /// fresh, adds its envelope, covering brake times up to t_now + lead. A lower-priority UAV
  /// yields to every higher-priority plan (with age margins), so its replanning fails more
  /// often, and then it brakes where its plan had it move out of the way; the others learn of it
  /// only when its brake plan arrives and they replan (a replanning period plus the link's
  /// latency later), flying until then plans that may count on it having moved away
  /// (docs/safety.md §4.10, dup_reorder seed 32). Higher-priority plans keep the age rule only:
  /// a lower-priority UAV already yields to them. 0: the age rule for every plan (as before).
  /// Default: two replanning periods.
  double brake_envelope_lead_s = 0.8;
  /// Distance (m) kept from the worker's predicted (mid-body) position, > 0.
  double worker_safety_distance_m = 3.0;
  /// Extra distance (m) added to the inter-UAV and worker half-spaces in the QP only, so that
  /// the trajectory between samples still verifies, ≥ 0.
  double qp_distance_buffer_m = 0.15;
  /// ProxQP absolute accuracy and iteration limit.
  double qp_eps_abs = 1e-6;
  int qp_max_iterations = 4000;
  /// Wall-clock bound (s) of ProxQP's sparse solve; past it the QP is re-solved by the dense
  /// backend (trajectory_qp.hpp, docs/safety.md §4.5), > 0.
  double qp_solve_timeout_s = 2.0;
  /// When the QP over the whole horizon is primal infeasible, re-solve it cut to fewer samples
  /// ending at rest (UavPlanner::solveTruncated) before falling back: a plan that makes progress and
  /// stops inside the last corridor it can reach, instead of the previous plan or a brake. Key
  /// `qp.truncate_on_infeasible`; default false (docs/planning.md §6.3, §12).
  bool qp_truncate_on_infeasible = false;

  // --- camera heading / pitch -------------------------------------------------------------
  /// Solver of the camera angles (camera_tracking.hpp): the closed-form rate-limited filter
  /// (default: same line-of-sight error as Ceres in bench_planner at 1/2000 of the time,
  /// docs/planning.md §6.5) or the Ceres least-squares problem.
  enum class CameraSolver { kFilter, kCeres } camera_solver = CameraSolver::kFilter;
  double heading_weight = 1.0;            ///< Ceres: line-of-sight residual weight, > 0
  double heading_smoothness_weight = 2.0; ///< Ceres: angular-acceleration residual weight, ≥ 0

  // --- verification and fallback ------------------------------------------------------------
  /// Radius (m) of the ball around the UAV that must not touch any occupied voxel *cube*
  /// (FCL) at every densely sampled point, > 0, ≤ obstacle_clearance_m − √3/2·res.
  double verify_clearance_m = 0.5;
  /// Verification points per sample interval (≥ 1; positions, velocities, accelerations are
  /// evaluated on the cubic Hermite spline between samples).
  int verify_substeps = 4;
  /// Relative tolerance of the speed/acceleration checks and absolute (m) of the distance
  /// checks, ≥ 0.
  double verify_tolerance = 1e-3;
  /// Recovery from a separation the measured state already violates (the worker walked up to
  /// a hovering UAV, a UAV starts too close to another): the required distance to the worker /
  /// another UAV is then min(limit, d0 − recovery_slack_m + s(τ)), τ = t − t0, where s(τ) is
  /// the distance covered from rest accelerating at recovery_acceleration_mps2 up to
  /// recovery_speed_mps. The QP asks for 1.2·s(τ) with half the slack, so a solved plan
  /// passes verification. All > 0 (docs/planning.md §7).
  double recovery_speed_mps = 0.5;
  double recovery_acceleration_mps2 = 1.0;
  double recovery_slack_m = 0.1;
  /// The last verified plan may be reused only when it still covers at least this much time
  /// (s) after t_now, > 0 ...
  double fallback_min_horizon_s = 2.0;
  /// ... and its position at t_now lies within this distance (m) of the current state, > 0.
  double fallback_max_deviation_m = 1.0;
  /// Wall-clock budget (ms) of one replanning; exceeded → fallback. 0 disables (tests that
  /// must be deterministic under load).
  double time_budget_ms = 100.0;

  /// Every problem, each naming the field and its value; empty when valid.
  std::vector<std::string> validate() const;
};

/// \brief s(τ): the distance covered in τ seconds from rest at recovery_acceleration_mps2,
/// capped at recovery_speed_mps (0 for τ ≤ 0). See PlannerConfig::recovery_speed_mps.
inline double recoveryAllowance(const PlannerConfig& c, double tau_s) {
  if (!(tau_s > 0.0)) return 0.0;
  const double t1 = c.recovery_speed_mps / c.recovery_acceleration_mps2;
  if (tau_s <= t1) return 0.5 * c.recovery_acceleration_mps2 * tau_s * tau_s;
  return 0.5 * c.recovery_speed_mps * t1 + c.recovery_speed_mps * (tau_s - t1);
}

/// \brief The distance (m) a plan must keep at τ = t − t0 from something (another UAV's plan,
/// a braking envelope, the worker) that must be `limit_m` away and is `d0_m` away at t0: the
/// limit, or — when the start already violates it — the recovery requirement
/// min(limit, d0 − recovery_slack_m + s(τ)) (docs/planning.md §7.1). The verifier uses it as
/// is; the QP (`qp_form`) asks for 1.2·s(τ) with half the slack, so that a solved plan passes
/// verification.
inline double recoveringDistance(const PlannerConfig& c, double limit_m, double d0_m, double tau_s, bool qp_form = false) {
  if (!(d0_m < limit_m)) return limit_m;
  const double recover = qp_form ? d0_m - 0.5 * c.recovery_slack_m + 1.2 * recoveryAllowance(c, tau_s)
                                 : d0_m - c.recovery_slack_m + recoveryAllowance(c, tau_s);
  return std::min(limit_m, recover);
}

/// \brief The distance (m) kept from another UAV's plan of age `age_s` (t_now − its t0) at the same
/// time: Γ_dis + min(age_margin_speed_mps · age, age_margin_max_m) (negative ages count as 0).
/// The one rule of the QP, the verifier and the brake-point mover (docs/safety.md §1 rule 1,
/// "The silent UAV's keep-out").
inline double uavKeepOutDistance(const PlannerConfig& c, double age_s) {
  const double age = age_s > 0.0 ? age_s : 0.0;
  return c.mutual_distance_m + std::min(c.age_margin_speed_mps * age, c.age_margin_max_m);
}

/// \brief Reads every key of PlannerConfig (the layout of config/planner.yaml) under
/// `prefix` ("" or e.g. "planner."). In kError mode every missing key is an error; in
/// kUseDefaults mode absent keys keep the defaults. Cross-field rules (validate()) are
/// added to the reader's errors.
PlannerConfig readPlannerConfig(common::ConfigReader& reader, const std::string& prefix = "");

/// \brief Loads and validates a planner YAML file. Failure lists every problem, one per line.
common::Result<PlannerConfig> loadPlannerConfig(const std::string& path, common::ConfigReader::MissingKeys mode,
                                                std::vector<std::string>* warnings = nullptr);

}  // namespace gesture_formation::planning

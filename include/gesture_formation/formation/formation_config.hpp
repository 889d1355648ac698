#pragma once
/// \file
/// \brief Configuration of the formation (config/formation.yaml; docs/design.md §8.2), as read by
/// `gfctl formation-ref`, `gfctl gesture-filter` and the formation planner nodelet.
///
/// Keys (defaults: Table II and FormationLimits / WorkerHeadingConfig / DuplicateWindowConfig):
/// ```
/// leader: {beta_deg: 90, gamma_deg: 11, distance_m: 10}
/// followers: [{beta_deg: 60, gamma_deg: 0, distance_m: 8}, {beta_deg: -60, gamma_deg: 0, distance_m: 8}]
/// limits: {gamma_min_deg: -30, gamma_max_deg: 60, distance_min_m: 4, distance_max_m: 25, safety_distance_m: 2.5}
/// worker_heading: {mode: constant, constant_heading_deg: 0, speed_low_mps: 0.2, speed_high_mps: 0.5}
/// duplicates: {window_per_sender: 64, max_senders: 16}
/// ```
/// `followers` may hold any number of entries (also none). With MissingKeys::kUseDefaults a
/// missing `followers` gives Table II's two; a missing key of followers[0] / followers[1]
/// takes Table II's value, of followers[2+] γ 0° and d 8 m, but β has no default there
/// (error). β must lie in (−180, 180]; γ (as elevation) and d must lie within `limits`:
/// values outside are errors, never clamped.

#include <string>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/result.hpp"
#include "gesture_formation/formation/formation_commands.hpp"
#include "gesture_formation/formation/formation_params.hpp"
#include "gesture_formation/formation/worker_heading.hpp"

namespace gesture_formation::formation {

/// \brief Everything configurable about the formation.
struct FormationConfig {
  FormationParams params;               ///< initial parameters (Table II)
  FormationLimits limits;               ///< clamping limits and safety distance
  WorkerHeadingConfig worker_heading;   ///< ^Hφ mode
  DuplicateWindowConfig duplicates;     ///< command-id memory

  /// \brief Every problem, each naming the key; empty when valid.
  std::vector<std::string> validate() const;
  /// \brief The same problems, typed {key, message}: each field outside its range and the rules
  /// between fields (elevations and distances within the limits).
  std::vector<common::ConfigError> problems() const;
};

/// \brief Reads a FormationConfig from `reader` starting from the defaults; problems are
/// recorded in the reader (all of them, each naming the key).
FormationConfig readFormationConfig(common::ConfigReader& reader);

/// \brief Loads and validates a config file; on failure the reason lists every problem, one
/// per line. Unknown keys under the sections read are reported in `warnings`.
common::Result<FormationConfig> loadFormationConfig(const std::string& path, common::ConfigReader::MissingKeys mode,
                                                    std::vector<std::string>* warnings = nullptr);

}  // namespace gesture_formation::formation

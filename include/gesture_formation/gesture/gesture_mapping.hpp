#pragma once
/// \file
/// \brief Gesture id → action mapping (docs/design.md §2: "configuration, not code"; file format in
/// docs/formation.md §7 and config/gestures.yaml).
///
/// ```
/// mapping:
///   1: {parameter: leader.beta_deg, increment: -30}   # the paper's default mapping
///   2: {parameter: leader.beta_deg, increment: 30}
///   3: {parameter: leader.gamma_deg, increment: -5}
///   4: {parameter: leader.gamma_deg, increment: 5}
///   # other targets / parameters: all.distance_m, followers.distance_m, follower1.beta_deg …
///   # events: {event: assist_requested} or {event: abort}
/// ```
/// A `mapping` key replaces the default mapping as a whole (ids not listed are unmapped).
/// Ids must be in [1, max_gesture_id]; id 0 ("none") cannot be mapped.
/// Thread safety: immutable after reading.

#include <cstdint>
#include <map>
#include <string>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/formation/formation_commands.hpp"

namespace gesture_formation::gesture {

/// \brief Non-parameter actions a gesture can request.
enum class GestureEvent {
  kAssistRequested,  ///< "assist_requested": the worker asks the operator for help
  kAbort,            ///< "abort": the formation returns / lands
};

/// \brief "assist_requested", "abort".
const char* toString(GestureEvent e);

/// \brief What one gesture does.
struct GestureAction {
  enum class Kind { kParameter, kEvent };
  Kind kind = Kind::kParameter;
  std::string parameter_path;  ///< kParameter: e.g. "leader.beta_deg" (as in the file)
  formation::CommandTarget target;
  formation::Parameter parameter = formation::Parameter::kBeta;
  double increment = 0.0;  ///< kParameter: i_q in the parameter's unit ([deg] or [m])
  GestureEvent event = GestureEvent::kAssistRequested;  ///< kEvent only
};

/// \brief The mapping of gesture ids to actions.
struct GestureMapping {
  std::map<int, GestureAction> actions;

  /// \brief The paper's mapping: 1 → ^Lβ −30°, 2 → ^Lβ +30°, 3 → ^Lγ −5°, 4 → ^Lγ +5°.
  static GestureMapping paperDefault();
  /// \brief The action of `gesture_id`, or nullptr when unmapped.
  const GestureAction* find(int gesture_id) const;
};

/// \brief Reads `mapping` from `reader` (keeps `mapping` untouched when the key is absent
/// in kUseDefaults mode). Checks ids against [1, max_gesture_id] and targets against a
/// formation with `follower_count` followers; records every problem in the reader and
/// then leaves `mapping` untouched (all or nothing).
void readGestureMapping(common::ConfigReader& reader, int max_gesture_id, int follower_count, GestureMapping& mapping);

/// \brief The formation command of a parameter action, sent by "gesture" with `sequence`.
/// Precondition: action.kind == kParameter.
formation::FormationCommand toCommand(const GestureAction& action, std::uint64_t sequence);

}  // namespace gesture_formation::gesture

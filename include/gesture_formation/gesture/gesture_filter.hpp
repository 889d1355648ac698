#pragma once
/// \file
/// \brief Post-processing of the gesture classifier's output (paper: "Human detection and
/// gesture recognition", last paragraph; docs/design.md §2 and §8.3; docs/formation.md §6).
///
/// Per measurement (t, id), in this order:
///  1. reject (state unchanged, reason given) when t is not finite, t is earlier than the
///     previous accepted measurement (equal times are accepted: bursts), or id is not an
///     integer in [0, max_gesture_id];
///  2. append it to G;
///  3. drop every entry older than t − t_c: an entry is KEPT iff t_i ≥ t − max_age_s
///     (an entry exactly t_c old stays);
///  4. keep the K = window_size newest entries (drop the oldest beyond K);
///  5. evaluate only when |G| ≥ min_measurements: f_d = (count of the most frequent id) / |G|
///     (computed as a double division); when two or more ids share the highest count
///     (a tie) nothing fires;
///  6. fire when f_d > Π_d (ratio_threshold; STRICTLY greater), the dominant id ≠ 0, the
///     filter is armed (below), and either nothing has fired yet (the first command has no
///     cooldown) or t − t_last_fired ≥ t_d (cooldown_s; an elapsed time exactly t_d may fire).
/// Re-arming (`rearm`): with `release` (the default: one performance, one command) a fired
/// command disarms the filter until the gesture has been released — the dominant id of every
/// evaluation has been 0 (none; no tie), none of its measurements of 0 a vote that merely fell
/// short (update's `none_seen` false: the views failed to agree on a gesture rather than agreed on
/// none), for at least release_s (from the first such evaluation; any other evaluation restarts
/// it), or every earlier
/// entry of G has expired (nothing seen for t_c: a new performance). A view lost while the worker
/// holds a gesture makes the vote fall short (id 0) but is no release. A gesture held, or misread and held, for longer than t_d thus fires
/// once. With `repeat` (the paper) the filter is always armed: a held gesture fires again
/// every t_d. Firing does not clear G. Rejected and unevaluated measurements do not count
/// toward anything.
/// Cost per measurement: O(max_gesture_id) with no heap allocation (ring buffer and counts
/// are allocated at construction).
/// Thread safety: none; one filter per thread.

#include <cstddef>
#include <string>
#include <vector>

#include "gesture_formation/common/config_reader.hpp"
#include "gesture_formation/common/result.hpp"

namespace gesture_formation::gesture {

/// \brief Gesture id 0: the worker is not gesturing ("none").
constexpr int kGestureNone = 0;

/// \brief When the filter may fire again after a command (YAML `rearm`; docs/formation.md §6).
enum class RearmMode {
  kRelease,  ///< `release` (default): one performance, one command — again only once released
  kRepeat,   ///< `repeat`: the paper — a gesture still dominant fires again every cooldown_s
};
/// \brief "release", "repeat".
const char* toString(RearmMode mode);

/// \brief Parameters of the filter (YAML top-level keys of config/gestures.yaml).
/// Defaults: docs/design.md §2 (K = 20, t_c = 20 s, Π_d = 0.8, t_d = 5 s).
struct GestureFilterConfig {
  int window_size = 20;         ///< K: at most this many newest measurements in G, ≥ 1
  int min_measurements = 20;    ///< evaluate only when |G| ≥ this, in [1, window_size] (default K)
  double max_age_s = 20.0;      ///< t_c [s], > 0: entries with t_i < t − t_c are dropped
  double ratio_threshold = 0.8;  ///< Π_d ∈ [0, 1]: fire when f_d > Π_d
  double cooldown_s = 5.0;      ///< t_d [s], ≥ 0: minimum time between two fired commands
  int max_gesture_id = 4;       ///< valid ids are 0..max_gesture_id (0 none, 1..4 the paper's), ≥ 1
  RearmMode rearm = RearmMode::kRelease;  ///< `rearm`: release | repeat (see RearmMode)
  double release_s = 1.0;       ///< `release_s` [s], ≥ 0: how long "none" must dominate to re-arm (release)

  /// \brief Every problem, each naming the key; empty when valid.
  std::vector<std::string> validate() const;
};

/// \brief Reads the filter keys (`window_size, min_measurements, max_age_s, ratio_threshold,
/// cooldown_s, max_gesture_id, rearm, release_s`) from `reader`; a `rearm` other than release or
/// repeat is an error naming the key and the value. When `window_size` is given but
/// `min_measurements` is not, min_measurements = window_size.
GestureFilterConfig readGestureFilterConfig(common::ConfigReader& reader);

/// \brief Why one GestureFilter::update fired or did not.
enum class FilterVerdict {
  kRejected,        ///< bad measurement; state unchanged (GestureFilterOutput::reason says why)
  kTooFew,          ///< |G| < min_measurements: not evaluated
  kTie,             ///< two or more ids share the highest count
  kBelowThreshold,  ///< f_d ≤ ratio_threshold
  kNoneDominant,    ///< the dominant id is 0 (none)
  kCooldown,        ///< less than cooldown_s since the last fired command
  kAwaitingRelease,  ///< rearm: release — the gesture that fired has not been released yet
  kFired,           ///< a command fires
};

/// \brief "rejected", "too_few", "tie", "below_threshold", "none_dominant", "cooldown",
/// "awaiting_release", "fired".
const char* toString(FilterVerdict v);

/// \brief The result of one GestureFilter::update. No heap allocation unless rejected.
struct GestureFilterOutput {
  bool accepted = false;       ///< false: rejected (reason says why), state unchanged
  bool evaluated = false;      ///< |G| ≥ min_measurements after this measurement
  bool fired = false;          ///< a command fires for `dominant_id` at this measurement's time
  int dominant_id = -1;        ///< most frequent id in G; −1 on a tie or when not evaluated
  double dominant_ratio = 0.0;  ///< f_d (also on a tie: the shared highest count / |G|)
  std::size_t window_count = 0;  ///< |G| after this measurement
  FilterVerdict verdict = FilterVerdict::kRejected;
  std::string reason;          ///< rejection reason (empty otherwise; see verdict)
};

/// \brief The sliding-window dominant-gesture filter (see the file comment).
class GestureFilter {
 public:
  /// \brief Precondition: config.validate() is empty (see create()).
  explicit GestureFilter(const GestureFilterConfig& config);
  /// \brief Validates the config first.
  static common::Result<GestureFilter> create(const GestureFilterConfig& config);

  /// \brief Processes one classifier output at time `t_s` [s] with id `gesture_id`.
  /// `gesture_id` is a double so that non-integer input can be rejected here. `none_seen`: for
  /// id 0, whether the input saw the worker not gesturing (release evidence) rather than a vote
  /// that fell short (lost or disagreeing views, a 3-D refusal); ignored for other ids.
  GestureFilterOutput update(double t_s, double gesture_id, bool none_seen = true);

  /// \brief Disarms the filter until the gesture in progress (if any) is released — what a new
  /// leader's filter does, since its predecessor may have fired for the performance it now sees.
  void awaitRelease();

  /// \brief Forgets every measurement and the last fired time.
  void reset();

  const GestureFilterConfig& config() const { return config_; }
  std::size_t size() const { return size_; }
  /// \brief Time of the last fired command [s]; NaN before the first.
  double lastFiredTime() const { return last_fired_s_; }
  /// \brief Time of the last accepted measurement [s]; NaN before the first.
  double lastTime() const { return last_t_s_; }
  /// \brief Whether a dominant gesture may fire (always with rearm: repeat).
  bool armed() const { return armed_; }

 private:
  struct Entry {
    double t_s;
    int id;
  };
  void popFront();

  GestureFilterConfig config_;
  std::vector<Entry> ring_;  ///< capacity window_size
  std::size_t head_ = 0;     ///< index of the oldest entry
  std::size_t size_ = 0;
  std::vector<int> counts_;  ///< occurrences of each id in G
  double last_t_s_;
  double last_fired_s_;
  bool armed_ = true;
  double none_since_s_;  ///< first evaluation of the current run with "none" dominant (NaN: none)
};

}  // namespace gesture_formation::gesture

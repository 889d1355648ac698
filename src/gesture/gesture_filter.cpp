#include "gesture_formation/gesture/gesture_filter.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "gesture_formation/common/config_fields.hpp"
#include "gesture_formation/common/format_number.hpp"

namespace gesture_formation::gesture {

using common::ConfigReader;
using common::Range;

const char* toString(FilterVerdict v) {
  switch (v) {
    case FilterVerdict::kRejected: return "rejected";
    case FilterVerdict::kTooFew: return "too_few";
    case FilterVerdict::kTie: return "tie";
    case FilterVerdict::kBelowThreshold: return "below_threshold";
    case FilterVerdict::kNoneDominant: return "none_dominant";
    case FilterVerdict::kCooldown: return "cooldown";
    case FilterVerdict::kAwaitingRelease: return "awaiting_release";
    case FilterVerdict::kFired: return "fired";
  }
  return "?";
}

const char* toString(RearmMode mode) {
  switch (mode) {
    case RearmMode::kRelease: return "release";
    case RearmMode::kRepeat: return "repeat";
  }
  return "?";
}

namespace {

/// GestureFilterConfig's numbers: key, range — the only place it is written — and place.
const common::FieldTable<GestureFilterConfig>& fields() {
  using C = GestureFilterConfig;
  static const common::FieldTable<GestureFilterConfig> t{{
      {"window_size", Range::closed(1, 100000), [](C& c) { return &c.window_size; }},
      {"min_measurements", Range::atLeast(1), [](C& c) { return &c.min_measurements; }},
      {"max_age_s", Range::positive(), [](C& c) { return &c.max_age_s; }},
      {"ratio_threshold", Range::closed(0.0, 1.0), [](C& c) { return &c.ratio_threshold; }},
      {"cooldown_s", Range::nonNegative(), [](C& c) { return &c.cooldown_s; }},
      {"max_gesture_id", Range::closed(1, 1000), [](C& c) { return &c.max_gesture_id; }},
      {"release_s", Range::nonNegative(), [](C& c) { return &c.release_s; }},
  }};
  return t;
}

/// Each field outside its range, then the rule between fields.
std::vector<common::ConfigError> problems(const GestureFilterConfig& c) {
  std::vector<common::ConfigError> e = fields().rangeProblems(c);
  common::checkRule(e, c.min_measurements <= c.window_size, "min_measurements", c.min_measurements,
                    "must be <= window_size " + std::to_string(c.window_size) + " (the filter could never evaluate)");
  fields().sortByTableOrder(e);
  return e;
}

}  // namespace

std::vector<std::string> GestureFilterConfig::validate() const { return common::problemLines(problems(*this)); }

GestureFilterConfig readGestureFilterConfig(ConfigReader& r) {
  GestureFilterConfig c;
  std::string rearm = toString(c.rearm);
  r.readString("rearm", rearm, {toString(RearmMode::kRelease), toString(RearmMode::kRepeat)});  // else: an error naming key and value
  c.rearm = rearm == toString(RearmMode::kRepeat) ? RearmMode::kRepeat : RearmMode::kRelease;
  fields().readFields(r, "", c);
  if (!r.has("min_measurements")) c.min_measurements = c.window_size;  // default: K
  // The rule between fields, always (a key outside its range kept its default while reading).
  common::addProblems(r, "", problems(c));
  return c;
}

GestureFilter::GestureFilter(const GestureFilterConfig& config)
    : config_(config),
      ring_(static_cast<std::size_t>(config.window_size > 0 ? config.window_size : 1)),
      counts_(static_cast<std::size_t>(config.max_gesture_id > 0 ? config.max_gesture_id + 1 : 1), 0),
      last_t_s_(std::numeric_limits<double>::quiet_NaN()),
      last_fired_s_(std::numeric_limits<double>::quiet_NaN()),
      none_since_s_(std::numeric_limits<double>::quiet_NaN()) {}

common::Result<GestureFilter> GestureFilter::create(const GestureFilterConfig& config) {
  const auto e = config.validate();
  if (!e.empty()) {
    std::string reason;
    for (const auto& s : e) reason += s + "\n";
    return common::Result<GestureFilter>::fail(reason);
  }
  return common::Result<GestureFilter>::ok(GestureFilter(config));
}

void GestureFilter::reset() {
  head_ = 0;
  size_ = 0;
  for (int& c : counts_) c = 0;
  last_t_s_ = std::numeric_limits<double>::quiet_NaN();
  last_fired_s_ = std::numeric_limits<double>::quiet_NaN();
  armed_ = true;
  none_since_s_ = std::numeric_limits<double>::quiet_NaN();
}

void GestureFilter::popFront() {
  --counts_[static_cast<std::size_t>(ring_[head_].id)];
  head_ = (head_ + 1) % ring_.size();
  --size_;
}

void GestureFilter::awaitRelease() {
  armed_ = config_.rearm == RearmMode::kRepeat;
  none_since_s_ = std::numeric_limits<double>::quiet_NaN();
}

GestureFilterOutput GestureFilter::update(double t_s, double gesture_id, bool none_seen) {
  GestureFilterOutput out;
  out.window_count = size_;
  if (!std::isfinite(t_s)) {
    out.reason = "non-finite time " + common::formatNumber(t_s);
    return out;
  }
  if (t_s < last_t_s_) {  // false while last_t_s_ is NaN
    out.reason = "out of order: t=" + common::formatNumber(t_s) + " s is earlier than the previous measurement at " + common::formatNumber(last_t_s_) + " s";
    return out;
  }
  if (!(std::isfinite(gesture_id) && gesture_id == std::floor(gesture_id) && gesture_id >= 0.0 &&
        gesture_id <= config_.max_gesture_id)) {
    out.reason = "unknown gesture id " + common::formatNumber(gesture_id) + " (valid: integers 0.." + std::to_string(config_.max_gesture_id) + ")";
    return out;
  }
  const int id = static_cast<int>(gesture_id);
  out.accepted = true;
  // Every earlier entry has expired (nothing seen for t_c): what follows is a new performance.
  if (!std::isnan(last_t_s_) && last_t_s_ < t_s - config_.max_age_s) armed_ = true;
  last_t_s_ = t_s;

  // 2.–4. append, drop entries older than t − t_c, keep the K newest.
  if (size_ == ring_.size()) popFront();
  ring_[(head_ + size_) % ring_.size()] = Entry{t_s, id};
  ++size_;
  ++counts_[static_cast<std::size_t>(id)];
  const double oldest_kept_s = t_s - config_.max_age_s;
  while (size_ > 0 && ring_[head_].t_s < oldest_kept_s) popFront();
  out.window_count = size_;

  // 5. evaluate.
  if (static_cast<int>(size_) < config_.min_measurements) {
    out.verdict = FilterVerdict::kTooFew;
    return out;
  }
  out.evaluated = true;
  int best = -1, best_count = 0;
  bool tie = false;
  for (std::size_t g = 0; g < counts_.size(); ++g) {
    if (counts_[g] > best_count) {
      best = static_cast<int>(g);
      best_count = counts_[g];
      tie = false;
    } else if (counts_[g] == best_count && best_count > 0) {
      tie = true;
    }
  }
  out.dominant_ratio = static_cast<double>(best_count) / static_cast<double>(size_);
  // Release: "none" dominating (no tie) for release_s re-arms; anything else restarts the run,
  // and so does a measurement of none that saw no release (a vote that fell short).
  if (!tie && best == kGestureNone && (id != kGestureNone || none_seen)) {
    if (std::isnan(none_since_s_)) none_since_s_ = t_s;
    if (t_s - none_since_s_ >= config_.release_s) armed_ = true;
  } else {
    none_since_s_ = std::numeric_limits<double>::quiet_NaN();
  }
  if (tie) {
    out.verdict = FilterVerdict::kTie;
    return out;
  }
  out.dominant_id = best;
  // 6. fire?
  if (!(out.dominant_ratio > config_.ratio_threshold)) {
    out.verdict = FilterVerdict::kBelowThreshold;
  } else if (best == kGestureNone) {
    out.verdict = FilterVerdict::kNoneDominant;
  } else if (!std::isnan(last_fired_s_) && !(t_s - last_fired_s_ >= config_.cooldown_s)) {
    out.verdict = FilterVerdict::kCooldown;
  } else if (config_.rearm == RearmMode::kRelease && !armed_) {
    out.verdict = FilterVerdict::kAwaitingRelease;
  } else {
    out.verdict = FilterVerdict::kFired;
    out.fired = true;
    last_fired_s_ = t_s;
    armed_ = config_.rearm == RearmMode::kRepeat;
    none_since_s_ = std::numeric_limits<double>::quiet_NaN();
  }
  return out;
}

}  // namespace gesture_formation::gesture

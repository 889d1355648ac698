#include "gesture_formation/gesture/gesture_filter.hpp"

#include <cmath>
#include <limits>
#include <sstream>

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

std::vector<std::string> GestureFilterConfig::validate() const {
  std::vector<std::string> e;
  if (window_size < 1) e.push_back("window_size must be >= 1, got " + std::to_string(window_size));
  if (min_measurements < 1 || min_measurements > window_size) {
    e.push_back("min_measurements must be in [1, window_size=" + std::to_string(window_size) + "], got " +
                std::to_string(min_measurements));
  }
  if (!(std::isfinite(max_age_s) && max_age_s > 0.0)) e.push_back("max_age_s must be > 0, got " + common::formatNumber(max_age_s));
  if (!(ratio_threshold >= 0.0 && ratio_threshold <= 1.0)) {
    e.push_back("ratio_threshold must be in [0, 1], got " + common::formatNumber(ratio_threshold));
  }
  if (!(std::isfinite(cooldown_s) && cooldown_s >= 0.0)) e.push_back("cooldown_s must be >= 0, got " + common::formatNumber(cooldown_s));
  if (!(std::isfinite(release_s) && release_s >= 0.0)) e.push_back("release_s must be >= 0, got " + common::formatNumber(release_s));
  if (max_gesture_id < 1 || max_gesture_id > 1000) {
    e.push_back("max_gesture_id must be in [1, 1000], got " + std::to_string(max_gesture_id));
  }
  return e;
}

GestureFilterConfig readGestureFilterConfig(ConfigReader& r) {
  GestureFilterConfig c;
  r.readInt("window_size", c.window_size, Range::closed(1, 100000));
  c.min_measurements = c.window_size;
  r.readInt("min_measurements", c.min_measurements, Range::atLeast(1));
  r.readDouble("max_age_s", c.max_age_s, Range::positive());
  r.readDouble("ratio_threshold", c.ratio_threshold, Range::closed(0.0, 1.0));
  r.readDouble("cooldown_s", c.cooldown_s, Range::nonNegative());
  r.readInt("max_gesture_id", c.max_gesture_id, Range::closed(1, 1000));
  std::string rearm = c.rearm_on_release ? "release" : "cooldown";
  r.readString("rearm", rearm, {"release", "cooldown"});
  c.rearm_on_release = rearm == "release";
  r.readDouble("release_s", c.release_s, Range::nonNegative());
  if (c.min_measurements > c.window_size) {
    r.addError("min_measurements", "value " + std::to_string(c.min_measurements) + " exceeds window_size " +
                                       std::to_string(c.window_size) + " (the filter could never evaluate)");
  }
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

GestureFilterOutput GestureFilter::update(double t_s, double gesture_id) {
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
  // Release: "none" dominating (no tie) for release_s re-arms; anything else restarts the run.
  if (!tie && best == kGestureNone) {
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
  } else if (config_.rearm_on_release && !armed_) {
    out.verdict = FilterVerdict::kAwaitingRelease;
  } else {
    out.verdict = FilterVerdict::kFired;
    out.fired = true;
    last_fired_s_ = t_s;
    armed_ = !config_.rearm_on_release;
    none_since_s_ = std::numeric_limits<double>::quiet_NaN();
  }
  return out;
}

}  // namespace gesture_formation::gesture

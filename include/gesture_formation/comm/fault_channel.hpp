#pragma once
/// \file
/// \brief A lossy, delaying, duplicating, reordering link for simulation (issue 9 item 1;
/// docs/security.md §8). One FaultChannel models one direction of one link (sender → receiver);
/// a multicast "bus" is one channel per receiver, each with its own seed.
///
/// Per packet sent at t:
///   1. lost with probability loss_probability (nothing delivered);
///   2. else delivered at t + delay_s + U[0, jitter_s); with probability reorder_probability
///      the copy is held back an extra reorder_extra_delay_s, so later packets overtake it;
///   3. with probability duplicate_probability a second copy is delivered, with its own
///      jitter, after the first (duplicate_extra_delay_s later at least).
/// Packets come out of poll() in order of delivery time (ties: order sent, then copy).
/// Deterministic for a seed: a 64-bit Mersenne Twister (its output is fixed by the C++
/// standard) with our own conversion to [0, 1), so runs repeat across compilers and
/// libraries; the random draws per send are a fixed number (5), independent of outcomes.
/// Thread safety: none; one channel per simulation thread.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <queue>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::comm {

/// \brief Fault parameters. Defaults: a perfect link. validate() names the field.
struct FaultChannelConfig {
  double loss_probability = 0.0;        ///< [0, 1]
  double delay_s = 0.0;                 ///< fixed latency [s], ≥ 0
  double jitter_s = 0.0;                ///< extra latency U[0, jitter_s) [s], ≥ 0
  double duplicate_probability = 0.0;   ///< [0, 1]
  double duplicate_extra_delay_s = 0.0; ///< a duplicate arrives at least this much after the original [s], ≥ 0
  double reorder_probability = 0.0;     ///< [0, 1]
  double reorder_extra_delay_s = 0.05;  ///< hold-back of a reordered packet [s], ≥ 0
  std::uint64_t seed = 1;

  /// \brief Every number outside its range (faultChannelFields(), and duplicate_extra_delay_s
  /// >= 0), each "<key> must be ..., got v".
  std::vector<std::string> validate() const;
};

/// \brief The one range of each number of a link's faults, keyed as a mission's link sections
/// write them: delay_s, jitter_s, loss, duplicate, reorder, reorder_extra_delay_s. (The
/// simulator sets duplicate_extra_delay_s to delay_s; seed is not a setting.)
const common::FieldTable<FaultChannelConfig>& faultChannelFields();

/// \brief What happened on a channel so far.
struct FaultChannelStats {
  std::uint64_t sent = 0;        ///< send() calls
  std::uint64_t lost = 0;        ///< packets dropped
  std::uint64_t duplicated = 0;  ///< extra copies scheduled
  std::uint64_t reordered = 0;   ///< packets held back on purpose
  std::uint64_t delivered = 0;   ///< copies returned by poll()
  std::size_t in_flight = 0;     ///< copies scheduled, not yet delivered
};

template <class Packet>
class FaultChannel {
 public:
  /// \brief Precondition: config.validate() is empty (invalid values are clamped into range).
  explicit FaultChannel(const FaultChannelConfig& config) : config_(sanitize(config)), rng_(config.seed) {}

  /// \brief Sends one packet at t_s (seconds, the simulation clock).
  void send(const Packet& packet, double t_s) {
    ++stats_.sent;
    // Always five draws, so that one outcome does not shift the random stream of the next.
    const double u_loss = uniform();
    const double u_jitter = uniform();
    const double u_reorder = uniform();
    const double u_duplicate = uniform();
    const double u_duplicate_jitter = uniform();
    if (u_loss < config_.loss_probability) {
      ++stats_.lost;
      return;
    }
    double t_deliver = t_s + config_.delay_s + config_.jitter_s * u_jitter;
    if (u_reorder < config_.reorder_probability) {
      t_deliver += config_.reorder_extra_delay_s;
      ++stats_.reordered;
    }
    push(packet, t_deliver);
    if (u_duplicate < config_.duplicate_probability) {
      ++stats_.duplicated;
      push(packet, t_deliver + config_.duplicate_extra_delay_s + config_.jitter_s * u_duplicate_jitter);
    }
  }

  /// \brief Every copy due by t_s, in delivery order.
  std::vector<Packet> poll(double t_s) {
    std::vector<Packet> out;
    while (!queue_.empty() && queue_.top().t_deliver_s <= t_s) {
      out.push_back(queue_.top().packet);
      queue_.pop();
    }
    stats_.delivered += out.size();
    stats_.in_flight = queue_.size();
    return out;
  }

  /// \brief Delivery time of the next copy, or +inf when none is in flight.
  double nextDeliveryTime() const {
    return queue_.empty() ? std::numeric_limits<double>::infinity() : queue_.top().t_deliver_s;
  }
  const FaultChannelStats& stats() const { return stats_; }
  const FaultChannelConfig& config() const { return config_; }

 private:
  struct InFlight {
    double t_deliver_s;
    std::uint64_t order;  ///< scheduling order: breaks ties deterministically
    Packet packet;
  };
  struct Later {
    bool operator()(const InFlight& a, const InFlight& b) const {
      if (a.t_deliver_s != b.t_deliver_s) return a.t_deliver_s > b.t_deliver_s;
      return a.order > b.order;
    }
  };

  static FaultChannelConfig sanitize(FaultChannelConfig c) {
    auto clamp01 = [](double p) { return p >= 0.0 ? (p <= 1.0 ? p : 1.0) : 0.0; };  // NaN → 0
    auto clampNonneg = [](double v) { return std::isfinite(v) && v > 0.0 ? v : 0.0; };
    c.loss_probability = clamp01(c.loss_probability);
    c.duplicate_probability = clamp01(c.duplicate_probability);
    c.reorder_probability = clamp01(c.reorder_probability);
    c.delay_s = clampNonneg(c.delay_s);
    c.jitter_s = clampNonneg(c.jitter_s);
    c.duplicate_extra_delay_s = clampNonneg(c.duplicate_extra_delay_s);
    c.reorder_extra_delay_s = clampNonneg(c.reorder_extra_delay_s);
    return c;
  }

  /// Uniform in [0, 1) from the top 53 bits (exact, portable).
  double uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }

  void push(const Packet& packet, double t_deliver_s) {
    queue_.push(InFlight{t_deliver_s, next_order_++, packet});
    stats_.in_flight = queue_.size();
  }

  FaultChannelConfig config_;
  std::mt19937_64 rng_;
  std::priority_queue<InFlight, std::vector<InFlight>, Later> queue_;
  std::uint64_t next_order_ = 0;
  FaultChannelStats stats_;
};

}  // namespace gesture_formation::comm

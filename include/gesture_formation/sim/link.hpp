#pragma once
/// \file
/// \brief A one-way message link between simulated UAVs (or from the operator), built on
/// comm::FaultChannel (the fault model of the comm layer, docs/security.md §8), so that the
/// simulator and the comm tests share one definition of loss, delay, jitter, duplication and
/// reordering. Per message: lost with probability `loss`; else it arrives after `delay_s` plus
/// a uniform jitter in [0, jitter_s); with probability `reorder` it is held back another
/// `reorder_extra_delay_s` (later messages overtake it); with probability `duplicate` a second
/// copy arrives (at least `delay_s` after the first). Delivery is in arrival-time order (ties:
/// send order), so jitter and hold-back reorder. Issue 9 fault hooks (`mission.links`,
/// `mission.faults.link`; docs/simulation.md). Default: a clean 20 ms link.
/// Deterministic for its RNG. Thread safety: none.

#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "gesture_formation/comm/fault_channel.hpp"
#include "gesture_formation/common/config_fields.hpp"

namespace gesture_formation::sim {

struct LinkConfig {
  double delay_s = 0.02;                ///< ≥ 0
  double jitter_s = 0.0;                ///< ≥ 0
  double loss = 0.0;                    ///< [0, 1]
  double duplicate = 0.0;               ///< [0, 1]
  double reorder = 0.0;                 ///< [0, 1]: probability a message is held back
  double reorder_extra_delay_s = 0.2;   ///< hold-back of a reordered message [s], ≥ 0
  std::vector<std::string> validate(const std::string& prefix = "") const;
};

/// \brief The one range of each number of LinkConfig: mission.links.uav / .operator and mission.faults.link / .operator_link.
const common::FieldTable<LinkConfig>& linkConfigFields();

struct LinkCounters {
  std::uint64_t sent = 0, lost = 0, duplicated = 0, reordered = 0, delivered = 0;
};

template <class T>
class Link {
 public:
  Link(const LinkConfig& config, std::mt19937_64 rng) : channel_(toChannel(config, rng())) {}

  /// \brief Sends `msg` at `t_s`.
  void send(double t_s, const T& msg) { channel_.send(msg, t_s); }

  /// \brief Every message that has arrived by `t_s`, in arrival order.
  std::vector<T> receive(double t_s) { return channel_.poll(t_s); }

  LinkCounters counters() const {
    const comm::FaultChannelStats& s = channel_.stats();
    return LinkCounters{s.sent, s.lost, s.duplicated, s.reordered, s.delivered};
  }

 private:
  static comm::FaultChannelConfig toChannel(const LinkConfig& c, std::uint64_t seed) {
    comm::FaultChannelConfig f;
    f.loss_probability = c.loss;
    f.delay_s = c.delay_s;
    f.jitter_s = c.jitter_s;
    f.duplicate_probability = c.duplicate;
    f.duplicate_extra_delay_s = c.delay_s;
    f.reorder_probability = c.reorder;
    f.reorder_extra_delay_s = c.reorder_extra_delay_s;
    f.seed = seed;
    return f;
  }
  comm::FaultChannel<T> channel_;
};

}  // namespace gesture_formation::sim

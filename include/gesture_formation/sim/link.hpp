#pragma once
/// \file
/// \brief A one-way message link between simulated UAVs (or from the operator), built on
/// comm::FaultChannel (the fault model of the comm layer, docs/security.md §8), so that the
/// simulator and the comm tests share one definition of loss, delay, jitter, duplication and
/// reordering. Per message: lost with probability `loss` (loss_probability); else it arrives after `delay_s` plus
/// a uniform jitter in [0, jitter_s); with probability `reorder` (reorder_probability) it is held back another
/// `reorder_extra_delay_s` (later messages overtake it); with probability `duplicate` (duplicate_probability) a second
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

namespace gesture_formation::sim {

/// \brief A link's faults: comm::FaultChannelConfig with the simulator's defaults (a clean 20 ms
/// link; a reordered message held back 0.2 s); ranges and keys: comm::faultChannelFields().
struct LinkConfig : comm::FaultChannelConfig {
  LinkConfig() {
    delay_s = 0.02;
    reorder_extra_delay_s = 0.2;
  }
  std::vector<std::string> validate(const std::string& prefix = "") const {
    std::vector<std::string> e = comm::FaultChannelConfig::validate();
    for (auto& line : e) line = prefix + line;
    return e;
  }
};

/// \brief The operator's link by default: 100 ms, otherwise clean.
inline LinkConfig operatorLinkDefaults() {
  LinkConfig c;
  c.delay_s = 0.1;
  return c;
}

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
    comm::FaultChannelConfig f = c;
    f.duplicate_extra_delay_s = c.delay_s;  // a duplicate arrives at least a link delay after the first copy
    f.seed = seed;
    return f;
  }
  comm::FaultChannel<T> channel_;
};

}  // namespace gesture_formation::sim

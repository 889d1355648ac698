#pragma once
/// \file
/// \brief A one-way message link between simulated UAVs (or from the operator): each message
/// arrives after `delay_s` plus a uniform jitter in [0, jitter_s], or is lost with
/// probability `loss`, or arrives twice with probability `duplicate` (the copy `delay_s`
/// later). Delivery is in arrival-time order (ties: send order), so jitter can reorder.
/// This is the fault-injection hook of issue 9 (loss, delay, jitter, duplication); the default
/// is a clean 20 ms link. Deterministic for its RNG. Thread safety: none.

#include <cstdint>
#include <map>
#include <random>
#include <string>
#include <utility>
#include <vector>

namespace gesture_formation::sim {

struct LinkConfig {
  double delay_s = 0.02;   ///< ≥ 0
  double jitter_s = 0.0;   ///< ≥ 0
  double loss = 0.0;       ///< [0, 1]
  double duplicate = 0.0;  ///< [0, 1]
  std::vector<std::string> validate(const std::string& prefix = "") const;
};

struct LinkCounters {
  std::uint64_t sent = 0, lost = 0, duplicated = 0, delivered = 0;
};

template <class T>
class Link {
 public:
  Link(const LinkConfig& config, std::mt19937_64 rng) : config_(config), rng_(std::move(rng)) {}

  /// \brief Sends `msg` at `t_s`.
  void send(double t_s, const T& msg) {
    std::uniform_real_distribution<double> u01(0.0, 1.0);
    ++counters_.sent;
    const double lost = u01(rng_), jitter = u01(rng_), dup = u01(rng_);
    if (lost < config_.loss) {
      ++counters_.lost;
      return;
    }
    const double arrive = t_s + config_.delay_s + jitter * config_.jitter_s;
    queue_.emplace(std::make_pair(arrive, order_++), msg);
    if (dup < config_.duplicate) {
      ++counters_.duplicated;
      queue_.emplace(std::make_pair(arrive + config_.delay_s, order_++), msg);
    }
  }

  /// \brief Every message that has arrived by `t_s`, in arrival order.
  std::vector<T> receive(double t_s) {
    std::vector<T> out;
    while (!queue_.empty() && queue_.begin()->first.first <= t_s) {
      out.push_back(queue_.begin()->second);
      queue_.erase(queue_.begin());
      ++counters_.delivered;
    }
    return out;
  }

  const LinkCounters& counters() const { return counters_; }

 private:
  LinkConfig config_;
  std::mt19937_64 rng_;
  std::multimap<std::pair<double, std::uint64_t>, T> queue_;
  std::uint64_t order_ = 0;
  LinkCounters counters_;
};

}  // namespace gesture_formation::sim

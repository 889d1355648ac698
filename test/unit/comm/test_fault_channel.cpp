#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <vector>

#include "gesture_formation/comm/fault_channel.hpp"

using namespace gesture_formation::comm;

namespace {

struct Packet {
  int id;
  double t_sent;
};

/// Sends n packets every period_s and collects everything delivered (polling every period).
std::vector<std::pair<Packet, double>> run(FaultChannel<Packet>& ch, int n, double period_s) {
  std::vector<std::pair<Packet, double>> out;
  double t = 0.0;
  for (int i = 0; i < n; ++i, t += period_s) {
    ch.send(Packet{i, t}, t);
    for (const Packet& p : ch.poll(t)) out.push_back({p, t});
  }
  for (const Packet& p : ch.poll(1e9)) out.push_back({p, 1e9});
  return out;
}

/// |x − n p| ≤ 5 σ of a binomial (false positive ~6e-7 per check; fixed seed anyway).
void expectBinomial(std::uint64_t x, std::uint64_t n, double p, const char* what) {
  const double mean = static_cast<double>(n) * p;
  const double sigma = std::sqrt(static_cast<double>(n) * p * (1.0 - p));
  EXPECT_LE(std::abs(static_cast<double>(x) - mean), 5.0 * sigma) << what << ": " << x << " of " << n;
}

}  // namespace

TEST(CommFaultChannelTest, PerfectLinkDeliversEverythingInOrder) {
  FaultChannel<Packet> ch(FaultChannelConfig{});
  const auto out = run(ch, 1000, 0.01);
  ASSERT_EQ(out.size(), 1000u);
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(out[static_cast<std::size_t>(i)].first.id, i);
  EXPECT_EQ(ch.stats().delivered, 1000u);
  EXPECT_EQ(ch.stats().in_flight, 0u);
}

TEST(CommFaultChannelTest, LossRateWithinBinomialBounds) {
  for (double p : {0.1, 0.3, 0.5}) {
    FaultChannelConfig c;
    c.loss_probability = p;
    c.seed = 1234;
    FaultChannel<Packet> ch(c);
    const int n = 100000;
    const auto out = run(ch, n, 0.001);
    expectBinomial(ch.stats().lost, n, p, "lost");
    EXPECT_EQ(out.size() + ch.stats().lost, static_cast<std::size_t>(n));
  }
}

TEST(CommFaultChannelTest, DelayAndJitterBounds) {
  FaultChannelConfig c;
  c.delay_s = 0.05;
  c.jitter_s = 0.02;
  c.seed = 5;
  FaultChannel<Packet> ch(c);
  double t = 0.0;
  double min_latency = 1e9, max_latency = 0.0;
  for (int i = 0; i < 20000; ++i, t += 0.001) {
    ch.send(Packet{i, t}, t);
    for (const Packet& p : ch.poll(t)) {
      const double latency = t - p.t_sent;  // polled at most 1 ms late
      min_latency = std::min(min_latency, latency);
      max_latency = std::max(max_latency, latency);
    }
  }
  EXPECT_GE(min_latency, 0.05 - 1e-9);
  EXPECT_LE(max_latency, 0.05 + 0.02 + 0.001 + 1e-9);
  EXPECT_GT(max_latency - min_latency, 0.015);  // jitter is used
}

TEST(CommFaultChannelTest, DuplicationRateAndCopiesFollowTheOriginal) {
  FaultChannelConfig c;
  c.duplicate_probability = 0.2;
  c.duplicate_extra_delay_s = 0.003;
  c.seed = 77;
  FaultChannel<Packet> ch(c);
  const int n = 50000;
  const auto out = run(ch, n, 0.001);
  expectBinomial(ch.stats().duplicated, n, 0.2, "duplicated");
  EXPECT_EQ(out.size(), n + ch.stats().duplicated);
  std::map<int, int> copies;
  std::map<int, std::size_t> first_index;
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (copies[out[i].first.id]++ == 0) first_index[out[i].first.id] = i;
  }
  for (const auto& [id, k] : copies) EXPECT_LE(k, 2) << id;
  // Without jitter and reordering the originals stay in order.
  int last = -1;
  for (const auto& [id, idx] : first_index) {
    (void)idx;
    EXPECT_GT(id, last);
    last = id;
  }
}

TEST(CommFaultChannelTest, ReorderingLetsLaterPacketsOvertake) {
  FaultChannelConfig c;
  c.reorder_probability = 0.1;
  c.reorder_extra_delay_s = 0.0105;  // overtaken by the next ~10 packets sent every 1 ms
  c.seed = 9;
  FaultChannel<Packet> ch(c);
  const int n = 50000;
  const auto out = run(ch, n, 0.001);
  ASSERT_EQ(out.size(), static_cast<std::size_t>(n));
  expectBinomial(ch.stats().reordered, n, 0.1, "reordered");
  // Count packets delivered after a higher id: each held-back packet not itself
  // followed by another held-back one is overtaken.
  std::uint64_t inversions = 0;
  int max_id = -1;
  for (const auto& [p, t] : out) {
    (void)t;
    if (p.id < max_id) ++inversions;
    max_id = std::max(max_id, p.id);
  }
  EXPECT_GT(inversions, ch.stats().reordered / 2);
  EXPECT_LE(inversions, ch.stats().reordered);
}

TEST(CommFaultChannelTest, DeterministicForASeed) {
  FaultChannelConfig c;
  c.loss_probability = 0.3;
  c.delay_s = 0.02;
  c.jitter_s = 0.03;
  c.duplicate_probability = 0.1;
  c.reorder_probability = 0.05;
  c.seed = 2024;
  FaultChannel<Packet> a(c), b(c);
  const auto out_a = run(a, 5000, 0.002);
  const auto out_b = run(b, 5000, 0.002);
  ASSERT_EQ(out_a.size(), out_b.size());
  for (std::size_t i = 0; i < out_a.size(); ++i) {
    EXPECT_EQ(out_a[i].first.id, out_b[i].first.id);
    EXPECT_EQ(out_a[i].second, out_b[i].second);
  }
  c.seed = 2025;
  FaultChannel<Packet> other(c);
  const auto out_c = run(other, 5000, 0.002);
  bool differs = out_c.size() != out_a.size();
  for (std::size_t i = 0; !differs && i < out_a.size(); ++i) differs = out_a[i].first.id != out_c[i].first.id;
  EXPECT_TRUE(differs);
}

TEST(CommFaultChannelTest, RegressionFiguresForSeedOne) {
  // Pins the random stream (mt19937_64 is fixed by the standard): a change here changes every
  // simulation that uses the channel. The delivered ids were recorded once from the channel
  // (5 draws per packet, loss on the first) and are kept as literals, not recomputed here.
  FaultChannelConfig c;
  c.loss_probability = 0.5;
  c.seed = 1;
  FaultChannel<Packet> ch(c);
  std::vector<int> delivered;
  for (int i = 0; i < 16; ++i) ch.send(Packet{i, 0.0}, 0.0);
  for (const Packet& p : ch.poll(0.0)) delivered.push_back(p.id);
  EXPECT_EQ(delivered, (std::vector<int>{1, 6, 7, 8, 9, 10, 13, 14, 15}));
}

TEST(CommFaultChannelTest, ValidateNamesFields) {
  FaultChannelConfig c;
  c.loss_probability = 1.5;
  c.jitter_s = -1;
  c.reorder_probability = std::nan("");
  const auto e = c.validate();
  // Named by the keys a mission's link sections write (comm::faultChannelFields(), in its order).
  ASSERT_EQ(e.size(), 3u);
  EXPECT_EQ(e[0], "jitter_s must be >= 0, got -1");
  EXPECT_EQ(e[1], "loss must be in [0, 1], got 1.5");
  EXPECT_NE(e[2].find("reorder must be in [0, 1], got"), std::string::npos) << e[2];
}

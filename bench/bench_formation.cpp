// Benchmarks of the formation core and the gesture filter (docs/design.md §7 budget: formation
// references for 3 UAVs over a 40-step horizon < 50 µs). Prints Google Benchmark's table; run
// with --benchmark_repetitions=5 --benchmark_report_aggregates_only=true for medians.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "gesture_formation/formation/formation_commands.hpp"
#include "gesture_formation/formation/formation_geometry.hpp"
#include "gesture_formation/gesture/gesture_filter.hpp"

using namespace gesture_formation;

namespace {

formation::WorkerHorizon workerHorizon(int steps) {
  formation::WorkerHorizon w;
  w.p_world.resize(3, steps);
  w.heading_rad.resize(1, steps);
  for (int k = 0; k < steps; ++k) {
    w.p_world.col(k) = Eigen::Vector3d(0.2 * 0.5 * k, 0.1 * k, 12.0);  // 0.2 s steps, walking
    w.heading_rad(k) = 0.3;
  }
  return w;
}

/// The planner's per-replanning call: leader + followers over the horizon, no plan.
void BM_FormationHorizon(benchmark::State& state) {
  const int steps = static_cast<int>(state.range(0));
  const formation::WorkerHorizon w = workerHorizon(steps);
  formation::FormationParams params;  // Table II: leader + 2 followers
  std::vector<formation::ReferenceTrajectory> out;
  formation::formationHorizon(w, params, nullptr, out);  // allocate once
  for (auto _ : state) {
    formation::formationHorizon(w, params, nullptr, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * steps * params.uavCount());
}
BENCHMARK(BM_FormationHorizon)->Arg(40)->ArgName("steps");

/// Followers relative to the leader's planned heading and pitch (received over LCM).
void BM_FormationHorizonWithLeaderPlan(benchmark::State& state) {
  const formation::WorkerHorizon w = workerHorizon(40);
  formation::LeaderPlan plan;
  plan.heading_rad = formation::HorizonScalars::Constant(1, 40, -1.2);
  plan.pitch_rad = formation::HorizonScalars::Constant(1, 40, -0.19);
  const formation::FormationParams params;
  std::vector<formation::ReferenceTrajectory> out;
  formation::formationHorizon(w, params, &plan, out);
  for (auto _ : state) {
    formation::formationHorizon(w, params, &plan, out);
    benchmark::DoNotOptimize(out.data());
    benchmark::ClobberMemory();
  }
}
BENCHMARK(BM_FormationHorizonWithLeaderPlan);

/// One gesture classifier output through the filter (default K = 20), a noisy bursty stream.
void BM_GestureFilterUpdate(benchmark::State& state) {
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> id(0, 4);
  std::vector<int> ids(4096);
  for (std::size_t i = 0; i < ids.size(); ++i) ids[i] = (i / 64) % 2 == 0 ? 3 : id(rng);
  gesture::GestureFilter filter{gesture::GestureFilterConfig{}};
  double t = 0.0;
  std::size_t i = 0;
  for (auto _ : state) {
    t += 0.05;
    benchmark::DoNotOptimize(filter.update(t, ids[i++ & 4095]).fired);
  }
}
BENCHMARK(BM_GestureFilterUpdate);

/// One command applied to all UAVs (clamping + duplicate window).
void BM_ApplyCommandAll(benchmark::State& state) {
  auto fs = formation::FormationState::create(formation::FormationParams{}, formation::FormationLimits{}).value();
  formation::FormationCommand c;
  c.id.sender = "operator";
  c.target = formation::CommandTarget::all();
  c.parameter = formation::Parameter::kDistance;
  std::uint64_t seq = 0;
  for (auto _ : state) {
    c.id.sequence = ++seq;
    c.amount = (seq & 1) ? 1.0 : -1.0;
    benchmark::DoNotOptimize(fs.apply(c).status);
  }
}
BENCHMARK(BM_ApplyCommandAll);

}  // namespace

BENCHMARK_MAIN();

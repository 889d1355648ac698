// Benchmarks of the planning world model and corridors (docs/design.md §7 budget: corridor
// decomposition along a 40 m path in the tower map < 2 ms). Prints Google Benchmark's table;
// run with --benchmark_repetitions=10 --benchmark_report_aggregates_only=true for medians.
// Figures and the clearance-query decision: docs/planning.md.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <random>

#include "gesture_formation/planning/corridor_builder.hpp"
#include "gesture_formation/planning/distance_field.hpp"
#include "gesture_formation/planning/occupancy_map.hpp"
#include "gesture_formation/planning/scenario.hpp"

using namespace gesture_formation::planning;

namespace {

std::string scenarioPath() {
  const char* src = std::getenv("GF_SOURCE_DIR");
  return std::string(src ? src : ".") + "/config/scenarios/power_towers.yaml";
}

const Scenario& towers() {
  static const Scenario s = [] {
    auto r = loadScenario(scenarioPath());
    if (!r) {
      std::fprintf(stderr, "cannot load %s (run from the source tree or set GF_SOURCE_DIR):\n%s", scenarioPath().c_str(),
                   r.reason().c_str());
      std::exit(2);
    }
    return *r;
  }();
  return s;
}

const OccupancyMap& towerMap() {
  static const OccupancyMap m = *OccupancyMap::fromScenario(towers());
  return m;
}

/// Random query points in the tower map's free space region (fixed seed).
std::vector<Eigen::Vector3d> queryPoints(std::size_t n) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> X(-10, 60), Y(-14, 14), Z(0.5, 34);
  std::vector<Eigen::Vector3d> p;
  for (std::size_t i = 0; i < n; ++i) p.emplace_back(X(rng), Y(rng), Z(rng));
  return p;
}

/// A 40 m path of 8 segments weaving between the conductors and past the west tower.
std::vector<Eigen::Vector3d> path40m() {
  return {Eigen::Vector3d(-8, -10, 8),  Eigen::Vector3d(-4, -8, 12), Eigen::Vector3d(2, -9, 14.5),
          Eigen::Vector3d(7, -7.5, 14), Eigen::Vector3d(12, -6, 17.5), Eigen::Vector3d(17, -3, 19),
          Eigen::Vector3d(21, -1, 20.2), Eigen::Vector3d(24, 2, 21), Eigen::Vector3d(27, 4, 24)};
}

void BM_MapBuildPowerTowers(benchmark::State& state) {
  const Scenario& s = towers();
  for (auto _ : state) benchmark::DoNotOptimize(OccupancyMap::fromScenario(s));
  state.counters["voxels"] = static_cast<double>(towerMap().occupiedCount());
}
BENCHMARK(BM_MapBuildPowerTowers)->Unit(benchmark::kMillisecond);

void BM_DistanceFieldBuild(benchmark::State& state) {
  const OccupancyMap& m = towerMap();
  for (auto _ : state) benchmark::DoNotOptimize(DistanceField(m));
  state.counters["MB"] = DistanceField(m).memoryBytes() / 1e6;
}
BENCHMARK(BM_DistanceFieldBuild)->Unit(benchmark::kMillisecond);

void BM_ClearanceDistanceField(benchmark::State& state) {
  const DistanceField field(towerMap());
  const auto pts = queryPoints(4096);
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(field.clearance(pts[i++ & 4095]));
}
BENCHMARK(BM_ClearanceDistanceField);

void BM_ClearanceFcl(benchmark::State& state) {
  const FclClearance fcl(towerMap());
  const auto pts = queryPoints(4096);
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(fcl.clearance(pts[i++ & 4095]));
}
BENCHMARK(BM_ClearanceFcl)->Unit(benchmark::kMicrosecond);

void BM_CollisionFclBall(benchmark::State& state) {
  const FclClearance fcl(towerMap());
  const auto pts = queryPoints(4096);
  std::size_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(fcl.collides(pts[i++ & 4095], 0.5));
}
BENCHMARK(BM_CollisionFclBall)->Unit(benchmark::kMicrosecond);

/// arg 0: the path above; arg 1: the same path 2.5-4 m above the ground (ground points in
/// every local box).
void BM_CorridorPath40m(benchmark::State& state) {
  CorridorConfig cfg;
  cfg.clearance_m = 0.5;
  const CorridorBuilder builder(cfg);
  const OccupancyMap& m = towerMap();
  auto path = path40m();
  if (state.range(0) == 1) {
    for (std::size_t i = 0; i < path.size(); ++i) path[i].z() = 2.5 + 0.2 * static_cast<double>(i);
  }
  double length = 0.0;
  for (std::size_t i = 1; i < path.size(); ++i) length += (path[i] - path[i - 1]).norm();
  std::size_t planes = 0, points = 0;
  for (auto _ : state) {
    const auto c = builder.buildPath(path, m);
    if (!c) {
      state.SkipWithError(c.reason().c_str());
      break;
    }
    planes = points = 0;
    for (const auto& s : *c) planes += static_cast<std::size_t>(s.polytope.rows()), points += s.obstacle_points;
    benchmark::DoNotOptimize(planes);
  }
  state.counters["path_m"] = length;
  state.counters["segments"] = static_cast<double>(path.size() - 1);
  state.counters["planes"] = static_cast<double>(planes);
  state.counters["points"] = static_cast<double>(points);
}
BENCHMARK(BM_CorridorPath40m)->Arg(0)->Arg(1)->ArgName("low")->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();

// Benchmark of the worker estimator (docs/design.md §7 budget: one predict+update < 5 µs).
// Prints Google Benchmark's table; run with --benchmark_repetitions=10
// --benchmark_report_aggregates_only=true for medians.
#include <benchmark/benchmark.h>

#include "gesture_formation/estimation/human_kalman.hpp"
#include "gesture_formation/estimation/measurement_model.hpp"

using namespace gesture_formation::estimation;

namespace {

CameraPose pose() {
  CameraPose p;
  p.t_world_camera = Eigen::Vector3d(-10, 0, 3);
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  p.q_world_camera = Eigen::Quaterniond(R);
  return p;
}

void BM_PredictUpdate(benchmark::State& state) {
  HumanKalman kf;
  PositionMeasurement m;
  m.sigma_world = Eigen::Matrix3d::Identity() * 0.01;
  double t = 0.0;
  kf.step(t, m);
  for (auto _ : state) {
    t += 0.033;
    m.z_world.x() = 0.01 * std::sin(t);
    benchmark::DoNotOptimize(kf.step(t, m));
  }
}
BENCHMARK(BM_PredictUpdate);

void BM_MeasurementPlusPredictUpdate(benchmark::State& state) {
  CameraIntrinsics k;
  if (state.range(0) != 0) k.distortion = {0.1, -0.2, 0.001, 0.001, 0.05};
  const CameraModel cam(k);
  const MeasurementNoise noise;
  const CameraPose p = pose();
  HumanKalman kf;
  double t = 0.0;
  for (auto _ : state) {
    t += 0.033;
    const Box box{300.0 + std::sin(t), 200.0, 30.0, 100.0};
    const auto m = makeMeasurement(cam, p, box, std::nan(""), std::nan(""), 1.75, noise, 40.0);
    benchmark::DoNotOptimize(kf.step(t, *m));
  }
}
BENCHMARK(BM_MeasurementPlusPredictUpdate)->Arg(0)->Arg(1)->ArgName("distortion");

void BM_PredictTrajectory40(benchmark::State& state) {
  HumanKalman kf;
  PositionMeasurement m;
  m.sigma_world = Eigen::Matrix3d::Identity() * 0.01;
  kf.step(0.0, m);
  for (auto _ : state) benchmark::DoNotOptimize(kf.predictTrajectory(0.1, 0.2, 40));
}
BENCHMARK(BM_PredictTrajectory40);

}  // namespace

BENCHMARK_MAIN();

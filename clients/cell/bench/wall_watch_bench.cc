// Cost of the cell controller's wall watch: one pass over a scan's cloud per tube the scan before
// showed hanging over a wall (PointsNear), on a cloud of the scanner's size (2.3 M points).
//
//   cell_bench --benchmark_repetitions=7 --benchmark_report_aggregates_only=true

#include <random>

#include <benchmark/benchmark.h>

#include "clients/cell/wall_watch.h"

namespace tubepick::cell {
namespace {

/// 2.3 M points spread over the bin as the default sensor (1.1 m above the floor) sees it.
devices::Capture BinCloud() {
  devices::Capture capture;
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> x(-0.4f, 0.4f), y(-0.3f, 0.3f), z(0.85f, 1.1f);
  capture.points_Sensor.reserve(2'300'000);
  for (int i = 0; i < 2'300'000; ++i) capture.points_Sensor.emplace_back(x(rng), y(rng), z(rng));
  return capture;
}

void BM_PointsNearOneWatchedTube(benchmark::State& state) {
  const devices::Capture capture = BinCloud();
  const BinConfig bin;
  for (auto _ : state) benchmark::DoNotOptimize(PointsNear(capture, {-0.03, -0.30, 0.22}, 0.03, bin));
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(capture.points_Sensor.size()));
}
BENCHMARK(BM_PointsNearOneWatchedTube)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace tubepick::cell

BENCHMARK_MAIN();

// Benchmarks of the Bullet trajectory evaluator on a generated 10-tube scene (ground-truth tubes).
// Run with --benchmark_repetitions=5 --benchmark_report_aggregates_only=true for medians.
// Counter x_realtime: simulated seconds per wall-clock second.
#include <cstdint>
#include <ctime>
#include <vector>

#include <benchmark/benchmark.h>

#include "physics/scene_generator.h"
#include "physics/trajectory_simulator.h"

namespace tubepick::physics {
namespace {

constexpr std::uint64_t kSceneSeed = 1;
constexpr double kLift = 0.4;

const std::vector<Tube>& TenTubes() {
  static const std::vector<Tube> tubes = [] {
    SceneParams params;  // 10 tubes of set A
    std::vector<Tube> out;
    for (const TubeGeometry& g : GenerateScene(params, kSceneSeed).tubes) out.push_back(g.ToTube());
    return out;
  }();
  return tubes;
}

Trajectory Upward(std::uint32_t tube_index) {
  Trajectory t;
  t.tube_index = tube_index;
  t.waypoints = {Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, kLift)};
  return t;
}

Trajectory Escape(std::uint32_t tube_index, const Eigen::Vector3d& direction) {
  Trajectory t;
  t.tube_index = tube_index;
  t.kind = TrajectoryKind::kEscape;
  t.escape_direction = direction;
  t.waypoints = {Eigen::Vector3d::Zero(),
                 {0, 0, 0.02},
                 Eigen::Vector3d(0, 0, 0.02) + 0.1 * direction,
                 Eigen::Vector3d(0, 0, 0.02 + kLift) + 0.1 * direction};
  return t;
}

TrajectorySimParams Params(int threads) {
  TrajectorySimParams params;
  params.threads = threads;
  return params;
}

/// The whole Evaluate call (settle + one 0.4 m lift at 0.1 m/s = 4 s of motion) on one core.
void BM_EvaluateOneUpward(benchmark::State& state) {
  const std::vector<Tube>& tubes = TenTubes();
  BulletTrajectoryEvaluator evaluator(Params(1));
  const std::vector<Trajectory> trajectories = {Upward(static_cast<std::uint32_t>(state.range(0)))};
  double simulated = 0.0, displacement = 0.0;
  for (auto _ : state) {
    const std::vector<TrajectoryOutcome> out = evaluator.Evaluate(tubes, trajectories, 1, nullptr);
    simulated += out[0].simulated_time;
    displacement = out[0].displacement;
  }
  state.counters["x_realtime"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
  state.counters["disp_m"] = displacement;
}
BENCHMARK(BM_EvaluateOneUpward)->Arg(0)->Arg(9)->Unit(benchmark::kMillisecond)->UseRealTime();

/// Settling the 10 tubes into the snapshot (once per Evaluate call).
void BM_Settle(benchmark::State& state) {
  const std::vector<Tube>& tubes = TenTubes();
  const TrajectorySimParams params = Params(1);
  double seconds = 0.0;
  for (auto _ : state) {
    const SettledTubes settled(tubes, params, nullptr);
    seconds = settled.settle_seconds();
    benchmark::DoNotOptimize(settled.X_BinC().data());
  }
  state.counters["settle_s"] = seconds;
}
BENCHMARK(BM_Settle)->Unit(benchmark::kMillisecond)->UseRealTime();

/// One trajectory from the snapshot (fresh world + 4 s lift + 0.5 s hold), settle excluded.
void BM_RunOneUpward(benchmark::State& state) {
  const SettledTubes settled(TenTubes(), Params(1), nullptr);
  const Trajectory trajectory = Upward(static_cast<std::uint32_t>(state.range(0)));
  double simulated = 0.0;
  for (auto _ : state) simulated += settled.Run(trajectory, nullptr).outcome.simulated_time;
  state.counters["x_realtime"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RunOneUpward)->Arg(0)->Arg(9)->Unit(benchmark::kMillisecond)->UseRealTime();

/// Restoring the snapshot: a fresh world with bin and 10 tubes, no step.
void BM_RestoreFreshWorld(benchmark::State& state) {
  TrajectorySimParams params = Params(1);
  params.post_motion_time = 0.0;
  const SettledTubes settled(TenTubes(), params, nullptr);
  Trajectory still;
  still.waypoints = {Eigen::Vector3d::Zero()};
  for (auto _ : state) benchmark::DoNotOptimize(settled.Run(still, nullptr).steps);
}
BENCHMARK(BM_RestoreFreshWorld)->Unit(benchmark::kMicrosecond)->UseRealTime();

/// 15 trajectories (10 upward, 5 escapes) on 1 and 2 worker threads, settle included.
void BM_EvaluateFifteen(benchmark::State& state) {
  const std::vector<Tube>& tubes = TenTubes();
  std::vector<Trajectory> trajectories;
  for (std::uint32_t i = 0; i < tubes.size(); ++i) trajectories.push_back(Upward(i));
  for (std::uint32_t i = 0; i < 5; ++i) {
    trajectories.push_back(Escape(i, i % 2 == 0 ? Eigen::Vector3d(1, 0, 0) : Eigen::Vector3d(0, -1, 0)));
  }
  BulletTrajectoryEvaluator evaluator(Params(static_cast<int>(state.range(0))));
  double simulated = 0.0;
  const std::clock_t cpu_start = std::clock();  // process CPU time: all worker threads
  for (auto _ : state) {
    for (const TrajectoryOutcome& o : evaluator.Evaluate(tubes, trajectories, 1, nullptr)) {
      simulated += o.simulated_time;
    }
  }
  const double cpu_all_threads = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  state.counters["x_realtime"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
  state.counters["cpu_ms_all_threads"] = 1e3 * cpu_all_threads / static_cast<double>(state.iterations());
}
BENCHMARK(BM_EvaluateFifteen)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace tubepick::physics

BENCHMARK_MAIN();

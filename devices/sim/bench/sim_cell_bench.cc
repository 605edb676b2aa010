// Speed of the simulated cell: simulated seconds per wall-clock second (the real-time factor) of a
// full pick cycle on a 7-tube bin, one core.
//
//   devices_sim_bench --benchmark_counters_tabular=true
//
// "sim_per_wall" is the real-time factor (> 1: faster than real time).

#include <algorithm>
#include <chrono>

#include <benchmark/benchmark.h>

#include "core/planning/grasp_synthesis.h"
#include "devices/sim/sim_cell.h"

namespace tubepick::devices::sim {
namespace {

constexpr Timeout kLong{std::chrono::seconds(120)};

/// The grasp at the middle of the flattest long cylinder of the highest tube.
Eigen::Isometry3d TopGrasp(const SimCell& cell) {
  const std::vector<physics::TubeGeometry> tubes = cell.TubesBin();
  const std::vector<Eigen::Vector3d> coms = cell.TubeCentresOfMass();
  const std::size_t top =
      std::max_element(coms.begin(), coms.end(), [](const auto& a, const auto& b) { return a.z() < b.z(); }) -
      coms.begin();
  const std::vector<Eigen::Vector3d> line = tubes[top].Centreline();
  Eigen::Isometry3d best = Eigen::Isometry3d::Identity();
  double flattest = 2.0;
  for (std::size_t i = 0; i + 1 < line.size(); ++i) {
    const Eigen::Vector3d axis = line[i + 1] - line[i];
    if (axis.norm() < 0.04) continue;
    if (std::abs(axis.normalized().z()) < flattest) {
      flattest = std::abs(axis.normalized().z());
      best = *GraspFrame(0.5 * (line[i] + line[i + 1]), axis);
    }
  }
  return best;
}

/// Scan (optional), approach from the start pose, grasp, lift 0.4 m, carry to the place frame,
/// open, return to the start pose: ≈ 2.3 m of TCP travel at 0.25 m/s.
void PickCycle(SimCell& cell, bool scan) {
  if (scan) benchmark::DoNotOptimize(cell.scanner().Scan(kLong));
  const Eigen::Isometry3d start = cell.X_BinTcp();
  const Eigen::Isometry3d grasp = TopGrasp(cell);
  Eigen::Isometry3d above = grasp;
  above.translation().z() += 0.1;
  cell.gripper().MoveTo(0.045, 0.1, 50.0, kLong);
  cell.robot().MoveTo(above, 0.25, kLong);
  cell.robot().MoveTo(grasp, 0.1, kLong);
  cell.gripper().Close(0.05, 50.0, kLong);
  benchmark::DoNotOptimize(cell.ft_sensor().Read(kLong));
  cell.robot().MoveThrough({Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.4)}, 0.25, kLong);
  benchmark::DoNotOptimize(cell.ft_sensor().Read(kLong));
  Eigen::Isometry3d place = cell.X_BinTcp();
  place.translation() = cell.cell().place.X_BinPlace.translation() + Eigen::Vector3d(0, 0, 0.35);
  cell.robot().MoveTo(place, 0.25, kLong);
  place.translation().z() -= 0.25;
  cell.robot().MoveTo(place, 0.25, kLong);
  cell.gripper().Open(kLong);
  cell.robot().MoveTo(start, 0.25, kLong);
}

void BM_PickCycle(benchmark::State& state) {
  const Material material = state.range(0) == 0 ? Material::kPvc : Material::kRubber;
  const bool scan = state.range(1) != 0;
  double simulated = 0.0;
  int faults = 0;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    state.PauseTiming();
    SimCellParams params = SimCellParams::Thesis(material, 7, seed++);
    params.cell.bin.inner_size = Eigen::Vector3d(0.77, 0.58, 0.09);  // the thesis' bin (§5.3.2)
    auto cell = std::make_unique<SimCell>(params);
    cell->robot().ServoOn(kLong);
    cell->gripper().Activate(kLong);
    cell->ft_sensor().Bias(kLong);
    const double t0 = cell->SimulatedSeconds();
    state.ResumeTiming();
    try {
      PickCycle(*cell, scan);
    } catch (const std::exception& e) {  // DeviceFault, DeviceTimeout: count it, keep measuring
      ++faults;
    }
    state.PauseTiming();
    simulated += cell->SimulatedSeconds() - t0;
    cell.reset();
    state.ResumeTiming();
  }
  state.SetLabel(ToString(material) + (scan ? " with scan" : " physics only"));
  state.counters["sim_s_per_cycle"] = simulated / state.iterations();
  state.counters["faults"] = faults;
  state.counters["sim_per_wall"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PickCycle)
    ->Args({0, 0})
    ->Args({1, 0})
    ->Args({0, 1})
    ->Args({1, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);

/// Construction: generate, drop (GenerateScene) and settle 7 tubes.
void BM_Construct(benchmark::State& state) {
  const Material material = state.range(0) == 0 ? Material::kPvc : Material::kRubber;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    SimCell cell(SimCellParams::Thesis(material, 7, seed++));
    benchmark::DoNotOptimize(cell.TubesInBin());
  }
  state.SetLabel(ToString(material));
}
BENCHMARK(BM_Construct)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace
}  // namespace tubepick::devices::sim

BENCHMARK_MAIN();

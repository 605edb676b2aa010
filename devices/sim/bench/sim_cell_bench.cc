// Speed of the simulated cell: simulated seconds per wall-clock second (the real-time factor) of a
// full pick cycle on a 7-tube bin, and on a dense bin of 20 branched trees (set C), one core.
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
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> pieces;
  if (tubes[top].IsLinear()) {
    const std::vector<Eigen::Vector3d> line = tubes[top].Centreline();
    for (std::size_t i = 0; i + 1 < line.size(); ++i) pieces.emplace_back(line[i], line[i + 1]);
  } else {
    for (const Cylinder& c : tubes[top].Cylinders()) pieces.emplace_back(c.start, c.end);
  }
  Eigen::Isometry3d best = Eigen::Isometry3d::Identity();
  double flattest = 2.0;
  for (const auto& [a, b] : pieces) {
    const Eigen::Vector3d axis = b - a;
    if (axis.norm() < 0.04) continue;
    if (std::abs(axis.normalized().z()) < flattest) {
      flattest = std::abs(axis.normalized().z());
      best = *GraspFrame(0.5 * (a + b), axis);
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

/// The thesis' cell with `material`'s tubes (7), or with `trees` set-C trees of that material
/// (0.75 m, its mass scaled from the thesis tube's by length).
SimCellParams BenchCell(Material material, std::uint32_t trees, std::uint64_t seed) {
  SimCellParams params = SimCellParams::Thesis(material, trees > 0 ? trees : 7, seed);
  params.cell.bin.inner_size = Eigen::Vector3d(0.77, 0.58, 0.09);  // the thesis' bin (§5.3.2)
  if (trees > 0) {
    physics::RandomTubeParams shape = physics::RandomTubeParams::SetC();
    shape.radius = params.cell.tube.radius;
    params.tube_shape = shape;
    params.cell.bin.inner_size.z() = 0.2;  // a 20-tree heap starts above the thesis' walls
    params.world_tube_mass = params.cell.tube.mass * 0.75 / params.cell.tube.length;
  }
  return params;
}

void BM_PickCycle(benchmark::State& state) {
  const Material material = state.range(0) == 0 ? Material::kPvc : Material::kRubber;
  const bool scan = state.range(1) != 0;
  const auto trees = static_cast<std::uint32_t>(state.range(2));
  double simulated = 0.0;
  int faults = 0;
  std::uint64_t seed = 1;
  for (auto _ : state) {
    state.PauseTiming();
    auto cell = std::make_unique<SimCell>(BenchCell(material, trees, seed++));
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
  state.SetLabel(ToString(material) + (trees > 0 ? ", " + std::to_string(trees) + " set-C trees" : "") +
                 (scan ? " with scan" : " physics only"));
  state.counters["sim_s_per_cycle"] = simulated / state.iterations();
  state.counters["faults"] = faults;
  state.counters["sim_per_wall"] = benchmark::Counter(simulated, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PickCycle)
    ->Args({0, 0, 0})
    ->Args({1, 0, 0})
    ->Args({0, 1, 0})
    ->Args({1, 1, 0})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);
// A dense heap of hoses (each trial builds and settles its bin first, untimed: about a minute).
BENCHMARK(BM_PickCycle)->Args({0, 0, 20})->Args({1, 0, 20})->Unit(benchmark::kSecond)->Iterations(2);

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

#include "clients/cli/cell/sim_round.h"

#include <chrono>
#include <optional>

#include <fmt/core.h>

#include "clients/cli/inputs/sim_scene.h"
#include "physics/random_tubes.h"

namespace tubepick::cli {
namespace {

constexpr double kRestAfterRound = 2.0;  // simulated seconds

}  // namespace

void WithShapes(const std::string& set, devices::sim::SimCellParams* p) {
  physics::RandomTubeParams shape = physics::RandomTubeParams::Preset(set);
  shape.radius = p->cell.tube.radius;
  if (shape.branches.size() == 1) {
    if (p->cell.tube.length > 0.0) shape.branches.front().length = p->cell.tube.length;
  } else {
    const CellConfig tree = CellForPreset(p->cell, set);
    if (p->cell.tube.length > 0.0) p->cell.tube.mass *= tree.tube.length / p->cell.tube.length;
    p->cell.tube.length = tree.tube.length;
    p->cell.tube.topology = tree.tube.topology;
    p->cell.tube.junction_shape = tree.tube.junction_shape;
    p->cell.tube.layout = tree.tube.layout;
  }
  p->tube_shape = shape;
}

SimRoundResult RunSimRound(cell::PlannerClient& planner, const devices::sim::SimCellParams& sim_params,
                           const cell::CellControllerParams& params, std::uint32_t round,
                           cell::RecordSink* sink) {
  const auto wall_start = std::chrono::steady_clock::now();
  devices::sim::SimCell sim(sim_params);
  SimRoundResult result = RunSimRound(planner, sim, params, round, sink);
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

SimRoundResult RunSimRound(cell::PlannerClient& planner, devices::sim::SimCell& sim,
                           const cell::CellControllerParams& params, std::uint32_t round,
                           cell::RecordSink* sink, std::function<void(cell::CellState)> observer,
                           OperatorStop* stop) {
  const auto wall_start = std::chrono::steady_clock::now();
  cell::CellController controller({&sim.scanner(), &sim.robot(), &sim.gripper(), &sim.ft_sensor()}, planner,
                                  sim.cell(), params, sink);
  controller.set_device_clock([&sim] { return sim.SimulatedSeconds(); });
  controller.set_annotator([&sim] {
    nlohmann::json truth{{"tubes_in_bin", sim.TubesInBin()},
                         {"tubes_outside_bin", sim.TubesOutsideBin()},
                         {"tubes_elsewhere", sim.TubesElsewhere()},
                         {"held", sim.HeldTubes().size()},
                         {"sim_seconds", sim.SimulatedSeconds()}};
    if (const std::size_t thrown = sim.runaways().size(); thrown > 0) truth["runaways"] = thrown;
    return truth;
  });
  if (observer) controller.set_state_observer(std::move(observer));
  SimRoundResult result;
  {
    std::optional<OperatorStop::Watch> watch;
    if (stop) watch.emplace(*stop, controller);
    result.run = controller.Run(round);
  }
  sim.Advance(kRestAfterRound);  // what fell comes to rest before it is counted
  result.tubes_in_bin = sim.TubesInBin();
  result.tubes_outside_bin = sim.TubesOutsideBin();
  result.tubes_in_place_zone = sim.TubesInPlaceZone();
  result.tubes_elsewhere = sim.TubesElsewhere();
  result.tubes_held = static_cast<std::uint32_t>(sim.HeldTubes().size());
  // Carried-off tubes keep their last pose over the zone, so they count in tubes_in_place_zone. A
  // tube recorded as lost may have fallen onto the zone: the controller knew of it.
  const std::uint32_t known = result.run.picks + result.run.lost;
  result.tubes_unnoticed = result.tubes_in_place_zone > known ? result.tubes_in_place_zone - known : 0;
  result.simulated_s = sim.SimulatedSeconds();
  result.runaways = sim.runaways();
  result.peak_speeds = sim.peak_speeds();
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

std::string DescribeRunaways(const std::vector<devices::sim::SimRunaway>& runaways) {
  if (runaways.empty()) return "";
  std::string out = fmt::format(
      "; the simulation threw {} tube{} (a blow-up: where {} went is the simulator's "
      "doing, not the controller's):",
      runaways.size(), runaways.size() == 1 ? "" : "s", runaways.size() == 1 ? "it" : "they");
  for (std::size_t k = 0; k < runaways.size(); ++k) {
    const devices::sim::SimRunaway& r = runaways[k];
    out += fmt::format("{} tube {} at {:.1f} m/s, {:.0f} rad/s, {:.1f} s", k == 0 ? "" : ",", r.tube + 1,
                       r.speed, r.angular_speed, r.seconds);
  }
  return out;
}

}  // namespace tubepick::cli

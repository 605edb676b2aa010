#include "clients/cli/cell/sim_round.h"

#include <chrono>

namespace tubepick::cli {

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
                           cell::RecordSink* sink) {
  const auto wall_start = std::chrono::steady_clock::now();
  cell::CellController controller({&sim.scanner(), &sim.robot(), &sim.gripper(), &sim.ft_sensor()}, planner,
                                  sim.cell(), params, sink);
  controller.set_device_clock([&sim] { return sim.SimulatedSeconds(); });
  controller.set_annotator([&sim] {
    return nlohmann::json{{"tubes_in_bin", sim.TubesInBin()},
                          {"tubes_outside_bin", sim.TubesOutsideBin()},
                          {"held", sim.HeldTubes().size()},
                          {"sim_seconds", sim.SimulatedSeconds()}};
  });
  SimRoundResult result;
  result.run = controller.Run(round);
  result.tubes_in_bin = sim.TubesInBin();
  result.tubes_outside_bin = sim.TubesOutsideBin();
  result.simulated_s = sim.SimulatedSeconds();
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  return result;
}

}  // namespace tubepick::cli

#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "clients/cell/cell_controller.h"
#include "clients/cell/cell_records.h"
#include "clients/cell/planner_client.h"
#include "clients/cli/cell/operator_stop.h"
#include "devices/sim/sim_cell.h"

namespace tubepick::cli {

/// --shapes: the bins' tubes follow this set's shapes (Algorithm 2 presets) with the cell's tube
/// radius. A linear set keeps the cell's tube length; set C's trees are 0.75 m of tube (the cell's
/// length, mass scaled with it, and topology branched, so that the planner joins junctions).
void WithShapes(const std::string& set, devices::sim::SimCellParams* p);

/// One closed-loop round in the simulated cell.
struct SimRoundResult {
  cell::CellRunResult run;
  /// Ground truth at the end, after 2 s of simulated rest: tubes still in the bin, outside it
  /// (placed or lost), in the place zone, and anywhere else (neither bin, zone nor gripper).
  std::uint32_t tubes_in_bin = 0;
  std::uint32_t tubes_outside_bin = 0;
  std::uint32_t tubes_in_place_zone = 0;
  std::uint32_t tubes_elsewhere = 0;
  /// Tubes the gripper still holds (a safe stop that could not release).
  std::uint32_t tubes_held = 0;
  /// Tubes on the place zone (or carried off it) beyond the picks and the tubes recorded as lost
  /// (which may have fallen there): carried out of the bin without the controller knowing (a
  /// second tube the F/T took for none, one caught on the tool).
  std::uint32_t tubes_unnoticed = 0;
  /// Simulated seconds of the round and the wall time it took (cell construction included).
  double simulated_s = 0.0;
  double wall_s = 0.0;
  /// Tubes the simulation threw (devices::sim::SimRunaway): where they ended is not the controller's
  /// doing. Empty in a round the simulation kept within what the cell can do.
  std::vector<devices::sim::SimRunaway> runaways;
  /// The fastest any tube body moved in the round (its bin's settling included).
  devices::sim::SimPeakSpeeds peak_speeds;
};

/// "" without runaways, else a clause for the round's line naming each thrown tube (ground-truth id,
/// simulated time, speeds) and that where it went is the simulator's doing.
std::string DescribeRunaways(const std::vector<devices::sim::SimRunaway>& runaways);

/// Builds a SimCell from `sim_params`, runs the cell controller on it against `planner` until the
/// bin is empty, a limit or a fault, and returns what happened. The controller sees the cell of
/// `sim_params` (its tube radius, length and mass go to the planner), measures robot time in
/// simulated seconds, and its records carry the simulation's ground truth as truth_before /
/// truth_after / truth: {tubes_in_bin, tubes_outside_bin, held, sim_seconds}.
SimRoundResult RunSimRound(cell::PlannerClient& planner, const devices::sim::SimCellParams& sim_params,
                           const cell::CellControllerParams& params, std::uint32_t round,
                           cell::RecordSink* sink);

/// The same on a cell built by the caller (e.g. with explicit tubes: SimCell(params, tubes_Bin));
/// wall_s then covers only the run. `observer` (if set) sees every state the controller enters;
/// `stop` (if set) stops the round on SIGINT / SIGTERM.
SimRoundResult RunSimRound(cell::PlannerClient& planner, devices::sim::SimCell& sim,
                           const cell::CellControllerParams& params, std::uint32_t round,
                           cell::RecordSink* sink, std::function<void(cell::CellState)> observer = {},
                           OperatorStop* stop = nullptr);

}  // namespace tubepick::cli

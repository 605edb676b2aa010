#pragma once

#include <cstdint>

#include <CLI/CLI.hpp>

#include "clients/cli/inputs/cli_inputs.h"
#include "core/modeling/model_tubes.h"
#include "core/planning/pick_planner.h"

namespace tubepick::cli {

/// One in-process plan of a cloud, as `tubepick plan` makes it: modeling, PlanPick (simulated
/// unless no_sim) and the placements.
struct InProcessPlan {
  ModelingResult modeling;
  PickPlanResult plan;
};
InProcessPlan PlanInProcess(const CloudInput& cloud, const CellConfig& cell, const Params& params,
                            std::uint64_t seed, bool no_sim, std::uint32_t sim_threads);

/// `tubepick plan [--cloud FILE] [--cell CELL.yaml] [--profile] [--params] [--seed N]
///  [--no-sim] [--json OUT.json]`: models the tubes, plans ranked picks (thesis ch. 5) and prints
/// the best ones; --json writes the PlanPickResponse as proto3 JSON.
void AddPlanCommand(CLI::App& app);

}  // namespace tubepick::cli

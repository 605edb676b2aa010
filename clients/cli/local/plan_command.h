#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick plan [--cloud FILE] [--cell CELL.yaml] [--profile] [--params] [--seed N]
///  [--no-sim] [--json OUT.json]`: models the tubes, plans ranked picks (thesis ch. 5) and prints
/// the best ones; --json writes the PlanPickResponse as proto3 JSON.
void AddPlanCommand(CLI::App& app);

}  // namespace tubepick::cli

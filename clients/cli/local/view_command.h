#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick view [--cloud FILE] [--plan PLAN.json | --model MODEL.json] [--cell CELL.yaml]
///  [--profile] [--seed N] [--no-sim] [--max-points N] --out PAGE.html`: one self-contained HTML
/// page (docs/VIEWER.md) of a cloud and what the planner made of it: the JSON `tubepick plan` or
/// `model` wrote for that cloud, or, without one, a plan made here first.
void AddViewCommand(CLI::App& app);

}  // namespace tubepick::cli

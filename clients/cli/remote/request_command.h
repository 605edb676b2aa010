#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick request model|plan|plan-stream|wrench [--cloud FILE [--unit m|mm] | --tubes N]
///  [--every K] [--seed S] [--profile P] [--no-sim] [--max-plans N] [--cell CELL.yaml]
///  [--chunk-kib K] [--held N] --out FILE.json`: writes one request of the PickPlannerService as
/// proto3 JSON (cloud bytes base64), ready for `buf curl -d @FILE.json` and for the README examples.
/// model/plan carry the cloud file or the built-in scene (tubes dropped with the given seed and
/// scanned); plan-stream writes the PlanPickStream messages (header, then chunks), one JSON
/// document a line; wrench carries the readings of a lift holding --held tubes of the cell's mass.
void AddRequestCommand(CLI::App& app);

}  // namespace tubepick::cli

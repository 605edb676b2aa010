#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick bench modeling`: per-stage medians of the modeling pipeline on a ~2 M-point scene,
/// for each profile in one run, with the speed-up of the first over the others and peak memory.
/// Returns the `bench` command, for the rooms that add their own benches to it.
CLI::App* AddBenchCommand(CLI::App& app);

}  // namespace tubepick::cli

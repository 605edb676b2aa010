#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick cell --sim [--rounds N] [--tubes 7] [--material pvc|rubber] [--server auto|HOST:PORT]
///  [--seed S] [--records FILE.jsonl] [--json FILE]`: runs closed-loop bin-picking rounds in the
/// simulated cell (one SimCell per round, seed + round) with the cell controller against a planner
/// server, prints one line per round and then the thesis' Tables 5.4-5.9 and the time per pick.
/// `--server auto` (the default) starts the tubepick-server next to the tubepick executable on
/// 127.0.0.1 (any free port, metrics off) and stops it with SIGTERM at the end.
/// Exit status 0 when no round stopped on a fault, 3 otherwise.
void AddCellCommand(CLI::App& app);

}  // namespace tubepick::cli

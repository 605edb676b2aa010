#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick cell (--sim | --devices FILE) [--rounds N] [--server auto|HOST:PORT] [--tls-ca ...]
///  [--seed S] [--records FILE.jsonl] [--json FILE] [--dry-run] [--print-devices-config]`: runs
/// bin-picking rounds with the cell controller against a planner server, prints one line per round
/// and then the thesis' Tables 5.4-5.9 and the time per pick.
/// --sim: the simulated cell (one SimCell per round, seed + round; --tubes, --material, fault
/// campaigns). --devices: the devices a devices file names (devices/devices_config.h), rounds back
/// to back on the same devices; a round that does not end in an empty bin or a limit ends the run.
/// `--server auto` (the default) starts the tubepick-server next to the tubepick executable on
/// 127.0.0.1 (any free port, metrics off, its own process group, dying with this process) and stops it
/// with SIGTERM at the end. SIGINT / SIGTERM end the round under way in the safe stop and skip the rest.
/// Exit status 0 when no round stopped on a fault, 3 otherwise, 128 + the signal after a stop.
void AddCellCommand(CLI::App& app);

}  // namespace tubepick::cli

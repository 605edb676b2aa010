#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick model [--cloud FILE] [--cell CELL.yaml] [--profile fast|thesis] [--params P.yaml]
///  [--seed N] [--json OUT.json] [--dump-stages DIR]`: models the tubes of a cloud (or of the
/// built-in synthetic scene when --cloud is absent) and prints them.
void AddModelCommand(CLI::App& app);

}  // namespace tubepick::cli

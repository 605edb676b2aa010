#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick params --profile P [--params FILE] --dump`: prints the full parameter YAML.
void AddParamsCommand(CLI::App& app);

}  // namespace tubepick::cli

#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick scene --tubes N [--preset A|B|C] [--seed S] --out DIR [--cell CELL.yaml]`: drops N
/// random tubes into the bin, scans them and writes the scene directory (see scene_files.h).
void AddSceneCommand(CLI::App& app);

}  // namespace tubepick::cli

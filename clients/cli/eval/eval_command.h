#pragma once

#include <CLI/CLI.hpp>

namespace tubepick::cli {

/// `tubepick eval (--scenes DIR | --generate A..B [--per-count K] [--preset P] | --configs DIR)
///  --report DIR [--cell CELL.yaml] [--profile fast|thesis] [--params P.yaml] [--seed S]
///  [--jobs J]`: models every scene, evaluates it against its ground truth (core/evaluation) and
/// writes report.md, report.json and pictures into the report directory.
void AddEvalCommand(CLI::App& app);

}  // namespace tubepick::cli

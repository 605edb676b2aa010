#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "core/common/cell_config.h"
#include "core/params.h"

namespace tubepick::cli {

/// Options every planning command shares: cell, profile, params overrides, seed.
struct CommonOptions {
  std::string cell_path;  ///< empty = embedded default cell
  std::string profile = "fast";
  std::string params_path;  ///< empty = the profile as is
  std::uint64_t seed = 0;
};

/// The cell from --cell, or the embedded default (ARCHITECTURE.md's example).
CellConfig LoadCell(const CommonOptions& options);
/// The profile overridden by --params.
Params LoadParamsFor(const CommonOptions& options);

/// Writes text to a file, creating parent directories. @throws InvalidArgument on failure.
void WriteTextFile(const std::string& path, const std::string& text);

}  // namespace tubepick::cli

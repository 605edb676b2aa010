#pragma once

#include <string>

#include "clients/cell/cell_statistics.h"

namespace tubepick::cli {

/// The thesis' result tables 5.4-5.9 (and the time per pick of 5.10) as text, laid out like the
/// thesis: one column per number of tubes in the bin, largest first, then "overall".
/// @param title e.g. "pvc, 20 rounds of 7 tubes".
std::string FormatCellTables(const cell::CellStatistics& stats, const std::string& title);

}  // namespace tubepick::cli

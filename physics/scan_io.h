#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "physics/virtual_scanner.h"

namespace tubepick::physics {

/// Ground-truth labels file: plain text, one decimal int32 per line, one line per point in the
/// order of the cloud (tube index ≥ 0, kBinLabel = −1, kOutlierLabel = −2). Text so that any tool
/// (numpy.loadtxt, awk) reads it; ~3 bytes per point.
/// @throws InvalidArgument when the file cannot be written.
void WriteLabels(const std::string& path, const std::vector<std::int32_t>& labels);

/// @throws InvalidArgument "<path>:<line>: ..." for a line that is not one integer, or when the
///         file cannot be opened.
std::vector<std::int32_t> ReadLabels(const std::string& path);

/// Writes a scan as the scanner would deliver it plus its ground truth: `ply_path` gets the
/// points (sensor frame, metres, binary PLY via WritePly) coloured by LabelColour(label), and
/// `labels_path` the labels (WriteLabels).
/// @throws InvalidArgument when a file cannot be written or the scan's sizes differ.
void WriteScan(const std::string& ply_path, const std::string& labels_path, const ScanResult& scan);

}  // namespace tubepick::physics

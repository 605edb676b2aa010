#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/common/types.h"

namespace tubepick {

/// xyz of a cloud file exactly as stored (no unit scaling, no NaN removal).
struct CloudFile {
  Points points;
  /// "ply-ascii", "ply-binary-le", "ply-binary-be", "pcd-ascii", "pcd-binary", ...
  std::string format;
};

/// Reads a PLY (ascii, binary little/big endian) or PCD (ascii, binary, binary_compressed) file,
/// chosen by content (magic line), not by extension. Only the vertex x, y, z properties are read
/// (float or double); other properties and elements are skipped. Non-finite points are kept:
/// the caller counts and drops them (see PrepareCloud).
/// @throws InvalidArgument when the file is missing, truncated or not a supported cloud, with
///         the path and the reason.
CloudFile ReadCloudFile(const std::string& path);

/// RGB colour per point, for stage dumps.
using Rgb = std::array<std::uint8_t, 3>;

/// Writes a binary little-endian PLY with float x, y, z (and uchar red, green, blue when
/// `colours` is non-null; it must then have one entry per point).
/// @throws InvalidArgument when the file cannot be written or sizes differ.
void WritePly(const std::string& path, const Points& points, const std::vector<Rgb>* colours = nullptr);

/// Writes an ASCII PLY (for tests of the ASCII reader and for humans).
void WritePlyAscii(const std::string& path, const Points& points);

/// Writes a PCD file (ascii or binary) with FIELDS x y z.
void WritePcd(const std::string& path, const Points& points, bool binary);

/// A distinct, deterministic colour for label `i` (segments, tubes); label < 0 gives grey.
Rgb LabelColour(int label);

}  // namespace tubepick

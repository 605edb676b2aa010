#pragma once

// Private to core/modeling's cloud I/O (cloud_io.cc, ply_io.cc, pcd_io.cc); not part of the API.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "core/modeling/cloud_io.h"

namespace tubepick::internal {

/// Throws InvalidArgument "cloud file '<path>': <reason>".
[[noreturn]] void ThrowCloudFileError(const std::string& path, const std::string& reason);

/// Parses a PLY file whose whole content is `bytes`. @throws InvalidArgument naming `path`.
CloudFile ParsePly(const std::string& path, std::string_view bytes);

/// Parses a PCD v0.7 file whose whole content is `bytes`. @throws InvalidArgument naming `path`.
CloudFile ParsePcd(const std::string& path, std::string_view bytes);

/// True when `bytes` starts like a PCD file (comments, then VERSION or FIELDS).
bool LooksLikePcd(std::string_view bytes);

/// Decompresses LZF data (liblzf format, as in PCD binary_compressed) into exactly
/// `expected_size` bytes. @throws InvalidArgument naming `path` when the data is corrupt.
std::vector<char> LzfDecompress(const std::string& path, std::string_view compressed,
                                std::size_t expected_size);

/// Writes `bytes` to `path` (truncating). @throws InvalidArgument when it cannot.
void WriteFileBytes(const std::string& path, std::string_view bytes);

/// Splits header text into lines: returns the next line (without "\n" or "\r\n") starting at
/// `*pos` and advances `*pos` past it; false at the end of `bytes`.
bool NextLine(std::string_view bytes, std::size_t* pos, std::string_view* line);

/// Whitespace-separated tokens of one line.
std::vector<std::string_view> SplitWords(std::string_view line);

/// Cursor over whitespace-separated ASCII tokens (the body of ascii PLY / PCD files).
class TokenReader {
 public:
  explicit TokenReader(std::string_view text) : text_(text) {}
  /// Next token, or false at the end of the text.
  bool Next(std::string_view* token);

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
};

/// Parses a whole token as a number (a leading '+' is accepted, "nan"/"inf" too).
bool ParseNumber(std::string_view token, float* value);
bool ParseNumber(std::string_view token, double* value);
bool ParseNumber(std::string_view token, std::uint64_t* value);

/// Appends the shortest decimal text that reads back as exactly `value`.
void AppendNumber(std::string* out, float value);

/// Appends one "x y z\n" line per point (ASCII PLY and PCD bodies).
void AppendAsciiPoints(std::string* out, const Points& points);

/// count × size as text for error messages ("over 2^64" when it overflows).
inline std::string ByteCountText(std::uint64_t count, std::uint64_t size) {
  if (size != 0 && count > std::numeric_limits<std::uint64_t>::max() / size) return "over 2^64";
  return std::to_string(count * size);
}

/// Stores `value` as 4 little-endian bytes at `dst`.
void StoreFloatLE(char* dst, float value);

}  // namespace tubepick::internal

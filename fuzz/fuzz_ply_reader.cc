// libFuzzer target: the PLY reader (ascii, binary little/big endian) on arbitrary bytes.
// Accepted: a cloud, or InvalidArgument naming the reason. Anything else (another exception, a
// sanitizer report, a cloud with more points than the input has bytes) is a crash.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/common/errors.h"
#include "core/modeling/cloud_io_internal.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  // ReadCloudFile's dispatch: a PLY file starts with the line "ply".
  std::size_t pos = 0;
  std::string_view first_line;
  if (!tubepick::internal::NextLine(bytes, &pos, &first_line) || first_line != "ply") return 0;
  try {
    const tubepick::CloudFile cloud = tubepick::internal::ParsePly("fuzz.ply", bytes);
    // Every point takes at least one byte of the input (binary: 12, ascii: 3 tokens).
    if (cloud.points.size() > size || cloud.format.rfind("ply-", 0) != 0) std::abort();
  } catch (const tubepick::InvalidArgument&) {
  }
  return 0;
}

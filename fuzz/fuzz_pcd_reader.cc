// libFuzzer target: the PCD v0.7 reader (ascii, binary, binary_compressed with LZF) on arbitrary
// bytes. Accepted: a cloud, or InvalidArgument naming the reason. Anything else (another exception, a
// sanitizer report, a cloud with more points than the input can hold) is a crash.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "core/common/errors.h"
#include "core/modeling/cloud_io_internal.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  if (!tubepick::internal::LooksLikePcd(bytes)) return 0;  // ReadCloudFile's dispatch
  try {
    const tubepick::CloudFile cloud = tubepick::internal::ParsePcd("fuzz.pcd", bytes);
    // ascii and binary: at least one byte a point; binary_compressed: LZF expands at most ~88x.
    if (cloud.points.size() > 100 * size + 100 || cloud.format.rfind("pcd-", 0) != 0) std::abort();
  } catch (const tubepick::InvalidArgument&) {
  }
  return 0;
}

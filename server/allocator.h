#pragma once

#include <cstdint>
#include <optional>

namespace tubepick::server {

/// True when jemalloc serves this process's allocations (tubepick-server links it; the library, its
/// tests and the sanitizer builds run on another allocator). Looked up once, at run time.
bool UsesJemalloc();

/// The allocator's own account of its memory (jemalloc's stats.*), bytes. It tells a leak from the
/// allocator's cache: `allocated` is what live objects hold and grows with a leak; `resident` adds the
/// freed pages jemalloc keeps for reuse until they have been unused for ~10 s, which is most of the
/// swing of the process RSS under load.
struct AllocatorMemory {
  /// stats.allocated: bytes in live allocations.
  std::uint64_t allocated = 0;
  /// stats.resident: bytes of the allocator's pages that are resident (live, cached and metadata).
  std::uint64_t resident = 0;
};
/// nullopt when the process does not allocate with jemalloc or its statistics are unavailable.
std::optional<AllocatorMemory> ReadAllocatorMemory();

}  // namespace tubepick::server

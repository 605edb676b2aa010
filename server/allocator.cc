#include "server/allocator.h"

#include <dlfcn.h>

#include <cstddef>

namespace tubepick::server {
namespace {

using Mallctl = int (*)(const char*, void*, std::size_t*, void*, std::size_t);

// jemalloc's mallctl when it serves this process (it exports the symbol), else nullptr.
Mallctl JemallocMallctl() {
  static const auto mallctl = reinterpret_cast<Mallctl>(::dlsym(RTLD_DEFAULT, "mallctl"));
  return mallctl;
}

}  // namespace

bool UsesJemalloc() { return JemallocMallctl() != nullptr; }

std::optional<AllocatorMemory> ReadAllocatorMemory() {
  const Mallctl mallctl = JemallocMallctl();
  if (mallctl == nullptr) return std::nullopt;
  // The statistics are a snapshot taken when the epoch advances.
  std::uint64_t epoch = 1;
  std::size_t epoch_size = sizeof(epoch);
  if (mallctl("epoch", &epoch, &epoch_size, &epoch, epoch_size) != 0) return std::nullopt;
  const auto read = [mallctl](const char* name) -> std::optional<std::uint64_t> {
    std::size_t value = 0;
    std::size_t size = sizeof(value);
    if (mallctl(name, &value, &size, nullptr, 0) != 0) return std::nullopt;
    return value;
  };
  const std::optional<std::uint64_t> allocated = read("stats.allocated");
  const std::optional<std::uint64_t> resident = read("stats.resident");
  if (!allocated || !resident) return std::nullopt;
  return AllocatorMemory{*allocated, *resident};
}

}  // namespace tubepick::server

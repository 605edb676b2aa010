#pragma once

#include <cstdint>
#include <string>

namespace tubepick {

/// The cores this process may run on: the CPU affinity mask (taskset, a container's cpuset), capped
/// by a cgroup v2 CPU quota (`docker run --cpus`, Kubernetes limits) rounded up. Never less than 1.
/// Unlike omp_get_max_threads() it ignores OMP_NUM_THREADS: a parallel region's width is the
/// caller's decision (ResolveThreads), not the environment's.
int CoresAvailable();

/// The thread count a parallel region uses for a `threads` parameter: `requested` when non-zero,
/// else CoresAvailable(). Every parallel region in core/ and physics/ sizes itself with this.
int ResolveThreads(std::uint32_t requested);

namespace internal {
/// The whole cores a cgroup v2 `cpu.max` line allows ("max 100000" → 0 = no quota;
/// "150000 100000" → 2). Unreadable text is no quota.
int CoresFromCpuMax(const std::string& cpu_max);
}  // namespace internal

}  // namespace tubepick

#include "core/common/thread_budget.h"

#include <sched.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <thread>

namespace tubepick {
namespace {

int AffinityCores() {
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0) return std::max(1, CPU_COUNT(&set));
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

int CgroupQuotaCores() {
  std::ifstream in("/sys/fs/cgroup/cpu.max");
  if (!in) return 0;
  std::string line;
  std::getline(in, line);
  return internal::CoresFromCpuMax(line);
}

}  // namespace

namespace internal {

int CoresFromCpuMax(const std::string& cpu_max) {
  std::istringstream in(cpu_max);
  std::string quota;
  double period = 0;
  if (!(in >> quota >> period) || quota == "max" || period <= 0) return 0;
  char* end = nullptr;
  const double q = std::strtod(quota.c_str(), &end);
  if (end == quota.c_str() || *end != '\0' || !(q > 0)) return 0;
  return std::max(1, static_cast<int>(std::ceil(q / period)));
}

}  // namespace internal

int CoresAvailable() {
  static const int cores = [] {
    const int affinity = AffinityCores();
    const int quota = CgroupQuotaCores();
    return quota > 0 ? std::min(affinity, quota) : affinity;
  }();
  return cores;
}

int ResolveThreads(std::uint32_t requested) {
  return requested == 0 ? CoresAvailable() : static_cast<int>(requested);
}

}  // namespace tubepick

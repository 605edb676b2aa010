#include "server/metrics.h"

#include <fmt/format.h>

#include <fstream>
#include <iterator>
#include <sstream>

#include "server/allocator.h"

namespace tubepick::server {
namespace {

constexpr std::array<std::string_view, 4> kMethods = {"ModelTubes", "PlanPick", "PlanPickStream",
                                                      "AnalyzeWrench"};

// "VmRSS:\t  123 kB" → bytes.
std::optional<std::uint64_t> StatusKilobytes(const std::string& line, std::string_view key) {
  if (line.rfind(key, 0) != 0) return std::nullopt;
  std::istringstream in(line.substr(key.size()));
  std::uint64_t kb = 0;
  std::string unit;
  if (!(in >> kb >> unit) || unit != "kB") return std::nullopt;
  return kb * 1024;
}

// A float as Prometheus writes it ("+Inf", shortest round-trip otherwise).
std::string Number(double v) { return fmt::format("{}", v); }

}  // namespace

std::optional<ProcessMemory> ReadProcessMemory() {
  std::ifstream in("/proc/self/status");
  if (!in) return std::nullopt;
  ProcessMemory memory;
  bool rss = false, hwm = false;
  for (std::string line; std::getline(in, line);) {
    if (auto v = StatusKilobytes(line, "VmRSS:")) memory.resident_bytes = *v, rss = true;
    if (auto v = StatusKilobytes(line, "VmHWM:")) memory.peak_resident_bytes = *v, hwm = true;
  }
  if (!rss || !hwm) return std::nullopt;
  return memory;
}

Metrics::Metrics() {
  // Every method's OK series and histogram exist from the start, so dashboards see zeros.
  for (std::string_view method : kMethods) {
    calls_[{std::string(method), "OK"}] = 0;
    durations_[std::string(method)] = Histogram{};
  }
}

void Metrics::RecordCall(std::string_view method, std::string_view code, double seconds) {
  std::lock_guard lock(mu_);
  ++calls_[{std::string(method), std::string(code)}];
  auto it = durations_.find(method);
  if (it == durations_.end()) it = durations_.emplace(std::string(method), Histogram{}).first;
  Histogram& h = it->second;
  for (std::size_t i = 0; i < kRpcDurationBuckets.size(); ++i) {
    if (seconds <= kRpcDurationBuckets[i]) {
      ++h.buckets[i];
      break;
    }
  }
  ++h.count;
  h.sum += seconds;
}

void Metrics::RecordRejected() {
  std::lock_guard lock(mu_);
  ++rejected_;
}

void Metrics::RecordExpiredInQueue() {
  std::lock_guard lock(mu_);
  ++expired_in_queue_;
}

void Metrics::RecordModelingWarning(std::string_view code) {
  std::lock_guard lock(mu_);
  auto it = modeling_warnings_.find(code);
  if (it == modeling_warnings_.end()) it = modeling_warnings_.emplace(std::string(code), 0).first;
  ++it->second;
}

std::uint64_t Metrics::calls(std::string_view method, std::string_view code) const {
  std::lock_guard lock(mu_);
  auto it = calls_.find(std::pair<std::string, std::string>(method, code));
  return it == calls_.end() ? 0 : it->second;
}

std::uint64_t Metrics::rejected() const {
  std::lock_guard lock(mu_);
  return rejected_;
}

std::string Metrics::RenderPrometheus(const PoolLoad& load, std::uint32_t uploads) const {
  std::string out;
  auto o = std::back_inserter(out);
  auto header = [&](std::string_view name, std::string_view type, std::string_view help) {
    fmt::format_to(o, "# HELP {} {}\n# TYPE {} {}\n", name, help, name, type);
  };
  {
    std::lock_guard lock(mu_);
    header("tubepick_rpc_requests_total", "counter", "RPCs answered, by method and gRPC status code.");
    for (const auto& [key, count] : calls_)
      fmt::format_to(o, "tubepick_rpc_requests_total{{method=\"{}\",code=\"{}\"}} {}\n", key.first,
                     key.second, count);
    header("tubepick_rpc_duration_seconds", "histogram", "Time from arrival to answer of an RPC, seconds.");
    for (const auto& [method, h] : durations_) {
      std::uint64_t cumulative = 0;
      for (std::size_t i = 0; i < kRpcDurationBuckets.size(); ++i) {
        cumulative += h.buckets[i];
        fmt::format_to(o, "tubepick_rpc_duration_seconds_bucket{{method=\"{}\",le=\"{}\"}} {}\n", method,
                       Number(kRpcDurationBuckets[i]), cumulative);
      }
      fmt::format_to(o, "tubepick_rpc_duration_seconds_bucket{{method=\"{}\",le=\"+Inf\"}} {}\n", method,
                     h.count);
      fmt::format_to(o, "tubepick_rpc_duration_seconds_sum{{method=\"{}\"}} {}\n", method, Number(h.sum));
      fmt::format_to(o, "tubepick_rpc_duration_seconds_count{{method=\"{}\"}} {}\n", method, h.count);
    }
    header("tubepick_rejected_total", "counter",
           "Requests refused with RESOURCE_EXHAUSTED: the planning queue was full.");
    fmt::format_to(o, "tubepick_rejected_total {}\n", rejected_);
    header("tubepick_queue_expired_total", "counter",
           "Requests cancelled or past their deadline while queued; dropped without running.");
    fmt::format_to(o, "tubepick_queue_expired_total {}\n", expired_in_queue_);
    header("tubepick_modeling_warnings_total", "counter",
           "Answers whose modeling warned that a cell input probably does not fit the scene, by code.");
    for (const auto& [code, count] : modeling_warnings_)
      fmt::format_to(o, "tubepick_modeling_warnings_total{{code=\"{}\"}} {}\n", code, count);
  }
  header("tubepick_queue_depth", "gauge", "Admitted requests waiting for a planning worker.");
  fmt::format_to(o, "tubepick_queue_depth {}\n", load.queued);
  header("tubepick_stream_uploads", "gauge", "PlanPickStream calls still receiving their cloud.");
  fmt::format_to(o, "tubepick_stream_uploads {}\n", uploads);
  header("tubepick_workers_busy", "gauge", "Planning workers running a request.");
  fmt::format_to(o, "tubepick_workers_busy {}\n", load.busy);
  header("tubepick_workers", "gauge", "Planning worker threads.");
  fmt::format_to(o, "tubepick_workers {}\n", load.workers);
  if (const std::optional<ProcessMemory> memory = ReadProcessMemory()) {
    header("process_resident_memory_bytes", "gauge", "Resident memory size in bytes.");
    fmt::format_to(o, "process_resident_memory_bytes {}\n", memory->resident_bytes);
    header("process_resident_memory_peak_bytes", "gauge", "Peak resident memory size in bytes (VmHWM).");
    fmt::format_to(o, "process_resident_memory_peak_bytes {}\n", memory->peak_resident_bytes);
  }
  if (const std::optional<AllocatorMemory> heap = ReadAllocatorMemory()) {
    header(
        "tubepick_allocator_allocated_bytes", "gauge",
        "Bytes in live allocations (jemalloc stats.allocated): grows with a leak, not with the allocator's "
        "cache.");
    fmt::format_to(o, "tubepick_allocator_allocated_bytes {}\n", heap->allocated);
    header("tubepick_allocator_resident_bytes", "gauge",
           "Bytes of the allocator's resident pages (jemalloc stats.resident): live allocations plus freed "
           "pages "
           "kept for reuse until unused for ~10 s.");
    fmt::format_to(o, "tubepick_allocator_resident_bytes {}\n", heap->resident);
  }
  return out;
}

}  // namespace tubepick::server

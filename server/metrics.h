#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "server/worker_pool.h"

namespace tubepick::server {

/// Upper bounds of the RPC latency histogram buckets, seconds (+Inf is implicit).
inline constexpr std::array<double, 12> kRpcDurationBuckets = {0.01, 0.025, 0.05, 0.1,  0.25, 0.5,
                                                               1.0,  2.5,   5.0,  10.0, 30.0, 60.0};

/// Resident memory of this process from /proc/self/status, bytes.
struct ProcessMemory {
  /// VmRSS: resident now.
  std::uint64_t resident_bytes = 0;
  /// VmHWM: the peak resident size so far.
  std::uint64_t peak_resident_bytes = 0;
};
/// nullopt where /proc is not available.
std::optional<ProcessMemory> ReadProcessMemory();

/// The service's counters and histograms, rendered in the Prometheus text exposition format
/// (version 0.0.4). Thread-safe; recording is a short critical section per call.
class Metrics {
 public:
  Metrics();

  /// One answered RPC: `method` ("PlanPick", ...), `code` the gRPC status name ("OK", ...),
  /// `seconds` from arrival to answer.
  void RecordCall(std::string_view method, std::string_view code, double seconds);
  /// A request refused because the planning queue was full.
  void RecordRejected();
  /// A request whose deadline passed (or that was cancelled) while it waited in the queue, so it
  /// never ran.
  void RecordExpiredInQueue();
  /// An answer that carried a modeling warning with this code (ModelingWarning.code).
  void RecordModelingWarning(std::string_view code);

  std::uint64_t calls(std::string_view method, std::string_view code) const;
  std::uint64_t rejected() const;

  /// Every metric with HELP and TYPE lines; `load` gives the queue and worker gauges, `uploads`
  /// the PlanPickStream uploads in progress.
  std::string RenderPrometheus(const PoolLoad& load, std::uint32_t uploads) const;

 private:
  struct Histogram {
    std::array<std::uint64_t, kRpcDurationBuckets.size()> buckets{};  // per bucket, not cumulative
    std::uint64_t count = 0;
    double sum = 0.0;
  };
  mutable std::mutex mu_;
  std::map<std::pair<std::string, std::string>, std::uint64_t, std::less<>> calls_;
  std::map<std::string, Histogram, std::less<>> durations_;
  std::uint64_t rejected_ = 0;
  std::uint64_t expired_in_queue_ = 0;
  std::map<std::string, std::uint64_t, std::less<>> modeling_warnings_;
};

}  // namespace tubepick::server

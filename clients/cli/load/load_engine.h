#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "clients/cli/load/load_metrics.h"
#include "clients/cli/remote/channel.h"
#include "core/common/types.h"
#include "tubepick/v1/types.pb.h"

namespace tubepick::cli {

/// Which PickPlannerService RPC the load generator calls.
enum class LoadRpc { kPlanPick, kModelTubes, kPlanPickStream };

/// "plan", "model", "plan-stream" (the --rpc names).
std::string ToString(LoadRpc rpc);
/// @throws InvalidArgument naming --rpc for anything else.
LoadRpc ParseLoadRpc(const std::string& name);
/// A comma-separated list of --rpc names ("plan,plan-stream"), in order; repeats allowed.
/// @throws InvalidArgument naming --rpc for an empty list or an unknown name.
std::vector<LoadRpc> ParseLoadRpcs(const std::string& names);
/// The names joined by commas, as ParseLoadRpcs reads them.
std::string ToString(const std::vector<LoadRpc>& rpcs);

/// One recorded cloud, already packed for the wire.
struct LoadCloud {
  /// Where it came from (a file path, or a test's label).
  std::string name;
  /// Packed little-endian float32 x, y, z (PointCloud.xyz). Sent as is, so a test may pass bytes
  /// the server must reject.
  std::string xyz;
  /// PointCloud.unit; UNSPECIFIED = the server's cell unit.
  v1::LengthUnit unit = v1::LENGTH_UNIT_UNSPECIFIED;
};

/// Every *.ply and *.pcd file at or below `directory` (e.g. a tree of `tubepick scene` outputs),
/// sorted by path, read with ReadCloudFile and packed; non-finite points are kept (the server
/// drops them). @throws InvalidArgument when the directory holds no cloud or a file is unreadable.
std::vector<LoadCloud> ReadLoadClouds(const std::string& directory, v1::LengthUnit unit);

/// What to send, how often and how many at once.
struct LoadOptions {
  ChannelOptions channel;
  /// RPCs to call. Several make a fixed mix: thread w (of `concurrency`, which must be a multiple of
  /// rpcs.size()) calls rpcs[w % n] only, so the same number of calls of each RPC is always in flight;
  /// each RPC goes round-robin over the clouds.
  std::vector<LoadRpc> rpcs{LoadRpc::kPlanPick};
  /// Calls in flight at once: one worker thread each, all on one channel.
  std::uint32_t concurrency = 1;
  /// Measured calls; 0 = run for duration_seconds instead.
  std::uint64_t total = 0;
  /// Measured phase length when total == 0, seconds: no call starts after it (calls in flight
  /// finish and count).
  double duration_seconds = 0.0;
  /// Calls per second started in the measured phase (open loop: call k starts k / rate after the
  /// phase begins, an RPC k % rpcs.size() call by one of that RPC's threads, or as soon as one is free
  /// when the server is behind); 0 = closed loop, each thread calls again as soon as its call ends. A fixed
  /// rate loads the server the same whatever the machine's speed, so its memory (the allocator's cache of
  /// freed pages grows with the calls per second) can be compared between the start and the end of a run.
  double rate = 0.0;
  /// Calls that complete before the measured phase (same concurrency), not counted. The phase starts
  /// when the last of them completes, with the other threads' calls still in flight (those are not
  /// counted either), so the server is in its steady state when measuring (and RSS sampling) begins.
  std::uint64_t warmup = 0;
  /// Deadline of each call, seconds; 0 = none.
  double deadline_seconds = 0.0;
  /// PlanningOptions sent with every call.
  std::string profile;  ///< empty = the server's profile
  std::optional<std::uint64_t> seed;
  bool disable_simulation = false;
  std::uint32_t max_plans = 0;
  /// PlanPickStream chunk size, bytes.
  std::size_t chunk_bytes = 1 << 20;
  /// Prometheus endpoint of the server (http://HOST:PORT/metrics); empty = no RSS sampling.
  std::string metrics_url;
  double metrics_interval_seconds = 5.0;
  /// Length of the first and last windows the RSS samples are compared over, seconds.
  double rss_window_seconds = 60.0;
  /// How long after sampling starts the first window begins, seconds (RssSummary::settle_seconds).
  double rss_settle_seconds = 0.0;
  /// How long to wait for the channel to connect before giving up, seconds.
  double connect_timeout_seconds = 10.0;
};

/// Latency of the successful calls, seconds (nearest-rank percentiles). All zero without one.
struct LatencySummary {
  double min = 0.0;
  double mean = 0.0;
  double p50 = 0.0;
  double p90 = 0.0;
  double p95 = 0.0;
  double p99 = 0.0;
  double max = 0.0;
};

/// Nearest-rank percentiles of `seconds` (any order). Empty input gives all zeros.
LatencySummary SummarizeLatency(std::vector<double> seconds);

/// The calls of one RPC in a run that mixes several.
struct RpcReport {
  std::string rpc;     ///< "plan", "model", "plan-stream"
  std::string method;  ///< full gRPC method name
  std::uint64_t total = 0;
  std::uint64_t ok = 0;
  std::map<std::string, std::uint64_t> status_counts;
  LatencySummary latency;
};

/// One measured call on the wall clock, for lining a run up with events outside it (a replica
/// killed behind a proxy, a server restarted).
struct CallTiming {
  /// When the call started, seconds since the Unix epoch (system clock).
  double start_unix_seconds = 0.0;
  double seconds = 0.0;
  std::string code;  ///< status code name, "OK" included
};

/// The outcome of one load run (measured phase only), like ghz's summary.
struct LoadReport {
  std::string rpc;     ///< "plan", "model", "plan-stream"; several joined by commas
  std::string method;  ///< full gRPC method name; several joined by ", "
  std::string target;
  std::uint32_t concurrency = 0;
  std::uint64_t clouds = 0;
  /// Mean request payload (cloud bytes) per call.
  double mean_cloud_bytes = 0.0;
  std::uint64_t warmup = 0;
  /// LoadOptions::rate (0 = closed loop), and the most a measured call started after its slot,
  /// seconds: a server that cannot keep the rate lags.
  double rate = 0.0;
  double max_start_lag_seconds = 0.0;
  /// Measured calls (any status), of which `ok` succeeded.
  std::uint64_t total = 0;
  std::uint64_t ok = 0;
  /// Calls by status code name ("OK", "RESOURCE_EXHAUSTED", ...), OK included.
  std::map<std::string, std::uint64_t> status_counts;
  /// The first message seen for each non-OK code.
  std::map<std::string, std::string> error_examples;
  /// Wall time of the measured phase, seconds.
  double elapsed_seconds = 0.0;
  /// total / elapsed and ok / elapsed.
  double requests_per_second = 0.0;
  double ok_per_second = 0.0;
  LatencySummary latency;
  /// The same per RPC, in the order of LoadOptions::rpcs (one entry for a single RPC).
  std::vector<RpcReport> by_rpc;
  /// Present when metrics_url was given.
  std::optional<RssSummary> rss;
  /// Every measured call in the order they started (JSON report only).
  std::vector<CallTiming> calls;
};

/// Runs the load: connects, optionally warms up, then sends the clouds round-robin from
/// `concurrency` threads (each with one call in flight; at `rate` calls per second when given) until
/// `total` calls completed or `duration_seconds` passed. Call failures are counted by status code, never
/// thrown.
/// @throws InvalidArgument for inconsistent options (no clouds, concurrency 0 or not a multiple of the
///         number of RPCs, neither total nor duration, a negative rate) or when the target does not connect
///         within connect_timeout_seconds.
LoadReport RunLoad(const LoadOptions& options, const std::vector<LoadCloud>& clouds);

/// ghz-like text summary (several lines, ends with a newline).
std::string FormatLoadReportText(const LoadReport& report);
/// The same as JSON (seconds, bytes; RSS samples included).
std::string FormatLoadReportJson(const LoadReport& report);

}  // namespace tubepick::cli

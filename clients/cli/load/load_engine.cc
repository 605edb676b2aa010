#include "clients/cli/load/load_engine.h"

#include <fmt/core.h>
#include <grpcpp/generic/generic_stub.h>
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <future>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"
#include "tubepick/v1/requests.pb.h"
#include "tubepick/v1/service.grpc.pb.h"
#include "wire/cloud_stream.h"
#include "wire/packed_cloud.h"

namespace tubepick::cli {
namespace {

using Clock = std::chrono::steady_clock;

constexpr const char* kService = "/tubepick.v1.PickPlannerService/";

std::string MethodName(LoadRpc rpc) {
  switch (rpc) {
    case LoadRpc::kPlanPick:
      return std::string(kService) + "PlanPick";
    case LoadRpc::kModelTubes:
      return std::string(kService) + "ModelTubes";
    case LoadRpc::kPlanPickStream:
      return std::string(kService) + "PlanPickStream";
  }
  return {};
}

v1::PlanningOptions MakePlanningOptions(const LoadOptions& o) {
  v1::PlanningOptions options;
  options.set_profile(o.profile);
  if (o.seed) options.set_seed(*o.seed);
  options.set_disable_simulation(o.disable_simulation);
  options.set_max_plans(o.max_plans);
  return options;
}

/// A cloud's request, encoded once: the serialized unary request, or the stream's messages.
struct PreparedCall {
  grpc::ByteBuffer unary;
  std::vector<v1::PlanPickStreamRequest> stream;
};

grpc::ByteBuffer Serialize(const google::protobuf::Message& message) {
  std::string bytes;
  message.SerializeToString(&bytes);
  grpc::Slice slice(std::move(bytes));
  return grpc::ByteBuffer(&slice, 1);
}

PreparedCall Prepare(const LoadOptions& o, LoadRpc rpc, const LoadCloud& cloud) {
  PreparedCall call;
  v1::PointCloud* pc = nullptr;
  v1::ModelTubesRequest model;
  v1::PlanPickRequest plan;
  if (rpc == LoadRpc::kModelTubes) {
    *model.mutable_options() = MakePlanningOptions(o);
    pc = model.mutable_cloud();
  } else {
    *plan.mutable_options() = MakePlanningOptions(o);
    pc = plan.mutable_cloud();
  }
  pc->set_unit(cloud.unit);
  switch (rpc) {
    case LoadRpc::kModelTubes:
      pc->set_xyz(cloud.xyz);
      call.unary = Serialize(model);
      break;
    case LoadRpc::kPlanPick:
      pc->set_xyz(cloud.xyz);
      call.unary = Serialize(plan);
      break;
    case LoadRpc::kPlanPickStream: {
      call.stream = SplitCloudStream(plan, cloud.xyz, std::max<std::size_t>(1, o.chunk_bytes));
      break;
    }
  }
  return call;
}

/// One finished call.
struct CallRecord {
  /// Index into LoadOptions::rpcs.
  std::size_t rpc = 0;
  std::chrono::system_clock::time_point started;
  double seconds = 0.0;
  grpc::StatusCode code = grpc::StatusCode::OK;
  std::string message;
};

/// Makes calls on one shared channel; thread-safe (each call has its own context).
class Caller {
 public:
  Caller(std::shared_ptr<grpc::Channel> channel, const LoadOptions& options)
      : options_(options), generic_(channel), stub_(v1::PickPlannerService::NewStub(channel)) {
    for (const LoadRpc rpc : options.rpcs) methods_.push_back(MethodName(rpc));
  }

  /// Calls options.rpcs[rpc] with `call` (prepared for that RPC).
  CallRecord Call(std::size_t rpc, const PreparedCall& call) const {
    grpc::ClientContext context;
    if (options_.deadline_seconds > 0.0)
      context.set_deadline(std::chrono::system_clock::now() +
                           std::chrono::duration_cast<std::chrono::system_clock::duration>(
                               std::chrono::duration<double>(options_.deadline_seconds)));
    const auto wall_start = std::chrono::system_clock::now();
    const Clock::time_point t0 = Clock::now();
    const grpc::Status status = options_.rpcs[rpc] == LoadRpc::kPlanPickStream
                                    ? Stream(&context, call)
                                    : Unary(&context, methods_[rpc], call);
    CallRecord record;
    record.rpc = rpc;
    record.started = wall_start;
    record.seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    record.code = status.error_code();
    record.message = status.error_message();
    return record;
  }

 private:
  grpc::Status Unary(grpc::ClientContext* context, const std::string& method,
                     const PreparedCall& call) const {
    grpc::ByteBuffer response;
    std::promise<grpc::Status> done;
    std::future<grpc::Status> result = done.get_future();
    generic_.UnaryCall(context, method, grpc::StubOptions(), &call.unary, &response,
                       [&done](grpc::Status status) { done.set_value(std::move(status)); });
    return result.get();
  }

  grpc::Status Stream(grpc::ClientContext* context, const PreparedCall& call) const {
    v1::PlanPickStreamResponse response;
    std::unique_ptr<grpc::ClientWriter<v1::PlanPickStreamRequest>> writer =
        stub_->PlanPickStream(context, &response);
    for (const v1::PlanPickStreamRequest& message : call.stream) {
      if (!writer->Write(message)) break;  // the server already answered (an error): Finish says why
    }
    writer->WritesDone();
    return writer->Finish();
  }

  const LoadOptions& options_;
  std::vector<std::string> methods_;
  mutable grpc::GenericStub generic_;
  std::unique_ptr<v1::PickPlannerService::Stub> stub_;
};

/// The measured phase: it starts once, when the warm-up's last call completes (at once without a
/// warm-up), while the other threads' calls go on, so it begins with the server in its steady state
/// rather than idle. Written before `started` is set, read after seeing it.
struct MeasuredPhase {
  std::once_flag once;
  std::atomic<bool> started{false};
  Clock::time_point t0;
  std::optional<Clock::time_point> end;  ///< duration runs
  std::optional<RssSampler> sampler;     ///< started with the phase
  /// Open loop (LoadOptions::rate): each RPC's next slot (RPC r of n takes the slots k·n + r, so the
  /// mix stays fixed), and the most a call started after its slot.
  explicit MeasuredPhase(std::size_t rpcs) : slots(rpcs) {}
  std::vector<std::atomic<std::uint64_t>> slots;
  std::mutex lag_mutex;
  double max_start_lag_seconds = 0.0;
};

/// With a rate, waits for the next slot of RPC `rpc` (phase.t0 + k / rate, k = its j-th slot · the
/// number of RPCs + rpc) and returns false when it lies at or after the phase's end; without a rate,
/// returns true at once.
bool WaitForSlot(const LoadOptions& o, MeasuredPhase& phase, std::size_t rpc) {
  if (!(o.rate > 0.0)) return true;
  const std::uint64_t k = phase.slots[rpc].fetch_add(1) * phase.slots.size() + rpc;
  const Clock::time_point at =
      phase.t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(k / o.rate));
  if (phase.end && at >= *phase.end) return false;
  std::this_thread::sleep_until(at);
  const double lag = std::chrono::duration<double>(Clock::now() - at).count();
  std::lock_guard lock(phase.lag_mutex);
  phase.max_start_lag_seconds = std::max(phase.max_start_lag_seconds, lag);
  return true;
}

/// Runs the calls: `concurrency` threads, each with one call in flight, until o.total measured calls
/// started or the measured phase's end passed. calls[k][c] is cloud c prepared for o.rpcs[k]; thread w
/// calls RPC k = w % calls.size() only, and next[k] is that RPC's round-robin position over the
/// clouds. A call that started before the measured phase is not counted, even when it ends after.
/// Returns the measured calls.
std::vector<CallRecord> RunCalls(const Caller& caller, const std::vector<std::vector<PreparedCall>>& calls,
                                 const LoadOptions& o, MeasuredPhase& phase) {
  std::vector<std::atomic<std::uint64_t>> next(calls.size());
  std::atomic<std::uint64_t> warmed{0};
  std::atomic<std::uint64_t> started{0};
  const auto begin = [&] {
    std::call_once(phase.once, [&] {
      phase.t0 = Clock::now();
      if (o.total == 0)
        phase.end = phase.t0 + std::chrono::duration_cast<Clock::duration>(
                                   std::chrono::duration<double>(o.duration_seconds));
      if (!o.metrics_url.empty())
        phase.sampler.emplace(o.metrics_url, std::chrono::milliseconds(static_cast<long long>(
                                                 std::max(0.1, o.metrics_interval_seconds) * 1000.0)));
      phase.started.store(true, std::memory_order_release);
    });
  };
  if (o.warmup == 0) begin();
  std::mutex mutex;
  std::vector<CallRecord> records;
  std::vector<std::thread> workers;
  for (std::uint32_t w = 0; w < o.concurrency; ++w) {
    workers.emplace_back([&, rpc = w % calls.size()] {
      const std::vector<PreparedCall>& clouds = calls[rpc];
      std::vector<CallRecord> mine;
      for (;;) {
        const bool measured = phase.started.load(std::memory_order_acquire);
        if (measured) {
          if (o.total > 0 && started.fetch_add(1) >= o.total) break;
          if (phase.end && Clock::now() >= *phase.end) break;
          if (!WaitForSlot(o, phase, rpc)) break;
        }
        CallRecord record = caller.Call(rpc, clouds[next[rpc].fetch_add(1) % clouds.size()]);
        if (measured) {
          mine.push_back(std::move(record));
        } else if (warmed.fetch_add(1) + 1 >= o.warmup) {
          begin();
        }
      }
      std::lock_guard lock(mutex);
      records.insert(records.end(), std::make_move_iterator(mine.begin()),
                     std::make_move_iterator(mine.end()));
    });
  }
  for (std::thread& t : workers) t.join();
  return records;
}

std::string HumanBytes(double bytes) {
  if (bytes >= 1e9) return fmt::format("{:.2f} GB", bytes / 1e9);
  if (bytes >= 1e6) return fmt::format("{:.1f} MB", bytes / 1e6);
  if (bytes >= 1e3) return fmt::format("{:.1f} kB", bytes / 1e3);
  return fmt::format("{:.0f} B", bytes);
}

}  // namespace

std::string ToString(LoadRpc rpc) {
  switch (rpc) {
    case LoadRpc::kPlanPick:
      return "plan";
    case LoadRpc::kModelTubes:
      return "model";
    case LoadRpc::kPlanPickStream:
      return "plan-stream";
  }
  return "?";
}

LoadRpc ParseLoadRpc(const std::string& name) {
  if (name == "plan") return LoadRpc::kPlanPick;
  if (name == "model") return LoadRpc::kModelTubes;
  if (name == "plan-stream") return LoadRpc::kPlanPickStream;
  throw InvalidArgument("--rpc: '" + name + "' is not plan, model or plan-stream");
}

std::vector<LoadRpc> ParseLoadRpcs(const std::string& names) {
  std::vector<LoadRpc> rpcs;
  std::size_t begin = 0;
  for (;;) {
    const std::size_t comma = names.find(',', begin);
    rpcs.push_back(ParseLoadRpc(names.substr(begin, comma == std::string::npos ? comma : comma - begin)));
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
  return rpcs;
}

std::string ToString(const std::vector<LoadRpc>& rpcs) {
  std::string out;
  for (const LoadRpc rpc : rpcs) out += (out.empty() ? "" : ",") + ToString(rpc);
  return out;
}

std::vector<LoadCloud> ReadLoadClouds(const std::string& directory, v1::LengthUnit unit) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(directory)) throw InvalidArgument("--clouds: '" + directory + "' is not a directory");
  std::vector<fs::path> files;
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(directory)) {
    if (!e.is_regular_file()) continue;
    std::string ext = e.path().extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext == ".ply" || ext == ".pcd") files.push_back(e.path());
  }
  if (files.empty()) throw InvalidArgument("--clouds: no .ply or .pcd file at or below '" + directory + "'");
  std::sort(files.begin(), files.end());
  std::vector<LoadCloud> clouds;
  for (const fs::path& f : files) {
    CloudFile file = ReadCloudFile(f.string());
    clouds.push_back({f.string(), PackXyz(file.points), unit});
  }
  return clouds;
}

LatencySummary SummarizeLatency(std::vector<double> seconds) {
  LatencySummary s;
  if (seconds.empty()) return s;
  std::sort(seconds.begin(), seconds.end());
  const auto rank = [&](double q) {
    // Nearest rank: the smallest value with at least q of the samples at or below it.
    const auto n = static_cast<double>(seconds.size());
    const std::size_t i = static_cast<std::size_t>(std::max(1.0, std::ceil(q * n))) - 1;
    return seconds[std::min(i, seconds.size() - 1)];
  };
  s.min = seconds.front();
  s.max = seconds.back();
  double sum = 0.0;
  for (double v : seconds) sum += v;
  s.mean = sum / static_cast<double>(seconds.size());
  s.p50 = rank(0.50);
  s.p90 = rank(0.90);
  s.p95 = rank(0.95);
  s.p99 = rank(0.99);
  return s;
}

LoadReport RunLoad(const LoadOptions& o, const std::vector<LoadCloud>& clouds) {
  if (clouds.empty()) throw InvalidArgument("--clouds: no clouds to send");
  if (o.concurrency == 0) throw InvalidArgument("--concurrency: must be at least 1");
  if (o.total == 0 && !(o.duration_seconds > 0.0))
    throw InvalidArgument("--total or --duration: give a positive call count or duration");
  if (o.rpcs.empty()) throw InvalidArgument("--rpc: no RPC to call");
  if (!(o.rate >= 0.0) || !std::isfinite(o.rate))
    throw InvalidArgument(
        fmt::format("--rate: must be a finite number of calls per second >= 0, got {}", o.rate));
  if (o.concurrency % o.rpcs.size() != 0)
    throw InvalidArgument(
        fmt::format("--concurrency: {} is not a multiple of the {} RPCs of --rpc {} (each gets "
                    "the same number of threads)",
                    o.concurrency, o.rpcs.size(), ToString(o.rpcs)));
  if (std::find(o.rpcs.begin(), o.rpcs.end(), LoadRpc::kPlanPickStream) != o.rpcs.end() && o.chunk_bytes == 0)
    throw InvalidArgument("chunk size: must be positive");

  std::vector<std::vector<PreparedCall>> calls(o.rpcs.size());
  for (std::size_t k = 0; k < o.rpcs.size(); ++k) {
    calls[k].reserve(clouds.size());
    for (const LoadCloud& c : clouds) calls[k].push_back(Prepare(o, o.rpcs[k], c));
  }
  double cloud_bytes = 0.0;
  for (const LoadCloud& c : clouds) cloud_bytes += static_cast<double>(c.xyz.size());

  std::shared_ptr<grpc::Channel> channel = MakeChannel(o.channel);
  const auto connect_deadline =
      std::chrono::system_clock::now() + std::chrono::duration_cast<std::chrono::system_clock::duration>(
                                             std::chrono::duration<double>(o.connect_timeout_seconds));
  if (!channel->WaitForConnected(connect_deadline))
    throw InvalidArgument(fmt::format("--target: cannot connect to '{}' within {} s", o.channel.target,
                                      o.connect_timeout_seconds));
  const Caller caller(channel, o);

  MeasuredPhase phase(o.rpcs.size());
  const std::vector<CallRecord> records = RunCalls(caller, calls, o, phase);
  const double elapsed = std::chrono::duration<double>(Clock::now() - phase.t0).count();

  LoadReport report;
  report.rpc = ToString(o.rpcs);
  for (const LoadRpc rpc : o.rpcs) {
    report.method += (report.method.empty() ? "" : ", ") + MethodName(rpc).substr(1);
    RpcReport& by = report.by_rpc.emplace_back();
    by.rpc = ToString(rpc);
    by.method = MethodName(rpc).substr(1);
  }
  report.target = o.channel.target;
  report.concurrency = o.concurrency;
  report.clouds = clouds.size();
  report.mean_cloud_bytes = cloud_bytes / static_cast<double>(clouds.size());
  report.warmup = o.warmup;
  report.rate = o.rate;
  report.max_start_lag_seconds = phase.max_start_lag_seconds;
  report.total = records.size();
  report.elapsed_seconds = elapsed;
  std::vector<double> ok_seconds;
  std::vector<std::vector<double>> ok_seconds_by_rpc(o.rpcs.size());
  for (const CallRecord& r : records) {
    const std::string code = StatusCodeName(r.code);
    report.calls.push_back(
        {std::chrono::duration<double>(r.started.time_since_epoch()).count(), r.seconds, code});
    ++report.status_counts[code];
    RpcReport& by = report.by_rpc[r.rpc];
    ++by.total;
    ++by.status_counts[code];
    if (r.code == grpc::StatusCode::OK) {
      ok_seconds.push_back(r.seconds);
      ok_seconds_by_rpc[r.rpc].push_back(r.seconds);
    } else if (!report.error_examples.contains(code)) {
      report.error_examples[code] = r.message;
    }
  }
  for (std::size_t k = 0; k < o.rpcs.size(); ++k) {
    report.by_rpc[k].ok = ok_seconds_by_rpc[k].size();
    report.by_rpc[k].latency = SummarizeLatency(std::move(ok_seconds_by_rpc[k]));
  }
  report.ok = ok_seconds.size();
  if (elapsed > 0.0) {
    report.requests_per_second = static_cast<double>(report.total) / elapsed;
    report.ok_per_second = static_cast<double>(report.ok) / elapsed;
  }
  report.latency = SummarizeLatency(std::move(ok_seconds));
  std::sort(report.calls.begin(), report.calls.end(), [](const CallTiming& a, const CallTiming& b) {
    return a.start_unix_seconds < b.start_unix_seconds;
  });
  if (phase.sampler)
    report.rss = phase.sampler->Stop(o.rss_window_seconds,
                                     o.total == 0 ? std::optional<double>(o.duration_seconds) : std::nullopt,
                                     o.rss_settle_seconds);
  if (report.rss) {
    std::vector<CallSpan> spans;
    spans.reserve(report.calls.size());
    for (const CallTiming& c : report.calls)
      spans.push_back({c.start_unix_seconds - report.rss->start_unix_seconds, c.seconds});
    AddCallsInFlight(*report.rss, spans);
  }
  return report;
}

std::string FormatLoadReportText(const LoadReport& r) {
  std::string out;
  const auto line = [&out](const std::string& text) { out += text + "\n"; };
  line("Summary:");
  line(fmt::format("  RPC:          {} ({})", r.rpc, r.method));
  line(fmt::format("  Target:       {}", r.target));
  line(fmt::format("  Clouds:       {} (mean {} a cloud, {:.2f} M points)", r.clouds,
                   HumanBytes(r.mean_cloud_bytes), r.mean_cloud_bytes / 12.0 / 1e6));
  line(fmt::format("  Concurrency:  {}", r.concurrency));
  if (r.rate > 0.0)
    line(fmt::format("  Rate:         {:.3f} calls/s asked, started at most {:.3f} s late", r.rate,
                     r.max_start_lag_seconds));
  line(fmt::format("  Count:        {} ({} OK){}", r.total, r.ok,
                   r.warmup ? fmt::format(", after {} warm-up", r.warmup) : ""));
  line(fmt::format("  Total:        {:.3f} s", r.elapsed_seconds));
  line(fmt::format("  Requests/sec: {:.3f} (OK: {:.3f}/s)", r.requests_per_second, r.ok_per_second));
  line("");
  if (r.ok > 0) {
    line("Latency of successful calls (s):");
    line(fmt::format("  {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9}", "min", "mean", "p50", "p90", "p95", "p99",
                     "max"));
    const LatencySummary& l = r.latency;
    line(fmt::format("  {:>9.4f} {:>9.4f} {:>9.4f} {:>9.4f} {:>9.4f} {:>9.4f} {:>9.4f}", l.min, l.mean, l.p50,
                     l.p90, l.p95, l.p99, l.max));
  } else {
    line("Latency: no successful call");
  }
  if (r.by_rpc.size() > 1) {
    line("");
    line("By RPC (latency of successful calls, s):");
    for (const RpcReport& b : r.by_rpc)
      line(fmt::format("  {:<12} {:>6} calls ({} OK)  p50 {:.4f}  p95 {:.4f}  max {:.4f}", b.rpc, b.total,
                       b.ok, b.latency.p50, b.latency.p95, b.latency.max));
  }
  line("");
  line("Status code distribution:");
  for (const auto& [code, count] : r.status_counts) {
    std::string text = fmt::format("  [{}] {} responses", code, count);
    if (const auto e = r.error_examples.find(code); e != r.error_examples.end())
      text += fmt::format("  (first: {})", e->second);
    line(text);
  }
  if (r.rss) {
    const RssSummary& m = *r.rss;
    line("");
    line(fmt::format("Server RSS (process_resident_memory_bytes from {}, every {:g} s, {} samples{}):", m.url,
                     m.interval_seconds, m.samples.size(),
                     m.failed_scrapes ? fmt::format(", {} failed scrapes", m.failed_scrapes) : ""));
    if (m.samples.empty()) {
      line("  no sample");
    } else {
      // The windows as times since sampling began, e.g. "[30, 60] s".
      const double first_begin = m.samples.front().seconds + m.settle_seconds;
      const std::string first =
          fmt::format("[{:.0f}, {:.0f}] s", first_begin, first_begin + m.window_seconds);
      const std::string last =
          fmt::format("[{:.0f}, {:.0f}] s", m.end_seconds - m.window_seconds, m.end_seconds);
      line(fmt::format("  first {} max {}, last {} max {} ({:+.1f} %), peak {}", first,
                       HumanBytes(static_cast<double>(m.first_window_max)), last,
                       HumanBytes(static_cast<double>(m.last_window_max)), m.growth_percent,
                       HumanBytes(static_cast<double>(m.peak))));
      line(fmt::format("  first {} mean {}, last {} mean {} ({:+.1f} %); {} and {} samples", first,
                       HumanBytes(m.first_window_mean), last, HumanBytes(m.last_window_mean),
                       m.mean_growth_percent, m.first_window_samples, m.last_window_samples));
      line(fmt::format("  first {} median {}, last {} median {} ({:+.1f} %)", first,
                       HumanBytes(static_cast<double>(m.first_window_median)), last,
                       HumanBytes(static_cast<double>(m.last_window_median)), m.median_growth_percent));
      if (m.first_window_allocated_mean > 0.0)
        line(fmt::format(
            "  first {} allocated {}, last {} allocated {} ({:+.1f} %) (the allocator's live bytes)", first,
            HumanBytes(m.first_window_allocated_mean), last, HumanBytes(m.last_window_allocated_mean),
            m.allocated_growth_percent));
      if (m.first_window_calls_in_flight > 0.0)
        line(fmt::format(
            "  first {} {:.2f} calls in flight, last {} {:.2f}: live bytes per call in flight {:+.1f} %",
            first, m.first_window_calls_in_flight, last, m.last_window_calls_in_flight,
            m.allocated_per_call_growth_percent));
    }
  }
  return out;
}

std::string FormatLoadReportJson(const LoadReport& r) {
  nlohmann::json j;
  j["rpc"] = r.rpc;
  j["method"] = r.method;
  j["target"] = r.target;
  j["concurrency"] = r.concurrency;
  j["clouds"] = r.clouds;
  j["mean_cloud_bytes"] = r.mean_cloud_bytes;
  j["warmup"] = r.warmup;
  j["rate"] = r.rate;
  j["max_start_lag_seconds"] = r.max_start_lag_seconds;
  j["count"] = r.total;
  j["ok"] = r.ok;
  j["total_seconds"] = r.elapsed_seconds;
  j["requests_per_second"] = r.requests_per_second;
  j["ok_per_second"] = r.ok_per_second;
  const LatencySummary& l = r.latency;
  j["latency_seconds"] = {{"min", l.min}, {"mean", l.mean}, {"p50", l.p50}, {"p90", l.p90},
                          {"p95", l.p95}, {"p99", l.p99},   {"max", l.max}};
  j["status_counts"] = r.status_counts;
  j["error_examples"] = r.error_examples;
  nlohmann::json by_rpc = nlohmann::json::array();
  for (const RpcReport& b : r.by_rpc) {
    const LatencySummary& bl = b.latency;
    by_rpc.push_back({{"rpc", b.rpc},
                      {"method", b.method},
                      {"count", b.total},
                      {"ok", b.ok},
                      {"status_counts", b.status_counts},
                      {"latency_seconds",
                       {{"min", bl.min},
                        {"mean", bl.mean},
                        {"p50", bl.p50},
                        {"p90", bl.p90},
                        {"p95", bl.p95},
                        {"p99", bl.p99},
                        {"max", bl.max}}}});
  }
  j["by_rpc"] = by_rpc;
  if (r.rss) {
    const RssSummary& m = *r.rss;
    nlohmann::json samples = nlohmann::json::array();
    for (const RssSample& s : m.samples) {
      nlohmann::json sample = {{"seconds", s.seconds}, {"bytes", s.bytes}};
      if (s.allocated_bytes > 0) sample["allocated_bytes"] = s.allocated_bytes;
      samples.push_back(std::move(sample));
    }
    j["server_rss"] = {{"url", m.url},
                       {"interval_seconds", m.interval_seconds},
                       {"window_seconds", m.window_seconds},
                       {"settle_seconds", m.settle_seconds},
                       {"first_window_max_bytes", m.first_window_max},
                       {"last_window_max_bytes", m.last_window_max},
                       {"peak_bytes", m.peak},
                       {"growth_percent", m.growth_percent},
                       {"end_seconds", m.end_seconds},
                       {"first_window_samples", m.first_window_samples},
                       {"last_window_samples", m.last_window_samples},
                       {"first_window_mean_bytes", m.first_window_mean},
                       {"last_window_mean_bytes", m.last_window_mean},
                       {"mean_growth_percent", m.mean_growth_percent},
                       {"first_window_median_bytes", m.first_window_median},
                       {"last_window_median_bytes", m.last_window_median},
                       {"median_growth_percent", m.median_growth_percent},
                       {"first_window_allocated_mean_bytes", m.first_window_allocated_mean},
                       {"last_window_allocated_mean_bytes", m.last_window_allocated_mean},
                       {"allocated_growth_percent", m.allocated_growth_percent},
                       {"first_window_calls_in_flight", m.first_window_calls_in_flight},
                       {"last_window_calls_in_flight", m.last_window_calls_in_flight},
                       {"allocated_per_call_growth_percent", m.allocated_per_call_growth_percent},
                       {"failed_scrapes", m.failed_scrapes},
                       {"samples", samples}};
  }
  nlohmann::json calls = nlohmann::json::array();
  for (const CallTiming& c : r.calls)
    calls.push_back({{"start_unix_seconds", c.start_unix_seconds}, {"seconds", c.seconds}, {"code", c.code}});
  j["calls"] = calls;
  return j.dump(2) + "\n";
}

}  // namespace tubepick::cli

#include "clients/cli/load/load_command.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "clients/cli/inputs/cli_inputs.h"
#include "clients/cli/load/load_engine.h"
#include "core/common/errors.h"

namespace tubepick::cli {
namespace {

struct LoadCommandOptions {
  LoadOptions load;
  std::string clouds_dir;
  std::string rpc = "plan";
  std::string unit;
  std::string json_path;
  std::uint64_t seed = 0;
  std::size_t chunk_kib = 1024;
  bool fail_on_error = false;
  /// Fail when the server's mean RSS grows more than this, percent; unset = no memory check.
  std::optional<double> max_rss_growth;
  /// Fail when the server's mean live bytes (the allocator's) grow more than this, percent; unset = no check.
  std::optional<double> max_allocated_growth;
};

v1::LengthUnit ProtoUnit(const std::string& unit) {
  if (unit.empty()) return v1::LENGTH_UNIT_UNSPECIFIED;
  return ParseLengthUnit(unit, "--unit") == LengthUnit::kMillimetre ? v1::LENGTH_UNIT_MILLIMETRE
                                                                    : v1::LENGTH_UNIT_METRE;
}

void Run(LoadCommandOptions& o, bool seed_given) {
  o.load.rpcs = ParseLoadRpcs(o.rpc);
  if (seed_given) o.load.seed = o.seed;
  o.load.chunk_bytes = o.chunk_kib * 1024;
  const std::vector<LoadCloud> clouds = ReadLoadClouds(o.clouds_dir, ProtoUnit(o.unit));
  fmt::print(
      stderr, "load: {} clouds from {}, {} {} to {} at concurrency {}\n", clouds.size(), o.clouds_dir,
      o.load.total ? fmt::format("{} calls", o.load.total) : fmt::format("{} s of", o.load.duration_seconds),
      o.rpc, o.load.channel.target, o.load.concurrency);
  const LoadReport report = RunLoad(o.load, clouds);
  fmt::print("{}", FormatLoadReportText(report));
  if (!o.json_path.empty()) {
    WriteTextFile(o.json_path, FormatLoadReportJson(report));
    fmt::print("wrote {}\n", o.json_path);
  }
  bool failed = false;
  if (o.fail_on_error && report.ok < report.total) {
    fmt::print(stderr, "load: {} of {} calls failed\n", report.total - report.ok, report.total);
    failed = true;
  }
  // Half the scrapes a window should hold, at least 3: fewer means the endpoint was not answering.
  const auto min_samples = static_cast<std::size_t>(
      std::max(3.0, std::floor(0.5 * o.load.rss_window_seconds / o.load.metrics_interval_seconds)));
  if (o.max_rss_growth && report.rss) {
    if (const auto failure = RssGrowthFailure(*report.rss, *o.max_rss_growth, min_samples)) {
      fmt::print(stderr, "load: {}\n", *failure);
      failed = true;
    }
  }
  if (o.max_allocated_growth && report.rss) {
    if (const auto failure = AllocatedGrowthFailure(*report.rss, *o.max_allocated_growth, min_samples)) {
      fmt::print(stderr, "load: {}\n", *failure);
      failed = true;
    }
  }
  if (failed) throw CLI::RuntimeError(1);
}

}  // namespace

void AddLoadCommand(CLI::App& app) {
  auto o = std::make_shared<LoadCommandOptions>();
  CLI::App* cmd = app.add_subcommand("load", "Load-test a tubepick-server with recorded clouds (like ghz)");
  AddChannelOptions(cmd, o->load.channel);
  cmd->add_option("--clouds", o->clouds_dir,
                  "Directory of PLY/PCD clouds, searched recursively (e.g. `tubepick scene` outputs)")
      ->required()
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--unit", o->unit, "Unit sent with the clouds (default: the server's cell unit)")
      ->check(CLI::IsMember({"m", "mm"}));
  cmd->add_option("--rpc", o->rpc,
                  "RPC to call: plan, model or plan-stream; a comma list (plan,plan-stream) is a fixed mix, "
                  "the threads shared out evenly (--concurrency a multiple of its length)")
      ->check(CLI::Validator(
          [](std::string& value) -> std::string {
            try {
              ParseLoadRpcs(value);
            } catch (const InvalidArgument& e) {
              const std::string what = e.what();  // CLI11 names the option itself
              return what.rfind("--rpc: ", 0) == 0 ? what.substr(7) : what;
            }
            return {};
          },
          "RPC[,RPC...]"))
      ->capture_default_str();
  cmd->add_option("-c,--concurrency", o->load.concurrency, "Calls in flight at once (one thread each)")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  auto* total =
      cmd->add_option("-n,--total", o->load.total, "Number of measured calls")->check(CLI::PositiveNumber);
  auto* duration = cmd->add_option("-z,--duration", o->load.duration_seconds,
                                   "Measured run length, seconds (no call starts after it)")
                       ->check(CLI::PositiveNumber);
  total->excludes(duration);
  duration->excludes(total);
  cmd->add_option(
         "--rate", o->load.rate,
         "Calls per second to start in the measured phase, open loop (0 = each thread calls again as soon "
         "as its call ends); --concurrency caps the calls in flight")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--warmup", o->load.warmup, "Calls before measuring (not counted)")->capture_default_str();
  cmd->add_option("--deadline", o->load.deadline_seconds, "Deadline of each call, seconds (0 = none)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_flag("--no-sim", o->load.disable_simulation, "PlanningOptions.disable_simulation");
  cmd->add_option("--profile", o->load.profile, "PlanningOptions.profile (default: the server's)")
      ->check(CLI::IsMember({"fast", "thesis"}));
  auto* seed = cmd->add_option("--seed", o->seed, "PlanningOptions.seed (default: the server's)");
  cmd->add_option("--max-plans", o->load.max_plans, "PlanningOptions.max_plans (0 = all)")
      ->capture_default_str();
  cmd->add_option("--chunk-kib", o->chunk_kib, "PlanPickStream chunk size, KiB")
      ->check(CLI::Range(1, 65536))
      ->capture_default_str();
  cmd->add_flag("--fail-on-error", o->fail_on_error, "Exit 1 when any measured call failed (smoke tests)");
  cmd->add_option("--json", o->json_path, "Also write the report as JSON to this file");
  auto* metrics_url = cmd->add_option(
      "--metrics-url", o->load.metrics_url,
      "Server's Prometheus endpoint (http://HOST:PORT/metrics): sample its RSS during the run");
  cmd->add_option("--metrics-interval", o->load.metrics_interval_seconds, "RSS sampling period, seconds")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--rss-window", o->load.rss_window_seconds,
                  "Length of the first and last windows of the run whose RSS samples are compared, seconds")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--rss-settle", o->load.rss_settle_seconds,
                  "Begin the first RSS window this long after sampling starts, seconds (the allocator's "
                  "memory climbs for a while under fresh load)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  cmd->add_option("--max-rss-growth", o->max_rss_growth,
                  "Exit 1 when the mean RSS of the last window exceeds that of the first by more than this, "
                  "percent (needs --metrics-url)")
      ->check(CLI::NonNegativeNumber)
      ->needs(metrics_url);
  cmd->add_option("--max-allocated-growth", o->max_allocated_growth,
                  "Exit 1 when the server's mean live bytes (tubepick_allocator_allocated_bytes) per call "
                  "in flight of the last window exceed those of the first by more than this, percent, or it "
                  "does not export them (needs --metrics-url)")
      ->check(CLI::NonNegativeNumber)
      ->needs(metrics_url);
  cmd->add_option("--connect-timeout", o->load.connect_timeout_seconds,
                  "Give up connecting after this, seconds")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->callback([o, seed, total, duration] {
    if (total->count() == 0 && duration->count() == 0)
      throw InvalidArgument("load: give --total N or --duration D");
    Run(*o, seed->count() > 0);
  });
}

}  // namespace tubepick::cli

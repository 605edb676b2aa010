#include "clients/cli/load/bench_service.h"

#include <fmt/core.h>
#include <grpcpp/grpcpp.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "clients/cli/inputs/builtin_scene.h"
#include "clients/cli/inputs/cli_inputs.h"
#include "clients/cli/load/load_engine.h"
#include "clients/cli/remote/channel.h"
#include "clients/cli/remote/server_process.h"
#include "core/common/errors.h"
#include "core/common/thread_budget.h"
#include "core/modeling/cloud_io.h"
#include "core/modeling/model_tubes.h"
#include "core/params.h"
#include "core/planning/pick_planner.h"
#include "core/planning/plan_placement.h"
#include "tubepick/v1/service.grpc.pb.h"
#include "wire/packed_cloud.h"

namespace tubepick::cli {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct ServiceBenchOptions {
  std::string clouds_dir;
  std::uint32_t scenes = 3;
  std::uint32_t tubes = 10;
  std::uint32_t calls = 12;
  std::vector<std::uint32_t> concurrency{1, 2};
  std::uint32_t peak_concurrency = 4;
  std::vector<std::string> profiles{"fast", "thesis"};
  std::uint32_t workers = 0;
  std::uint32_t threads_per_call = 0;
  std::string json_path;
};

struct BenchCloud {
  std::string name;
  Points points_Sensor;
};

// Stage → seconds of one call; "total" is the sum that the ratio uses.
using Stages = std::map<std::string, double>;

/// Samples of one (profile, path, concurrency) cell of the tables.
struct PathFigures {
  std::map<std::string, std::vector<double>> stages;  // per stage, one sample per call
  std::vector<double> pack, call, server, rest;       // client pack, whole call, server side, rest
  double wall = 0.0;                                  // the run's wall time
  std::uint32_t calls = 0, failed = 0;
  std::string first_error;
};

std::vector<BenchCloud> LoadClouds(const ServiceBenchOptions& o) {
  std::vector<BenchCloud> clouds;
  if (!o.clouds_dir.empty()) {
    for (const LoadCloud& c : ReadLoadClouds(o.clouds_dir, v1::LENGTH_UNIT_METRE))
      clouds.push_back({c.name, UnpackXyz(c.xyz)});
    return clouds;
  }
  for (std::uint32_t s = 1; s <= o.scenes; ++s) {
    BuiltInScene scene = MakeBuiltInScene(CellConfig{}, o.tubes, s);
    clouds.push_back({scene.description, std::move(scene.points_Sensor)});
  }
  return clouds;
}

// Modeling, planning without simulation and placements, as RunPlanPick does them, on a fresh copy
// of the packed cloud (the server also reads a buffer it has just received).
Stages InProcessCall(const BenchCloud& cloud, const Params& params, std::uint32_t threads) {
  const CellConfig cell;
  const std::string xyz = PackXyz(cloud.points_Sensor);
  const Clock::time_point t0 = Clock::now();
  ModelingInput input = ModelingInputFor(cell);
  input.xyz_Sensor = PackedXyz{xyz};
  input.raw_region_Bin = RawRegionForPlanning(params.planning, cell.bin);
  ModelingParams modeling_params = params.modeling;
  modeling_params.threads = threads;
  const ModelingResult modeling = ModelTubes(input, modeling_params);
  PickPlanResult plan = PlanPick(modeling, cell, params.planning, nullptr, 0);
  const Clock::time_point tp = Clock::now();
  AttachPlacements(modeling, cell.place.X_BinPlace, params.placement, &plan);
  Stages stages;
  for (const StageTiming& t : modeling.timings) stages[t.stage] += t.seconds;
  for (const StageTiming& t : plan.timings) stages[t.stage] += t.seconds;
  stages["placement"] = SecondsSince(tp);
  stages["total"] = SecondsSince(t0);
  return stages;
}

PathFigures RunInProcess(const std::vector<BenchCloud>& clouds, const Params& params, std::uint32_t calls,
                         std::uint32_t threads) {
  PathFigures f;
  const Clock::time_point start = Clock::now();
  for (std::uint32_t i = 0; i < calls; ++i) {
    for (const auto& [stage, seconds] : InProcessCall(clouds[i % clouds.size()], params, threads))
      f.stages[stage].push_back(seconds);
    ++f.calls;
  }
  f.wall = SecondsSince(start);
  return f;
}

struct CallSample {
  Stages server;  // per stage, and "total"
  double pack = 0.0, call = 0.0;
  bool ok = false;
  std::string error;
};

// PlanPick as a client makes it: pack the points, call, read the stage timings of the answer.
CallSample ServiceCall(v1::PickPlannerService::Stub& stub, const BenchCloud& cloud,
                       const std::string& profile) {
  CallSample sample;
  const Clock::time_point t0 = Clock::now();
  v1::PlanPickRequest request;
  request.mutable_options()->set_profile(profile);
  request.mutable_options()->set_seed(0);
  request.mutable_options()->set_disable_simulation(true);
  request.mutable_cloud()->set_unit(v1::LENGTH_UNIT_METRE);
  request.mutable_cloud()->set_xyz(PackXyz(cloud.points_Sensor));
  sample.pack = SecondsSince(t0);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::minutes(2));
  v1::PlanPickResponse response;
  const Clock::time_point t1 = Clock::now();
  const grpc::Status status = stub.PlanPick(&context, request, &response);
  sample.call = SecondsSince(t1);
  sample.ok = status.ok();
  if (!sample.ok) {
    sample.error = status.error_message();
    return sample;
  }
  double total = response.modeling().total_seconds();
  for (const v1::StageTiming& t : response.modeling().stage_timings())
    sample.server[t.stage()] += t.seconds();
  for (const v1::StageTiming& t : response.stage_timings()) {
    sample.server[t.stage()] += t.seconds();
    total += t.seconds();
  }
  sample.server["total"] = total;
  return sample;
}

PathFigures RunService(const std::shared_ptr<grpc::Channel>& channel, const std::vector<BenchCloud>& clouds,
                       const std::string& profile, std::uint32_t calls, std::uint32_t concurrency) {
  PathFigures f;
  std::mutex mu;
  std::atomic<std::uint32_t> next{0};
  const Clock::time_point start = Clock::now();
  std::vector<std::thread> threads;
  for (std::uint32_t t = 0; t < concurrency; ++t) {
    threads.emplace_back([&] {
      auto stub = v1::PickPlannerService::NewStub(channel);
      for (std::uint32_t i = next++; i < calls; i = next++) {
        const CallSample s = ServiceCall(*stub, clouds[i % clouds.size()], profile);
        std::lock_guard lock(mu);
        ++f.calls;
        if (!s.ok) {
          if (f.failed++ == 0) f.first_error = s.error;
          continue;
        }
        for (const auto& [stage, seconds] : s.server) f.stages[stage].push_back(seconds);
        f.pack.push_back(s.pack);
        f.call.push_back(s.call);
        f.rest.push_back(s.call - s.server.at("total"));
      }
    });
  }
  for (std::thread& t : threads) t.join();
  f.wall = SecondsSince(start);
  return f;
}

// VmHWM of a process, MiB (0 when unreadable).
double PeakRssMiB(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return 0.0;
}

std::unique_ptr<ServerProcess> StartServer(const ServiceBenchOptions& o, std::string* config_path) {
  *config_path = (std::filesystem::temp_directory_path() /
                  fmt::format("tubepick-bench-service-{}.yaml", static_cast<long>(::getpid())))
                     .string();
  std::ofstream(*config_path) << fmt::format("server:\n  workers: {}\n  threads_per_call: {}\n", o.workers,
                                             o.threads_per_call);
  return ServerProcess::Start(
      SiblingExecutable("tubepick-server"),
      {"--config", *config_path, "--address", "127.0.0.1:0", "--metrics-address", "", "--log-level", "info"},
      std::chrono::seconds(60));
}

// The stage rows of the tables, in pipeline order; the rest follow alphabetically.
std::vector<std::string> StageOrder(const std::vector<const PathFigures*>& paths) {
  const std::vector<std::string> known = {
      "prepare",      "filter",      "normals", "segmentation", "cylinders", "joining",   "classification",
      "trajectories", "cloud_index", "grasps",  "simulation",   "ranking",   "placement", "response"};
  std::vector<std::string> order;
  for (const std::string& s : known) {
    for (const PathFigures* p : paths) {
      if (p->stages.count(s) != 0) {
        order.push_back(s);
        break;
      }
    }
  }
  for (const PathFigures* p : paths) {
    for (const auto& [stage, samples] : p->stages) {
      if (stage != "total" && std::find(order.begin(), order.end(), stage) == order.end())
        order.push_back(stage);
    }
  }
  return order;
}

std::string Cell(const PathFigures& f, const std::string& stage) {
  const auto it = f.stages.find(stage);
  return it == f.stages.end() ? "" : fmt::format("{:.4f}", Median(it->second));
}

/// One profile's table: stages and totals, in-process against each concurrency.
nlohmann::json PrintProfile(const std::string& profile, const PathFigures& local,
                            const std::vector<std::pair<std::uint32_t, PathFigures>>& service) {
  std::vector<const PathFigures*> all{&local};
  std::string header = "| median, s | in-process", rule = "|---|---";
  for (const auto& [c, f] : service) {
    all.push_back(&f);
    header += fmt::format(" | service c = {}", c);
    rule += "|---";
  }
  fmt::print("\nprofile {}: {} calls per column\n\n{} |\n{}|\n", profile, local.calls, header, rule);
  const auto row = [&](const std::string& name, auto&& value) {
    std::string line = "| " + name;
    for (const PathFigures* f : all) line += " | " + value(*f);
    fmt::print("{} |\n", line);
  };
  for (const std::string& stage : StageOrder(all))
    row(stage, [&](const PathFigures& f) { return Cell(f, stage); });
  const double base = Median(local.stages.at("total"));
  row("**pipeline / server side**", [&](const PathFigures& f) {
    const double t = Median(f.stages.at("total"));
    return &f == &local ? fmt::format("**{:.4f}**", t) : fmt::format("**{:.4f}** ({:.2f}×)", t, t / base);
  });
  row("client: pack",
      [](const PathFigures& f) { return f.pack.empty() ? "" : fmt::format("{:.4f}", Median(f.pack)); });
  row("transfer, parse, queue",
      [](const PathFigures& f) { return f.rest.empty() ? "" : fmt::format("{:.4f}", Median(f.rest)); });
  row("**whole call**", [&](const PathFigures& f) {
    return f.call.empty() ? "" : fmt::format("**{:.4f}** ({:.2f}×)", Median(f.call), Median(f.call) / base);
  });
  row("plans/s", [](const PathFigures& f) { return fmt::format("{:.2f}", (f.calls - f.failed) / f.wall); });
  nlohmann::json j;
  j["in_process"] = {{"median_seconds", base}, {"plans_per_second", local.calls / local.wall}};
  for (const auto& [c, f] : service) {
    if (f.failed > 0)
      fmt::print("service c = {}: {} of {} calls failed: {}\n", c, f.failed, f.calls, f.first_error);
    j["service"].push_back({{"concurrency", c},
                            {"server_median_seconds", Median(f.stages.at("total"))},
                            {"call_median_seconds", Median(f.call)},
                            {"pack_median_seconds", Median(f.pack)},
                            {"plans_per_second", (f.calls - f.failed) / f.wall},
                            {"failed", f.failed}});
  }
  return j;
}

void RunServiceBench(ServiceBenchOptions o) {
  const int cores = CoresAvailable();
  if (o.workers == 0) o.workers = static_cast<std::uint32_t>(cores);
  if (o.threads_per_call == 0) o.threads_per_call = std::max<std::uint32_t>(1, cores / o.workers);
  const std::vector<BenchCloud> clouds = LoadClouds(o);
  std::string config_path;
  std::unique_ptr<ServerProcess> server = StartServer(o, &config_path);
  ChannelOptions channel_options;
  channel_options.target = server->address();
  const auto channel = MakeChannel(channel_options);
  fmt::print(
      "bench service: {} clouds ({} points first), tubepick-server pid {} on {}: {} workers x {} threads "
      "per call, {} cores; in-process on {} threads; no warm-up\n",
      clouds.size(), clouds.front().points_Sensor.size(), server->pid(), server->address(), o.workers,
      o.threads_per_call, cores, o.threads_per_call);
  nlohmann::json report;
  std::map<std::string, double> local_total, call_total;
  for (const std::string& profile : o.profiles) {
    CommonOptions common;
    common.profile = profile;
    const Params params = LoadParamsFor(common);
    const PathFigures local = RunInProcess(clouds, params, o.calls, o.threads_per_call);
    std::vector<std::pair<std::uint32_t, PathFigures>> service;
    for (const std::uint32_t c : o.concurrency)
      service.emplace_back(c, RunService(channel, clouds, profile, o.calls, c));
    report["profiles"][profile] = PrintProfile(profile, local, service);
    local_total[profile] = Median(local.stages.at("total"));
    call_total[profile] = Median(service.front().second.call);
  }
  if (o.profiles.size() > 1) {
    const std::string& ref = o.profiles.front();
    for (std::size_t i = 1; i < o.profiles.size(); ++i) {
      const std::string& p = o.profiles[i];
      fmt::print(
          "\n{} / {}: {:.1f}× in-process, {:.1f}× whole call at c = {} (ratios of medians, same run)\n", p,
          ref, local_total[p] / local_total[ref], call_total[p] / call_total[ref], o.concurrency.front());
    }
  }
  const PathFigures peak = RunService(channel, clouds, o.profiles.front(), o.calls, o.peak_concurrency);
  const double peak_rss = PeakRssMiB(server->pid());
  fmt::print(
      "\nserver peak RSS over the whole run (the last {} calls at c = {}, {:.2f} plans/s): {:.0f} MiB\n",
      peak.calls, o.peak_concurrency, (peak.calls - peak.failed) / peak.wall, peak_rss);
  report["server_peak_rss_mib"] = peak_rss;
  const int exit_status = server->Stop(std::chrono::seconds(10));
  std::filesystem::remove(config_path);
  if (exit_status != 0) throw std::runtime_error(fmt::format("tubepick-server exited with {}", exit_status));
  if (!o.json_path.empty()) WriteTextFile(o.json_path, report.dump(2) + "\n");
}

}  // namespace

void AddBenchServiceCommand(CLI::App& bench) {
  auto o = std::make_shared<ServiceBenchOptions>();
  CLI::App* cmd = bench.add_subcommand(
      "service", "PlanPick through a real tubepick-server against the in-process pipeline, per stage");
  cmd->add_option("--clouds", o->clouds_dir,
                  "Directory of PLY/PCD clouds (metres) instead of built-in scenes")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--scenes", o->scenes, "Built-in scenes (seeds 1..N)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  cmd->add_option("--tubes", o->tubes, "Tubes per built-in scene")
      ->check(CLI::Range(1, 30))
      ->capture_default_str();
  cmd->add_option("--calls", o->calls, "Calls per column")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--concurrency", o->concurrency, "Service concurrencies (space- or comma-separated)")
      ->delimiter(',')
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_option("--peak-concurrency", o->peak_concurrency, "Concurrency of the last run (peak RSS)")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_option("--profiles", o->profiles, "Profiles, the first the reference (space- or comma-separated)")
      ->delimiter(',')
      ->check(CLI::IsMember(ProfileNames()))
      ->capture_default_str();
  cmd->add_option("--workers", o->workers, "Server workers (0 = the cores)")->capture_default_str();
  cmd->add_option("--threads-per-call", o->threads_per_call,
                  "Threads per call, server and in-process (0 = cores / workers)")
      ->capture_default_str();
  cmd->add_option("--json", o->json_path, "Also write the figures as JSON");
  cmd->callback([o] { RunServiceBench(*o); });
}

}  // namespace tubepick::cli

#include "clients/cli/bench_command.h"

#include <fmt/core.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <thread>

#include "clients/cli/builtin_scene.h"
#include "clients/cli/cli_inputs.h"
#include "core/modeling/cloud_io.h"
#include "core/modeling/model_tubes.h"

namespace tubepick::cli {
namespace {

struct BenchOptions {
  CommonOptions common;
  std::string cloud_path;
  std::uint32_t tubes = 10;
  std::uint32_t repetitions = 7;
  std::vector<std::string> profiles{"fast", "thesis"};
};

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0.0 : (n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]));
}

double PeakRssMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // ru_maxrss is in KiB on Linux
}

struct ProfileFigures {
  std::map<std::string, double> stage_median;
  std::vector<std::string> stage_order;
  double total_median = 0.0;
  std::size_t tubes = 0;
  std::size_t filtered = 0;
  double peak_rss_mib = 0.0;
};

void RunBench(const BenchOptions& o) {
  const CellConfig cell = LoadCell(o.common);
  Points points_Sensor;
  LengthUnit unit = cell.sensor.unit;
  std::string source;
  if (o.cloud_path.empty()) {
    BuiltInScene scene = MakeBuiltInScene(cell, o.tubes, o.common.seed);
    points_Sensor = std::move(scene.points_Sensor);
    unit = LengthUnit::kMetre;
    source = scene.description;
  } else {
    points_Sensor = ReadCloudFile(o.cloud_path).points;
    source = o.cloud_path;
  }
  fmt::print("bench modeling: {} ({} points), {} repetitions after 1 warm-up, {} hardware threads\n", source,
             points_Sensor.size(), o.repetitions, std::thread::hardware_concurrency());

  ModelingInput input;
  input.points_Sensor = &points_Sensor;
  input.unit = unit;
  input.X_BinSensor = cell.sensor.X_BinSensor;
  input.bin = cell.bin;
  input.seed = o.common.seed;

  std::vector<ProfileFigures> figures;
  for (const std::string& profile : o.profiles) {
    CommonOptions common = o.common;
    common.profile = profile;
    const Params params = LoadParamsFor(common);
    std::map<std::string, std::vector<double>> stage_samples;
    std::vector<double> totals;
    ProfileFigures f;
    for (std::uint32_t rep = 0; rep <= o.repetitions; ++rep) {
      const auto t0 = std::chrono::steady_clock::now();
      const ModelingResult r = ModelTubes(input, params.modeling);
      const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (rep == 0) {  // warm-up
        f.tubes = r.tubes.size();
        f.filtered = r.filtered.size();
        for (const auto& s : r.timings) f.stage_order.push_back(s.stage);
        continue;
      }
      for (const auto& s : r.timings) stage_samples[s.stage].push_back(s.seconds);
      totals.push_back(total);
    }
    for (const auto& [stage, samples] : stage_samples) f.stage_median[stage] = Median(samples);
    f.total_median = Median(totals);
    f.peak_rss_mib = PeakRssMiB();
    figures.push_back(f);
  }

  fmt::print("\n| stage (median s) |");
  for (const auto& p : o.profiles) fmt::print(" {} |", p);
  fmt::print("\n|---|");
  for (std::size_t i = 0; i < o.profiles.size(); ++i) fmt::print("---|");
  fmt::print("\n");
  for (const std::string& stage : figures.front().stage_order) {
    fmt::print("| {} |", stage);
    for (const auto& f : figures)
      fmt::print(" {:.4f} |", f.stage_median.count(stage) ? f.stage_median.at(stage) : 0.0);
    fmt::print("\n");
  }
  fmt::print("| **total** |");
  for (const auto& f : figures) fmt::print(" **{:.4f}** |", f.total_median);
  fmt::print("\n| filtered points |");
  for (const auto& f : figures) fmt::print(" {} |", f.filtered);
  fmt::print("\n| tubes found |");
  for (const auto& f : figures) fmt::print(" {} |", f.tubes);
  fmt::print("\n| process peak RSS after this profile (MiB) |");
  for (const auto& f : figures) fmt::print(" {:.0f} |", f.peak_rss_mib);
  fmt::print("\n\n");
  for (std::size_t i = 1; i < figures.size(); ++i) {
    fmt::print("speed-up {} over {}: {:.1f}x (ratio of medians, same run)\n", o.profiles[0], o.profiles[i],
               figures[i].total_median / std::max(1e-9, figures[0].total_median));
  }
}

}  // namespace

void AddBenchCommand(CLI::App& app) {
  CLI::App* bench = app.add_subcommand("bench", "Benchmarks that print figures (medians, ratios, memory)");
  bench->require_subcommand(1);
  auto o = std::make_shared<BenchOptions>();
  CLI::App* cmd = bench->add_subcommand("modeling", "Modeling pipeline on a ~2 M-point scene, per profile");
  cmd->add_option("--cloud", o->cloud_path, "Cloud to model instead of the built-in scene")
      ->check(CLI::ExistingFile);
  cmd->add_option("--cell", o->common.cell_path, "Cell YAML")->check(CLI::ExistingFile);
  cmd->add_option("--tubes", o->tubes, "Tubes in the built-in scene")->capture_default_str();
  cmd->add_option("--seed", o->common.seed, "Scene and modeling seed")->capture_default_str();
  cmd->add_option("--repetitions", o->repetitions, "Timed runs per profile")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  cmd->add_option("--profiles", o->profiles, "Profiles to compare; the first is the reference")
      ->capture_default_str();
  cmd->callback([o] { RunBench(*o); });
}

}  // namespace tubepick::cli

#include "clients/cli/local/bench_command.h"

#include <fmt/core.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <map>
#include <memory>
#include <thread>

#include "clients/cli/inputs/builtin_scene.h"
#include "clients/cli/inputs/cli_inputs.h"
#include "core/modeling/cloud_io.h"
#include "core/modeling/model_tubes.h"
#include "core/planning/classification.h"
#include "core/planning/pick_planner.h"
#include "core/planning/trajectory_synthesis.h"
#include "physics/trajectory_simulator.h"

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

  const ModelingInput input = MakeModelingInput(points_Sensor, unit, cell, o.common.seed, RawRegion::None());

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

template <typename F>
double MedianSeconds(std::uint32_t repetitions, F&& run) {
  run();  // warm-up
  std::vector<double> samples;
  for (std::uint32_t i = 0; i < repetitions; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    run();
    samples.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return Median(samples);
}

struct PlanBenchOptions {
  CommonOptions common;
  std::uint32_t tubes = 10;
  std::uint32_t repetitions = 5;
  std::uint32_t trajectories = 15;
};

// The whole plan without simulation (modeling + planning), and the simulation a plan needs when
// every tube is occluded: `trajectories` candidates of the scene's tubes evaluated in Bullet.
void RunPlanBench(const PlanBenchOptions& o) {
  const CellConfig cell = LoadCell(o.common);
  const Params params = LoadParamsFor(o.common);
  BuiltInScene scene = MakeBuiltInScene(cell, o.tubes, o.common.seed);
  const ModelingInput input =
      MakeModelingInput(scene.points_Sensor, LengthUnit::kMetre, cell, o.common.seed,  // scanner: metres
                        RawRegionForPlanning(params.planning, cell.bin));
  fmt::print("bench plan: {} ({} points), profile {}, {} repetitions after 1 warm-up\n", scene.description,
             scene.points_Sensor.size(), o.common.profile, o.repetitions);

  ModelingResult modeling;
  const double t_model = MedianSeconds(o.repetitions, [&] { modeling = ModelTubes(input, params.modeling); });
  PickPlanResult plan;
  const double t_plan = MedianSeconds(
      o.repetitions, [&] { plan = PlanPick(modeling, cell, params.planning, nullptr, o.common.seed); });

  // Candidate trajectories as the planner synthesises them, for every tube (occluded or not).
  const ClassificationResult classes =
      ClassifyTubes(modeling.tubes, cell.tube.length, params.planning.classification);
  const SafetyZone zone = MakeSafetyZone(cell.bin, params.planning.trajectories.safety_margin);
  std::vector<Trajectory> candidates;
  for (std::uint32_t i = 0; i < classes.tubes.size(); ++i) {
    for (Trajectory& t : SynthesizeTrajectories(i, classes.tubes[i], classes.classes[i], cell.tube.radius,
                                                zone, params.planning.trajectories)) {
      candidates.push_back(std::move(t));
    }
  }
  // Escapes first (they are what simulation is for), then upward lifts.
  std::stable_sort(candidates.begin(), candidates.end(), [](const Trajectory& a, const Trajectory& b) {
    return (a.kind != TrajectoryKind::kUpward) > (b.kind != TrajectoryKind::kUpward);
  });
  if (candidates.size() > o.trajectories) candidates.resize(o.trajectories);

  std::vector<double> sim_seconds;
  double displacement_sum = 0.0;
  for (int threads : {1, 2}) {
    physics::BulletTrajectoryEvaluator evaluator(
        physics::SimParamsForCell({}, cell, params.planning.cost.max_displacement, threads));
    std::vector<TrajectoryOutcome> outcomes;
    sim_seconds.push_back(MedianSeconds(o.repetitions, [&] {
      outcomes = evaluator.Evaluate(classes.tubes, candidates, o.common.seed, nullptr);
    }));
    displacement_sum = 0.0;
    for (const auto& out : outcomes) displacement_sum += out.displacement;
  }

  fmt::print("\n| figure (median) | value |\n|---|---|\n");
  fmt::print("| modeling | {:.4f} s |\n", t_model);
  fmt::print("| planning without simulation ({} plans{}) | {:.4f} s |\n", plan.plans.size(),
             plan.used_simulation ? ", simulated" : "", t_plan);
  fmt::print("| whole plan without simulation (modeling + planning) | {:.4f} s = {:.1f} plans/s |\n",
             t_model + t_plan, 1.0 / (t_model + t_plan));
  fmt::print("| simulation of {} trajectories, 1 thread | {:.4f} s |\n", candidates.size(), sim_seconds[0]);
  fmt::print("| simulation of {} trajectories, 2 threads | {:.4f} s |\n", candidates.size(), sim_seconds[1]);
  fmt::print("| whole plan with simulation, 2 threads | {:.4f} s |\n", t_model + t_plan + sim_seconds[1]);
  fmt::print(
      "\n2-thread speed-up of the simulation: {:.2f}x; summed displacement of the candidates {:.3f} m\n",
      sim_seconds[0] / std::max(1e-9, sim_seconds[1]), displacement_sum);
}

}  // namespace

CLI::App* AddBenchCommand(CLI::App& app) {
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

  auto p = std::make_shared<PlanBenchOptions>();
  CLI::App* plan = bench->add_subcommand("plan", "Whole plan with and without trajectory simulation");
  plan->add_option("--cell", p->common.cell_path, "Cell YAML")->check(CLI::ExistingFile);
  plan->add_option("--profile", p->common.profile, "Parameter profile")
      ->check(CLI::IsMember({"fast", "thesis"}))
      ->capture_default_str();
  plan->add_option("--tubes", p->tubes, "Tubes in the built-in scene")->capture_default_str();
  plan->add_option("--seed", p->common.seed, "Scene and planning seed")->capture_default_str();
  plan->add_option("--repetitions", p->repetitions, "Timed runs")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  plan->add_option("--trajectories", p->trajectories, "Trajectories to simulate")->capture_default_str();
  plan->callback([p] { RunPlanBench(*p); });
  return bench;
}

}  // namespace tubepick::cli

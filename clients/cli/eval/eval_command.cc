#include "clients/cli/eval/eval_command.h"

#include <fmt/core.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "clients/cli/eval/eval_report.h"
#include "clients/cli/inputs/cli_inputs.h"
#include "clients/cli/inputs/scene_files.h"
#include "clients/cli/inputs/sim_scene.h"
#include "core/common/errors.h"
#include "core/common/thread_budget.h"
#include "core/evaluation/virtual_labelling.h"
#include "core/modeling/model_tubes.h"
#include "physics/trajectory_simulator.h"
#include "physics/tube_config_io.h"
#include "viewer/view_page.h"
#include "wire/response_convert.h"

namespace tubepick::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct EvalOptions {
  CommonOptions common;
  std::string scenes_dir;
  std::string generate;  // "1..10", "5", "1,3,5"
  std::string configs_dir;
  std::uint32_t per_count = 20;
  std::string preset = "A";
  std::string report_dir;
  std::string joining;         // "", "greedy", "global"
  std::string topology;        // "", "linear", "branched", "auto"
  std::string junction_shape;  // "", "any", "wye", "tee"
  std::uint32_t jobs = 1;
  std::uint32_t pictures_per_count = 2;
  /// Cloud points of each scene's 3-D page; 0 = no pages.
  std::uint32_t view_points = 50'000;
  /// Plan every scene and check the best plan against the ground truth.
  bool plans = false;
  std::string command_line;
};

// One scene to evaluate.
struct SceneJob {
  enum class Kind { kGenerated, kDirectory, kConfiguration } kind = Kind::kGenerated;
  std::string name;
  std::string path;
  std::uint32_t tubes = 0;
  std::uint64_t seed = 0;
};

std::vector<std::uint32_t> ParseCounts(const std::string& text) {
  std::vector<std::uint32_t> counts;
  auto parse_one = [&](const std::string& s) -> std::uint32_t {
    std::size_t used = 0;
    unsigned long v = 0;
    try {
      v = std::stoul(s, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != s.size() || v < 1 || v > 30) {
      throw InvalidArgument("--generate: expected tube counts 1..30 as 'A..B', 'N' or 'A,B,C', got '" + text +
                            "'");
    }
    return static_cast<std::uint32_t>(v);
  };
  const auto dots = text.find("..");
  if (dots != std::string::npos) {
    const std::uint32_t a = parse_one(text.substr(0, dots)), b = parse_one(text.substr(dots + 2));
    if (a > b) throw InvalidArgument("--generate: empty range '" + text + "'");
    for (std::uint32_t n = a; n <= b; ++n) counts.push_back(n);
    return counts;
  }
  std::size_t start = 0;
  while (start <= text.size()) {
    const auto comma = text.find(',', start);
    counts.push_back(
        parse_one(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return counts;
}

std::vector<SceneJob> ListJobs(const EvalOptions& o, std::string& source) {
  std::vector<SceneJob> jobs;
  if (!o.generate.empty()) {
    for (std::uint32_t n : ParseCounts(o.generate)) {
      for (std::uint32_t k = 0; k < o.per_count; ++k) {
        SceneJob job;
        job.kind = SceneJob::Kind::kGenerated;
        job.tubes = n;
        job.seed = o.common.seed + 1000ull * n + k;
        job.name = fmt::format("n{:02}_s{}", n, job.seed);
        jobs.push_back(job);
      }
    }
    source = fmt::format("generated: {} x {} scenes per count, preset {}, scene seed = {} + 1000 N + k",
                         o.generate, o.per_count, o.preset, o.common.seed);
  } else if (!o.scenes_dir.empty()) {
    for (const std::string& dir : FindSceneDirectories(o.scenes_dir)) {
      SceneJob job;
      job.kind = SceneJob::Kind::kDirectory;
      job.path = dir;
      std::string rel = fs::relative(dir, o.scenes_dir).generic_string();
      job.name = rel == "." ? fs::path(dir).filename().string() : rel;
      jobs.push_back(job);
    }
    if (jobs.empty())
      throw InvalidArgument("--scenes: no scene directory (cloud.ply + labels.txt + tubes.txt) in '" +
                            o.scenes_dir + "'");
    source = fmt::format("scene directories under {}", o.scenes_dir);
  } else {
    if (!fs::is_directory(o.configs_dir))
      throw InvalidArgument("--configs: '" + o.configs_dir + "' is not a directory");
    for (const auto& entry : fs::recursive_directory_iterator(o.configs_dir)) {
      if (!entry.is_regular_file() || entry.path().extension() != ".txt") continue;
      SceneJob job;
      job.kind = SceneJob::Kind::kConfiguration;
      job.path = entry.path().string();
      job.name = fs::relative(entry.path(), o.configs_dir).generic_string();
      jobs.push_back(job);
    }
    std::sort(jobs.begin(), jobs.end(), [](const SceneJob& a, const SceneJob& b) { return a.name < b.name; });
    if (jobs.empty())
      throw InvalidArgument("--configs: no .txt tube configuration in '" + o.configs_dir + "'");
    source = fmt::format("published tube configurations under {}, scanned in the cell with scan seed {}",
                         o.configs_dir, o.common.seed);
  }
  return jobs;
}

SceneSnapshot MakeSnapshot(const ModelingResult& result, const std::vector<std::int32_t>& truth_of_input,
                           const std::vector<physics::TubeGeometry>& tubes_Bin,
                           const EvaluationParams& eval_params, const BinConfig& bin) {
  SceneSnapshot s;
  const VirtualLabels labels =
      LabelVirtualTubes(result.filtered.points, result.tube_of_point, result.tubes, eval_params.labelling);
  const std::size_t n = result.filtered.size();
  const std::size_t stride = std::max<std::size_t>(1, (n + kSnapshotPoints - 1) / kSnapshotPoints);
  for (std::size_t i = 0; i < n; i += stride) {
    s.points_Bin.push_back(result.filtered.points[i]);
    const std::int32_t t = truth_of_input[result.filtered_source_index[i]];
    s.truth.push_back(t >= 0 && static_cast<std::size_t>(t) < tubes_Bin.size() ? t : -1);
    s.virtual_label.push_back(labels.tube[i]);
    s.segment.push_back(result.segment_of_point[i]);
  }
  s.tubes = result.tubes;
  for (const physics::TubeGeometry& t : tubes_Bin) {
    s.real_centrelines.push_back(t.IsLinear() ? t.Centreline() : std::vector<Eigen::Vector3d>{});
  }
  s.bin = bin;
  return s;
}

// The scene's 3-D page, written as soon as the scene is done (pages are not kept in memory):
// its cloud, the modeled tubes and the verdict. Returns its path relative to the report.
std::string WriteScenePage(const EvaluatedScene& scene, const Points& points_Sensor, LengthUnit unit,
                           const CellConfig& cell, const ModelingResult& result, const Params& params,
                           const EvalOptions& o) {
  std::string file = scene.name;
  for (char& c : file) {
    if (c == '/' || c == '\\' || c == ' ') c = '_';
  }
  file = "views/" + file + ".html";
  viewer::ViewPage page;
  page.title = fmt::format("tubepick eval: {}", scene.name);
  page.source = o.command_line;
  page.links.push_back({"report", "../report.md"});
  page.cell = cell;
  page.tool = params.planning.tool;
  viewer::ViewFrame frame;
  frame.label = fmt::format("scene {} ({})", scene.name, scene.source);
  const SceneEvaluation& e = scene.evaluation;
  frame.note = fmt::format(
      "{} of {} tubes correct, {} partially, {} hidden; {} virtual tubes; micro-recall {:.3f}", e.correct,
      e.real_tube_count, e.partially_correct, e.hidden, e.virtual_tubes.size(), e.micro_recall());
  frame.cloud = viewer::ThinToBin(points_Sensor, unit, cell.sensor.X_BinSensor, o.view_points);
  frame.modeling = ToModelTubesResponse(result, o.common.profile, o.common.seed);
  page.frames.push_back(std::move(frame));
  WriteTextFile((fs::path(o.report_dir) / file).string(), viewer::PageHtml(page));
  return file;
}

// The median curve length of a configuration's tubes, metres (0 for none).
double MedianTubeLength(const std::vector<physics::TubeGeometry>& tubes) {
  std::vector<double> lengths;
  for (const physics::TubeGeometry& t : tubes) lengths.push_back(t.Length());
  if (lengths.empty()) return 0.0;
  std::nth_element(lengths.begin(), lengths.begin() + lengths.size() / 2, lengths.end());
  return lengths[lengths.size() / 2];
}

EvaluatedScene EvaluateJob(const SceneJob& job, const EvalOptions& o, const CellConfig& default_cell,
                           const Params& params, const EvaluationParams& eval_params) {
  EvaluatedScene out;
  out.name = job.name;
  Points points_Sensor;
  std::vector<std::int32_t> labels;
  std::vector<physics::TubeGeometry> tubes_Bin;
  CellConfig cell = default_cell;
  LengthUnit unit = LengthUnit::kMetre;
  switch (job.kind) {
    case SceneJob::Kind::kGenerated: {
      SimulatedScene sim = SimulateScene(cell, static_cast<int>(job.tubes), o.preset, job.seed);
      points_Sensor = std::move(sim.scan.points_Sensor);
      labels = std::move(sim.scan.labels);
      tubes_Bin = std::move(sim.drop.tubes);
      out.source = "generated";
      out.scene_seed = static_cast<std::int64_t>(job.seed);
      break;
    }
    case SceneJob::Kind::kDirectory: {
      SceneData data = ReadSceneDirectory(job.path, default_cell);
      points_Sensor = std::move(data.points_Sensor);
      labels = std::move(data.labels);
      tubes_Bin = std::move(data.tubes_Bin);
      cell = data.cell;
      unit = cell.sensor.unit;
      out.source = job.path;
      break;
    }
    case SceneJob::Kind::kConfiguration: {
      tubes_Bin = physics::ReadTubeConfigurations(job.path);
      // The configuration says what the cell's tubes are, as a preset does for generated scenes.
      if (o.common.cell_path.empty()) cell.tube.length = MedianTubeLength(tubes_Bin);
      physics::ScanResult scan = physics::ScanScene(tubes_Bin, cell, physics::ScannerParams{}, o.common.seed);
      points_Sensor = std::move(scan.points_Sensor);
      labels = std::move(scan.labels);
      out.source = job.path;
      break;
    }
  }
  out.tube_count = static_cast<std::uint32_t>(tubes_Bin.size());
  out.tube_length = cell.tube.length;
  out.input_points = points_Sensor.size();

  // Planning needs the raw points of its finger test; the modeling is the same either way.
  const RawRegion raw = o.plans ? RawRegionForPlanning(params.planning, cell.bin) : RawRegion::None();
  const ModelingResult result =
      ModelTubes(MakeModelingInput(points_Sensor, unit, cell, o.common.seed, raw), params.modeling);
  out.evaluation = EvaluateScene(result, labels, out.tube_count, eval_params);
  if (o.plans) {
    physics::BulletTrajectoryEvaluator evaluator(
        physics::SimParamsForCell({}, cell, params.planning.cost.max_displacement,
                                  static_cast<int>(std::max(1u, params.modeling.threads))));
    const PickPlanResult plan = PlanPick(result, cell, params.planning, &evaluator, o.common.seed);
    out.plan_check = CheckBestPlan(plan, tubes_Bin, cell, params.planning);
  }
  out.snapshot = MakeSnapshot(result, labels, tubes_Bin, eval_params, cell.bin);
  if (o.view_points > 0) {
    out.view_file = WriteScenePage(out, points_Sensor, unit, cell, result, params, o);
  }
  return out;
}

std::string FormatDuration(double seconds) {
  const auto s = static_cast<long>(seconds + 0.5);
  return s >= 60 ? fmt::format("{}m{:02}s", s / 60, s % 60) : fmt::format("{}s", s);
}

// A progress bar on stderr: redrawn in place on a terminal, a line per 10 % otherwise.
class Progress {
 public:
  explicit Progress(std::size_t total)
      : total_(total), tty_(isatty(STDERR_FILENO) != 0), start_(Clock::now()) {}
  void Advance(const std::string& last) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++done_;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
    const double eta = done_ ? elapsed / done_ * (total_ - done_) : 0.0;
    if (tty_) {
      constexpr int kWidth = 30;
      const int filled = static_cast<int>(kWidth * done_ / std::max<std::size_t>(1, total_));
      fmt::print(stderr, "\r[{}{}] {}/{} {} elapsed {} eta {}   ", std::string(filled, '#'),
                 std::string(kWidth - filled, '.'), done_, total_, last, FormatDuration(elapsed),
                 FormatDuration(eta));
      if (done_ == total_) fmt::print(stderr, "\n");
    } else if (done_ * 10 / total_ != (done_ - 1) * 10 / total_ || done_ == total_) {
      fmt::print(stderr, "eval: {}/{} scenes, elapsed {}, eta {}\n", done_, total_, FormatDuration(elapsed),
                 FormatDuration(eta));
    }
  }

 private:
  std::mutex mutex_;
  std::size_t total_;
  std::size_t done_ = 0;
  bool tty_;
  Clock::time_point start_;
};

void Run(const EvalOptions& o) {
  const auto t_start = Clock::now();
  const int sources = !o.scenes_dir.empty() + !o.generate.empty() + !o.configs_dir.empty();
  if (sources != 1) throw InvalidArgument("eval: give exactly one of --scenes, --generate, --configs");
  CellConfig cell = LoadCell(o.common);
  // Generated scenes: the preset's tube length (and its junction shape); --topology overrides the
  // preset's topology, not its tubes.
  if (!o.generate.empty()) cell = CellForPreset(cell, o.preset);
  if (!o.topology.empty()) cell.tube.topology = ParseTubeTopology(o.topology, "--topology");
  if (!o.junction_shape.empty()) {
    cell.tube.junction_shape = ParseJunctionShape(o.junction_shape, "--junction-shape");
  }
  Params params = LoadParamsFor(o.common);
  if (o.joining == "greedy") params.modeling.joining.strategy = JoiningStrategy::kGreedy;
  if (o.joining == "global") params.modeling.joining.strategy = JoiningStrategy::kGlobal;
  const std::uint32_t jobs = std::max<std::uint32_t>(1, o.jobs);
  if (jobs > 1 && params.modeling.threads == 0) {
    params.modeling.threads = std::max<std::uint32_t>(1, static_cast<std::uint32_t>(CoresAvailable()) / jobs);
  }
  params.Validate();
  const EvaluationParams eval_params;

  EvalRun run;
  run.command_line = o.command_line;
  const std::vector<SceneJob> scene_jobs = ListJobs(o, run.source);
  run.profile = o.common.profile;
  run.params_path = o.common.params_path;
  run.joining_strategy = params.modeling.joining.strategy == JoiningStrategy::kGlobal ? "global" : "greedy";
  run.topology = ToString(cell.tube.topology);
  run.junction_shape = ToString(cell.tube.junction_shape);
  run.params_yaml = DumpParams(params);
  run.evaluation_params = eval_params;
  run.modeling_seed = o.common.seed;
  run.jobs = jobs;
  run.modeling_threads = params.modeling.threads;
  fmt::print(stderr,
             "eval: {} scenes ({}), profile {}, joining {}, topology {}, junction shape {}, {} job(s)\n",
             scene_jobs.size(), run.source, run.profile, run.joining_strategy, run.topology,
             run.junction_shape, jobs);

  // Every scene is independent and fully seeded: results land in input order whatever the
  // number of workers, so the report does not depend on --jobs (timings aside).
  std::vector<std::optional<EvaluatedScene>> results(scene_jobs.size());
  std::vector<std::exception_ptr> failures(scene_jobs.size());
  std::atomic<std::size_t> next{0};
  Progress progress(scene_jobs.size());
  auto worker = [&] {
    for (std::size_t i = next++; i < scene_jobs.size(); i = next++) {
      try {
        results[i] = EvaluateJob(scene_jobs[i], o, cell, params, eval_params);
        const SceneEvaluation& e = results[i]->evaluation;
        std::string lifted;
        if (results[i]->plan_check)
          lifted = fmt::format(", best plan lifts {}", results[i]->plan_check->lifted);
        progress.Advance(
            fmt::format("{} {}/{} correct{}", scene_jobs[i].name, e.correct, e.real_tube_count, lifted));
      } catch (...) {
        failures[i] = std::current_exception();
        progress.Advance(scene_jobs[i].name + " FAILED");
      }
    }
  };
  if (jobs == 1) {
    worker();
  } else {
    std::vector<std::thread> threads;
    for (std::uint32_t t = 0; t < jobs; ++t) threads.emplace_back(worker);
    for (std::thread& t : threads) t.join();
  }
  for (std::size_t i = 0; i < failures.size(); ++i) {
    if (!failures[i]) continue;
    try {
      std::rethrow_exception(failures[i]);
    } catch (const std::exception& e) {
      throw InvalidArgument("scene " + scene_jobs[i].name + ": " + e.what());
    }
  }
  for (auto& r : results) run.scenes.push_back(std::move(*r));

  std::vector<SceneEvaluation> evaluations;
  std::vector<const SceneEvaluation*> all;
  evaluations.reserve(run.scenes.size());
  for (const EvaluatedScene& s : run.scenes) evaluations.push_back(s.evaluation);
  for (const SceneEvaluation& e : evaluations) all.push_back(&e);
  run.rows = AggregateByTubeCount(evaluations);
  run.overall = Aggregate(all);
  run.wall_seconds = std::chrono::duration<double>(Clock::now() - t_start).count();
  WriteReport(run, o.report_dir, o.pictures_per_count);

  fmt::print("{:>6} {:>6} {:>9} {:>9} {:>9} {:>7} {:>9} {:>9} {:>8}\n", "tubes", "scenes", "correct",
             "partial", "not", "hidden", "correct%", "recall", "time_s");
  for (const EvaluationAggregate& r : run.rows) {
    fmt::print("{:>6} {:>6} {:>9.2f} {:>9.2f} {:>9.2f} {:>7.2f} {:>8.1f}% {:>9.3f} {:>8.3f}\n", r.tube_count,
               r.scenes, r.correct, r.partially_correct, r.not_correct, r.hidden, 100.0 * r.correct_fraction,
               r.micro_recall, r.mean_total_seconds);
  }
  const EvaluationAggregate& a = run.overall;
  fmt::print(
      "all: {} scenes, {} tubes, {:.1f}% correct, {:.1f}% partially correct, micro-recall {:.3f}, {} wall\n",
      a.scenes, a.real_tubes, 100.0 * a.correct_fraction,
      100.0 * a.total_partially_correct / std::max<std::uint32_t>(1, a.real_tubes), a.micro_recall,
      FormatDuration(run.wall_seconds));
  if (o.plans) {
    std::vector<const PlanCheck*> checks;
    for (const EvaluatedScene& s : run.scenes) checks.push_back(&*s.plan_check);
    const PlanCheckSummary c = SummarizePlanChecks(checks);
    fmt::print(
        "best plans: {} of {} scenes planned ({} sure, {} simulated, {} unsure); on a free real tube {}, on "
        "a "
        "tube lain on while a free one existed {}, off every tube {}; the check lifted it alone {}, with "
        "others {}, not at all {}\n",
        c.planned, c.scenes, c.sure, c.simulated, c.unsure, c.grasped_free, c.grasped_lain_on_while_free,
        c.off_tube, c.lifted_alone, c.lifted_several, c.lifted_none);
  }
  fmt::print("wrote {}/report.md, report.json, images/\n", o.report_dir);
}

}  // namespace

void AddEvalCommand(CLI::App& app) {
  auto o = std::make_shared<EvalOptions>();
  CLI::App* cmd =
      app.add_subcommand("eval", "Evaluate the tube modeling against ground truth (thesis 4.5.2)");
  auto* scenes = cmd->add_option("--scenes", o->scenes_dir, "Directory of scene directories (tubepick scene)")
                     ->check(CLI::ExistingDirectory);
  auto* generate = cmd->add_option("--generate", o->generate,
                                   "Generate scenes with these tube counts: 'A..B', 'N' or 'A,B'");
  auto* configs =
      cmd->add_option("--configs", o->configs_dir,
                      "Directory of published tube_configurations .txt files (searched recursively); "
                      "without --cell, each scene's tube.length is the median length of its tubes")
          ->check(CLI::ExistingDirectory);
  scenes->excludes(generate)->excludes(configs);
  generate->excludes(configs);
  cmd->add_option("--per-count", o->per_count, "Generated scenes per tube count")
      ->check(CLI::Range(1, 10000))
      ->capture_default_str();
  cmd->add_option("--preset", o->preset, "Tube shape set of generated scenes")
      ->check(CLI::IsMember({"A", "B", "C", "CY"}))
      ->capture_default_str();
  cmd->add_option("--seed", o->common.seed,
                  "Base seed: generated scene k with N tubes uses seed + 1000 N + k; also the modeling and "
                  "configuration-scan seed")
      ->capture_default_str();
  cmd->add_option("--cell", o->common.cell_path, "Cell YAML (default: embedded default cell)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--profile", o->common.profile, "Parameter profile")
      ->check(CLI::IsMember({"fast", "thesis"}))
      ->capture_default_str();
  cmd->add_option("--params", o->common.params_path, "Params YAML applied on top of the profile")
      ->check(CLI::ExistingFile);
  cmd->add_option("--joining", o->joining, "Override the joining strategy")
      ->check(CLI::IsMember({"greedy", "global"}));
  cmd->add_option("--topology", o->topology,
                  "Override the cell's tube.topology (default: the cell's; generated branched presets "
                  "model a linear cell's tubes as branched)")
      ->check(CLI::IsMember({"linear", "branched", "auto"}));
  cmd->add_option("--junction-shape", o->junction_shape,
                  "Override the cell's tube.junction_shape (default: the cell's; generated set CY: wye)")
      ->check(CLI::IsMember({"any", "wye", "tee"}));
  cmd->add_option("--report", o->report_dir, "Directory for report.md, report.json and images/")->required();
  cmd->add_option(
         "--jobs", o->jobs,
         "Scenes evaluated concurrently (results identical; per-stage times are then not representative)")
      ->check(CLI::Range(1, 256))
      ->capture_default_str();
  cmd->add_option("--view-points", o->view_points,
                  "Cloud points in each scene's 3-D page (views/NAME.html); 0 = write no pages")
      ->capture_default_str();
  cmd->add_flag("--plans", o->plans,
                "Also plan every scene (with simulation) and check the best plan against the ground truth: "
                "the real tube it grasps, whether a tube lies on it, and a Bullet lift of the real tubes");
  cmd->add_option("--pictures-per-count", o->pictures_per_count,
                  "Top-down pictures per tube count (the worst and a typical scene)")
      ->check(CLI::Range(0, 10))
      ->capture_default_str();
  cmd->callback([o, cmd] {
    o->command_line = "tubepick eval";
    for (const CLI::Option* opt : cmd->get_options()) {
      if (opt->count() == 0 || opt->get_name() == "--help") continue;
      o->command_line += " " + opt->get_name();
      for (const std::string& r : opt->results()) o->command_line += " " + r;
    }
    Run(*o);
  });
}

}  // namespace tubepick::cli

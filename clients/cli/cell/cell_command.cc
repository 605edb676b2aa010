#include "clients/cli/cell/cell_command.h"

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "clients/cell/cell_controller.h"
#include "clients/cell/cell_controller_config.h"
#include "clients/cell/cell_records.h"
#include "clients/cell/cell_statistics.h"
#include "clients/cell/planner_client.h"
#include "clients/cli/cell/cell_devices.h"
#include "clients/cli/cell/cell_tables.h"
#include "clients/cli/cell/fault_campaign.h"
#include "clients/cli/cell/fault_injector.h"
#include "clients/cli/cell/operator_stop.h"
#include "clients/cli/cell/planner_outage.h"
#include "clients/cli/cell/round_view.h"
#include "clients/cli/cell/sim_round.h"
#include "clients/cli/inputs/sim_scene.h"
#include "clients/cli/remote/server_process.h"
#include "core/common/cell_config.h"
#include "core/common/errors.h"
#include "devices/devices_config.h"
#include "devices/sim/sim_cell.h"

namespace tubepick::cli {
namespace {

using nlohmann::json;

/// Exit status of a run whose --records file lost records (a full disk): the cell did its work,
/// its trace is incomplete (4 is a cloud that does not fit the cell, 5 a failed devices check). A safe
/// stop (3) or a signal (128 + it) takes precedence.
constexpr int kExitRecordsLost = 6;

struct CellOptions {
  bool sim = false;
  std::uint32_t rounds = 1;
  std::uint32_t tubes = 7;
  std::string material = "pvc";
  std::string shapes;  ///< --shapes: A, B or C; empty = the material's thesis set (pvc A, rubber B)
  std::string place_zone = "conveyor";  ///< --place-zone: conveyor or table
  std::optional<double> sim_tube_mass;  ///< --sim-tube-mass: what the simulated tubes weigh, kg
  std::string server = "auto";
  std::uint64_t seed = 1;
  std::string records_path;
  std::string view_dir;  ///< --view: a 3-D page per round
  std::size_t view_points = 100'000;
  std::string json_path;
  std::string profile;
  std::string resolution;
  bool no_sim_planning = false;
  double plan_deadline = 300.0;
  std::uint32_t max_attempts_per_tube = 0;
  std::string controller_path;  ///< empty = the controller's defaults
  bool print_controller_config = false;
  std::string cell_path;    ///< empty = the thesis cell for --material
  double fault_rate = 0.0;  ///< --inject-faults
  std::uint64_t fault_seed = 1;
  std::string devices_path;  ///< --devices: the real (or mixed) cell
  bool print_devices_config = false;
  bool dry_run = false;
  cell::GrpcPlannerClientOptions planner_options;  ///< --tls-*
  // Options given on the command line (they override --controller).
  bool profile_given = false;
  bool resolution_given = false;
  bool plan_deadline_given = false;
  bool tubes_given = false;
};

v1::ResolutionVariant ParseVariant(const std::string& name) {
  return name.empty() ? v1::RESOLUTION_VARIANT_UNSPECIFIED
                      : cell::ResolutionVariantFromName(name, "--resolution");
}

/// The controller parameters of every round but the seed: --controller (or the defaults), then the
/// options given on the command line. Without --controller, --plan-deadline applies with its default
/// (300 s) as before.
cell::CellControllerParams ControllerParams(const CellOptions& o) {
  cell::CellControllerParams params = o.controller_path.empty()
                                          ? cell::CellControllerParams{}
                                          : cell::LoadCellControllerParams(o.controller_path);
  if (o.profile_given) params.profile = o.profile;
  if (o.resolution_given) params.resolution_variant = ParseVariant(o.resolution);
  if (o.no_sim_planning) params.disable_simulation = true;
  if (o.controller_path.empty() || o.plan_deadline_given) {
    if (!(o.plan_deadline > 0.0))
      throw InvalidArgument(fmt::format("--plan-deadline: must be positive, got {}", o.plan_deadline));
    params.plan_deadline = std::chrono::milliseconds(std::llround(o.plan_deadline * 1000.0));
  }
  if (o.max_attempts_per_tube > 0) params.max_attempts_per_tube = o.max_attempts_per_tube;
  if (o.sim || o.tubes_given) {  // the simulated bins hold --tubes; a real cell's, if given
    if (o.tubes == 0) throw InvalidArgument("--tubes: must be at least 1");
    if (params.tubes_per_bin != 0 && params.tubes_per_bin != o.tubes)
      throw InvalidArgument(fmt::format(
          "tubes_per_bin: {} in the controller config, but --tubes {} (leave it 0 or give the same)",
          params.tubes_per_bin, o.tubes));
    params.tubes_per_bin = o.tubes;
  }
  params.Validate();
  return params;
}

/// Every record kept in memory (for the tables) and, with --records, written as JSON lines; with
/// --view, the round pages see every planner call and record on their way.
struct RecordSinks {
  RecordSinks(const CellOptions& o, cell::PlannerClient& planner_client)
      : file(o.records_path.empty() ? nullptr : std::make_unique<cell::JsonLinesFileSink>(o.records_path)),
        tee(&memory, file.get()) {
    if (!o.view_dir.empty()) view.emplace(planner_client, tee, o.view_dir, o.view_points, ToolParams{});
  }
  cell::RecordSink& sink() { return view ? static_cast<cell::RecordSink&>(*view) : tee; }
  cell::PlannerClient& planner(cell::PlannerClient& direct) {
    return view ? static_cast<cell::PlannerClient&>(*view) : direct;
  }
  /// The records file's line (after the run); true when records were lost.
  bool PrintRecordsFile() const {
    if (!file) return false;
    fmt::print("{}\n", cell::DescribeRecordsFile(*file));
    return file->lost() > 0;
  }
  /// Where the pages went (after the run).
  void PrintPages() const {
    if (view && !view->pages().empty())
      fmt::print("3-D pages: {} round page(s) in {} (open in a browser)\n", view->pages().size(),
                 std::filesystem::path(view->pages().front()).parent_path().string());
  }
  cell::MemoryRecordSink memory;
  std::unique_ptr<cell::JsonLinesFileSink> file;
  cell::TeeRecordSink tee;
  std::optional<RoundViewRecorder> view;
};

/// The planner of the run: `--server auto` starts tubepick-server (its own process group, dies
/// with this process), else the address given.
std::unique_ptr<RestartableServer> StartPlanner(const CellOptions& o, std::string& address) {
  address = o.server;
  if (o.server != "auto") {
    fmt::print("planner: {}\n", address);
    return nullptr;
  }
  auto server = std::make_unique<RestartableServer>(
      SiblingExecutable("tubepick-server"),
      std::vector<std::string>{"--metrics-address", "", "--log-level", "info"});
  address = server->address();
  fmt::print("planner: started tubepick-server (pid {}) on {}\n", server->pid(), address);
  return server;
}

/// Closes the run's channel, then stops the planner this command started (if any). Closed first:
/// a server with a client still connected takes about 1.8 s longer to shut down (gRPC waits for
/// the connection), and the rounds are over.
void StopPlanner(RestartableServer* server, std::unique_ptr<cell::GrpcPlannerClient>& client) {
  client.reset();
  if (!server) return;
  const int status = server->Stop(std::chrono::seconds(15));
  spdlog::info("tubepick-server exited with status {}", status);
}

void WriteJson(const std::string& path, const json& document) {
  if (path.empty()) return;
  std::ofstream out(path);
  if (!out) throw InvalidArgument(fmt::format("--json {}: cannot open for writing", path));
  out << document.dump(2) << '\n';
  if (!out.flush()) throw InvalidArgument(fmt::format("--json {}: error writing (disk full?)", path));
  fmt::print("wrote {}\n", path);
}

/// Exit status after an operator stop: 128 + the signal, as a shell reports a killed command.
[[noreturn]] void ExitForSignal(const OperatorStop& stop) {
  fmt::print("stopped by {}: the round ended in the safe stop\n", stop.SignalName());
  std::fflush(stdout);
  throw CLI::RuntimeError(128 + stop.signal());
}

/// The tubes the simulation threw (SimRoundResult::runaways), ground-truth ids 1..N.
json RunawaysJson(const std::vector<devices::sim::SimRunaway>& runaways) {
  json out = json::array();
  for (const devices::sim::SimRunaway& r : runaways)
    out.push_back({{"tube", r.tube + 1},
                   {"seconds", r.seconds},
                   {"speed", r.speed},
                   {"angular_speed", r.angular_speed}});
  return out;
}

json RoundJson(std::uint32_t round, const cell::CellRunResult& result, double wall) {
  return {{"round", round},
          {"reason", cell::ToString(result.reason)},
          {"message", result.message},
          {"picks", result.picks},
          {"lost_in_transit", result.lost},
          {"attempts", result.attempts},
          {"scans", result.scans},
          {"planner_warnings", result.planner_warnings},
          {"tube_mass_doubts", result.tube_mass_doubts},
          {"tube_mass_doubt", result.tube_mass_doubt},
          {"tubes_expected", result.tubes_expected},
          {"tubes_unaccounted", result.tubes_unaccounted},
          {"wall_s", wall}};
}

/// Rounds on the devices of a devices file (tubepick cell --devices FILE): the same controller,
/// limits, records and tables as in the simulated cell; device time is wall time.
void RunOnDevices(const CellOptions& o, const cell::CellControllerParams& base_params) {
  const devices::DevicesConfig config = devices::LoadDevicesConfig(o.devices_path);
  if (o.fault_rate > 0.0)
    throw InvalidArgument("--inject-faults: only with --sim (faults are injected into the simulated cell)");
  OpenedCell opened = OpenCell(config, o.cell_path);
  fmt::print("devices: robot {}, gripper {}, F/T {}, scanner {}; cell from {}\n",
             devices::ToString(config.robot_driver), devices::ToString(config.gripper_driver),
             devices::ToString(config.ft_driver), devices::ToString(config.scanner_driver),
             opened.cell_source);
  OperatorStop stop;
  std::string address;
  std::unique_ptr<RestartableServer> server = StartPlanner(o, address);
  auto grpc_planner_owner = std::make_unique<cell::GrpcPlannerClient>(address, o.planner_options);
  cell::GrpcPlannerClient& grpc_planner = *grpc_planner_owner;
  RecordSinks records(o, grpc_planner);
  cell::RecordSink& sink = records.sink();
  cell::PlannerClient& planner = records.planner(grpc_planner);

  if (o.dry_run) {
    cell::CellControllerParams params = base_params;
    params.seed = o.seed * 1000;
    cell::CellController controller(opened.devices, planner, opened.cell, params, &sink);
    const cell::DryRunResult dry = controller.DryRun(0);
    fmt::print("{}", cell::FormatDryRun(dry));
    WriteJson(o.json_path, cell::DryRunJson(dry));
    StopPlanner(server.get(), grpc_planner_owner);
    if (!dry.motions.empty() || dry.bin_empty) return;
    throw CLI::RuntimeError(3);
  }

  json rounds_json = json::array();
  bool any_fault = false;
  for (std::uint32_t round = 0; round < o.rounds && stop.signal() == 0; ++round) {
    cell::CellControllerParams params = base_params;
    params.seed = (o.seed + round) * 1000;
    const auto round_start = std::chrono::steady_clock::now();
    cell::CellController controller(opened.devices, planner, opened.cell, params, &sink);
    controller.set_device_clock([round_start] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - round_start).count();
    });
    cell::CellRunResult result;
    {
      OperatorStop::Watch watch(stop, controller);
      result = controller.Run(round);
    }
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - round_start).count();
    fmt::print("round {:>2}: {} | {} picked, {} lost in transit, {} attempts, {} scans, {:.0f} s{}\n", round,
               result.message, result.picks, result.lost, result.attempts, result.scans, wall,
               cell::DescribeRoundWarnings(result));
    std::fflush(stdout);
    rounds_json.push_back(RoundJson(round, result, wall));
    if (result.reason != cell::CellStopReason::kBinEmpty &&
        result.reason != cell::CellStopReason::kLimitReached) {
      any_fault = true;
      break;  // a real cell does not carry on after a safe stop: the operator looks first
    }
  }
  const cell::CellStatistics stats = cell::SummarizeRecords(records.memory.records());
  fmt::print("\n{}", FormatCellTables(stats, fmt::format("{}, {} round{}", o.devices_path, stats.rounds,
                                                         stats.rounds == 1 ? "" : "s")));
  const bool records_lost = records.PrintRecordsFile();
  records.PrintPages();
  WriteJson(o.json_path, json{{"devices", o.devices_path},
                              {"seed", o.seed},
                              {"rounds", rounds_json},
                              {"statistics", cell::StatisticsJson(stats)}});
  StopPlanner(server.get(), grpc_planner_owner);
  if (stop.signal() != 0) ExitForSignal(stop);
  if (any_fault) throw CLI::RuntimeError(3);
  if (records_lost) throw CLI::RuntimeError(kExitRecordsLost);
}

void Run(const CellOptions& o) {
  const cell::CellControllerParams base_params = ControllerParams(o);
  if (o.print_controller_config) {
    fmt::print("{}", cell::DumpCellControllerParams(base_params));
    return;
  }
  if (o.print_devices_config) {
    fmt::print("{}", devices::ExampleDevicesConfig());
    return;
  }
  const cell::GrpcPlannerClientOptions& tls = o.planner_options;
  if (o.server == "auto" &&
      !(tls.tls_ca_file.empty() && tls.tls_cert_file.empty() && tls.tls_server_name.empty()))
    throw InvalidArgument(
        "--tls-*: the planner --server auto starts is plaintext on loopback; give the TLS planner's "
        "--server "
        "HOST:PORT");
  if (o.sim && !o.devices_path.empty())
    throw InvalidArgument("--sim and --devices: give one (--sim is the all-simulated cell)");
  if (!o.sim && o.devices_path.empty())
    throw InvalidArgument(
        "which cell? --devices FILE for a real cell (tubepick cell --print-devices-config prints an "
        "example; "
        "`tubepick devices check --devices FILE` first), or --sim for the simulated cell");
  if (!o.devices_path.empty()) return RunOnDevices(o, base_params);
  if (o.dry_run)
    throw InvalidArgument("--dry-run: with --devices FILE (the simulated cell has nothing to spare)");
  const bool custom_cell = !o.cell_path.empty();  // --devices: OpenCell reads it
  const CellConfig cell_config = custom_cell ? LoadCellConfig(o.cell_path) : CellConfig{};
  if (o.rounds == 0) throw InvalidArgument("--rounds: must be at least 1");
  const devices::sim::Material material = devices::sim::ParseMaterial(o.material, "--material");

  if (!(o.fault_rate >= 0.0 && o.fault_rate <= 1.0))
    throw InvalidArgument(
        fmt::format("--inject-faults: a probability per state in [0, 1], got {}", o.fault_rate));
  const bool injecting = o.fault_rate > 0.0;

  OperatorStop stop;
  std::string address;
  std::unique_ptr<RestartableServer> server = StartPlanner(o, address);
  if (!server && injecting)
    fmt::print("faults: no planner outages (the planner was not started here: --server auto)\n");
  FaultCampaign campaign;
  auto grpc_planner_owner = std::make_unique<cell::GrpcPlannerClient>(address, o.planner_options);
  cell::GrpcPlannerClient& grpc_planner = *grpc_planner_owner;
  RecordSinks records(o, grpc_planner);
  cell::RecordSink& sink = records.sink();
  cell::PlannerClient& planner = records.planner(grpc_planner);

  json rounds_json = json::array();
  bool any_fault = false;
  for (std::uint32_t round = 0; round < o.rounds && stop.signal() == 0; ++round) {
    cell::CellControllerParams params = base_params;
    params.seed = (o.seed + round) * 1000;
    devices::sim::SimCellParams sim_params =
        devices::sim::SimCellParams::Thesis(material, o.tubes, o.seed + round);
    if (custom_cell) sim_params.cell = cell_config;
    if (!o.shapes.empty()) WithShapes(o.shapes, &sim_params);
    sim_params.place_zone_conveyor = o.place_zone == "conveyor";
    sim_params.world_tube_mass = o.sim_tube_mass;
    if (server) {
      server->AwaitBack();
      server->StartAgain();  // an outage the last round ended in
    }
    const auto round_start = std::chrono::steady_clock::now();
    devices::sim::SimCell sim(sim_params);
    std::optional<FaultInjector> injector;
    std::function<void(cell::CellState)> observer;
    if (injecting) {
      injector.emplace(o.fault_rate, o.fault_seed * 1000 + round, sim, server.get());
      observer = [&injector](cell::CellState state) { injector->OnState(state); };
    }
    const SimRoundResult r = RunSimRound(planner, sim, params, round, &sink, observer, &stop);
    campaign.Add(r, injector ? &*injector : nullptr);
    const cell::CellRunResult& result = r.run;
    const std::uint32_t left = r.tubes_in_bin;
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - round_start).count();
    fmt::print(
        "round {:>2} (seed {}): {} | {} picked, {} left in the bin, {} lost in transit, {} released "
        "outside, {}"
        "{} attempts, {} scans, {:.0f} s simulated, {:.0f} s wall{}{}\n",
        round, o.seed + round, result.message, result.picks, left, result.lost, r.tubes_elsewhere,
        r.tubes_unnoticed > 0 ? fmt::format("{} carried out unnoticed, ", r.tubes_unnoticed) : "",
        result.attempts, result.scans, r.simulated_s, wall, cell::DescribeRoundWarnings(result),
        DescribeRunaways(r.runaways));
    std::fflush(stdout);
    json round_json = RoundJson(round, result, wall);
    round_json.update({{"seed", o.seed + round},
                       {"tubes_left", left},
                       {"released_outside", r.tubes_elsewhere},
                       {"carried_out_unnoticed", r.tubes_unnoticed},
                       {"still_held", r.tubes_held},
                       {"simulated_s", r.simulated_s},
                       {"simulation_runaways", RunawaysJson(r.runaways)},
                       {"peak_tube_speed", r.peak_speeds.linear},
                       {"peak_tube_angular_speed", r.peak_speeds.angular}});
    rounds_json.push_back(std::move(round_json));
    if (result.reason == cell::CellStopReason::kFault) {
      any_fault = true;
      if (!injecting && result.fault && result.fault->kind() == cell::FaultKind::kServerUnavailable) {
        fmt::print("planner unavailable: the remaining rounds are skipped\n");
        break;
      }
    }
  }

  const cell::CellStatistics stats = cell::SummarizeRecords(records.memory.records());
  fmt::print("\n{}", FormatCellTables(
                         stats, fmt::format("{}, {} round{} of {} tubes, seed {}", o.material, stats.rounds,
                                            stats.rounds == 1 ? "" : "s", o.tubes, o.seed)));
  const bool records_lost = records.PrintRecordsFile();
  records.PrintPages();
  if (injecting) fmt::print("{}\n{}\n", campaign.KindsLine(), campaign.SummaryLine());
  WriteJson(o.json_path, json{{"material", o.material},
                              {"shapes", o.shapes.empty() ? (o.material == "rubber" ? "B" : "A") : o.shapes},
                              {"tubes", o.tubes},
                              {"place_zone", o.place_zone},
                              {"seed", o.seed},
                              {"rounds", rounds_json},
                              {"faults", campaign.Json(o.fault_rate, o.fault_seed)},
                              {"statistics", cell::StatisticsJson(stats)}});
  StopPlanner(server.get(), grpc_planner_owner);
  if (stop.signal() != 0) ExitForSignal(stop);
  // A campaign expects safe stops; what it must never see is a tube released outside.
  if (injecting ? campaign.released_outside > 0 : any_fault) throw CLI::RuntimeError(3);
  if (records_lost) throw CLI::RuntimeError(kExitRecordsLost);
}

}  // namespace

void AddCellCommand(CLI::App& app) {
  auto o = std::make_shared<CellOptions>();
  CLI::App* cmd = app.add_subcommand(
      "cell",
      "Run bin-picking rounds on a cell's devices (--devices) or in the simulated cell (--sim); "
      "thesis Tables 5.4-5.9");
  CLI::Option* sim =
      cmd->add_flag("--sim", o->sim, "Use the simulated cell (Bullet world behind all four devices)");
  cmd->add_option("--devices", o->devices_path,
                  "Devices YAML of a real (or virtual) cell: a driver and connection per device "
                  "(--print-devices-config prints an example; check it with `tubepick devices check`)")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--print-devices-config", o->print_devices_config,
                "Print a commented example devices YAML and exit");
  cmd->add_flag("--dry-run", o->dry_run,
                "With --devices: scan and plan once, print the motions the cell would command, move nothing");
  cmd->add_option("--tls-ca", o->planner_options.tls_ca_file,
                  "PEM CA bundle of the planner's certificate (enables TLS)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--tls-cert", o->planner_options.tls_cert_file, "PEM client certificate chain (mutual TLS)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--tls-key", o->planner_options.tls_key_file, "PEM client private key (mutual TLS)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--tls-server-name", o->planner_options.tls_server_name,
                  "Name to check the planner's certificate against (default: the address' host)");
  cmd->add_option("--rounds", o->rounds, "Rounds (bins) to run; round r uses seed + r")
      ->capture_default_str();
  CLI::Option* tubes =
      cmd->add_option("--tubes", o->tubes,
                      "Tubes per bin: dropped into each simulated bin; with --devices, how many "
                      "each bin holds (the controller's tubes_per_bin)")
          ->capture_default_str();
  cmd->add_option("--material", o->material, "pvc (set A) or rubber (set B), thesis Table 5.2")
      ->capture_default_str();
  cmd->add_option(
         "--shapes", o->shapes,
         "Tube shapes of the simulated bins: A (20° bends), B (45°), C (branched trees, as published: "
         "branches in random directions) or CY (trees with Y-pieces, arms 120° apart); trees are rigid in "
         "pvc and jointed link chains in rubber; "
         "default: A for pvc, B for rubber")
      ->check(CLI::IsMember({"A", "B", "C", "CY"}));
  cmd->add_option(
         "--place-zone", o->place_zone,
         "The simulated place zone: a conveyor that carries each placed tube off before the next scan, "
         "or a table where placed tubes pile up")
      ->check(CLI::IsMember({"conveyor", "table"}))
      ->capture_default_str();
  cmd->add_option("--sim-tube-mass", o->sim_tube_mass,
                  "With --sim: what the simulated tubes weigh, kg, when not the cell's tube.mass (which the "
                  "controller and planner still use): shows what a wrong tube.mass does")
      ->check(CLI::PositiveNumber)
      ->needs(sim);
  cmd->add_option("--server", o->server,
                  "Planner address HOST:PORT, or auto: start tubepick-server on loopback")
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the first round's cell and the planner seeds")
      ->capture_default_str();
  cmd->add_option("--records", o->records_path,
                  "Write every attempt as a JSON line to this file; a record that cannot be written (disk "
                  "full) does not stop the cell: it is logged, counted at the end, and the exit status is 6");
  cmd->add_option("--view", o->view_dir,
                  "Write a 3-D page per round into this directory (round_NNN.html: each scan, its plans, the "
                  "pick made and what came of it)");
  cmd->add_option("--view-points", o->view_points, "Cloud points per scan in the --view pages")
      ->check(CLI::Range(1000, 2'000'000))
      ->capture_default_str();
  cmd->add_option("--json", o->json_path, "Write the per-round results and the statistics as JSON");
  CLI::Option* profile = cmd->add_option("--profile", o->profile,
                                         "Planner parameter profile (fast, thesis; default: the server's)");
  CLI::Option* resolution =
      cmd->add_option("--resolution", o->resolution,
                      "Resolution rotation: torque_axis, torque_axis_negative, perpendicular, joint_safe, "
                      "torque_axis_then_perpendicular "
                      "(default: the server's)");
  cmd->add_flag("--no-sim-planning", o->no_sim_planning, "Ask the planner not to simulate trajectories");
  CLI::Option* plan_deadline =
      cmd->add_option("--plan-deadline", o->plan_deadline,
                      "PlanPick deadline per try, seconds (with --controller: only when given)")
          ->capture_default_str();
  cmd->add_option("--max-attempts-per-tube", o->max_attempts_per_tube,
                  "Attempts since the last pick before the round stops (0 = controller default)");
  cmd->add_option("--controller", o->controller_path,
                  "Cell controller parameters YAML (deploy/cell-controller.example.yaml; strict: unknown "
                  "keys are errors). Options given here override it; the planner seed of round r is "
                  "always (--seed + r)·1000")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--print-controller-config", o->print_controller_config,
                "Print the controller parameters this command would use (defaults, --controller, the "
                "options given) as YAML and exit");
  cmd->add_option("--cell", o->cell_path,
                  "Cell YAML (bin, sensor, place, tube) for the simulated cell and the planner requests "
                  "(default: the thesis cell for --material)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--inject-faults", o->fault_rate,
                  "Fault campaign: on every state the controller enters, this probability of a device or "
                  "planner fault fitting the state (robot alarm, gripper fault, slip, F/T timeout or spike, "
                  "scanner timeout or empty scan, planner outage); exit 3 only if a tube ends outside the "
                  "bin and the place zone")
      ->capture_default_str();
  cmd->add_option("--fault-seed", o->fault_seed, "Seed of the injected faults (round r: seed·1000 + r)")
      ->capture_default_str();
  cmd->callback([o, profile, resolution, plan_deadline, tubes] {
    o->profile_given = profile->count() > 0;
    o->resolution_given = resolution->count() > 0;
    o->plan_deadline_given = plan_deadline->count() > 0;
    o->tubes_given = tubes->count() > 0;
    Run(*o);
  });
}

}  // namespace tubepick::cli

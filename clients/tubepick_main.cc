// tubepick: command-line front end of the planning library (model, params, bench, ...).
#include <fmt/core.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "clients/cli/cell/cell_command.h"
#include "clients/cli/cell/devices_check.h"
#include "clients/cli/cell/resolution_trials.h"
#include "clients/cli/cell/virtual_cell.h"
#include "clients/cli/eval/eval_command.h"
#include "clients/cli/load/bench_service.h"
#include "clients/cli/load/load_command.h"
#include "clients/cli/local/bench_command.h"
#include "clients/cli/local/model_command.h"
#include "clients/cli/local/params_command.h"
#include "clients/cli/local/plan_command.h"
#include "clients/cli/local/scene_command.h"
#include "clients/cli/local/view_command.h"
#include "clients/cli/remote/health_command.h"
#include "clients/cli/remote/request_command.h"
#include "core/common/errors.h"

int main(int argc, char** argv) {
  CLI::App app{"tubepick - bin picking of entangled tubes"};
  app.require_subcommand(1);
  std::string log_level = "warn";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error")->capture_default_str();
  app.parse_complete_callback([&] { spdlog::set_level(spdlog::level::from_str(log_level)); });
  tubepick::cli::AddModelCommand(app);
  tubepick::cli::AddParamsCommand(app);
  tubepick::cli::AddPlanCommand(app);
  tubepick::cli::AddViewCommand(app);
  tubepick::cli::AddBenchServiceCommand(*tubepick::cli::AddBenchCommand(app));
  tubepick::cli::AddSceneCommand(app);
  tubepick::cli::AddEvalCommand(app);
  tubepick::cli::AddCellCommand(app);
  tubepick::cli::AddDevicesCommand(app);
  tubepick::cli::AddVirtualCellCommand(app);
  tubepick::cli::AddResolutionTrialsCommand(app);
  tubepick::cli::AddLoadCommand(app);
  tubepick::cli::AddHealthCommand(app);
  tubepick::cli::AddRequestCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const tubepick::InvalidArgument& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 2;
  } catch (const tubepick::FailedPrecondition& e) {
    fmt::print(stderr, "error: {}\n", e.what());
    return 4;  // 3 is tubepick cell's "a round ended in a fault"
  } catch (const std::exception& e) {
    fmt::print(stderr, "internal error: {}\n", e.what());
    return 1;
  }
  return 0;
}

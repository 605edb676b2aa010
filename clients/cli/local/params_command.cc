#include "clients/cli/local/params_command.h"

#include <fmt/core.h>

#include <memory>

#include "clients/cli/inputs/cli_inputs.h"

namespace tubepick::cli {

void AddParamsCommand(CLI::App& app) {
  auto options = std::make_shared<CommonOptions>();
  auto dump = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand("params", "Show algorithm parameters (every key, with its value)");
  cmd->add_option("--profile", options->profile, "Parameter profile")
      ->check(CLI::IsMember({"fast", "thesis"}))
      ->capture_default_str();
  cmd->add_option("--params", options->params_path, "Params YAML applied on top of the profile")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--dump", *dump, "Print the parameters as YAML");
  cmd->callback([options, dump] {
    const Params params = LoadParamsFor(*options);
    fmt::print("# tubepick parameters, profile '{}'{}\n", options->profile,
               options->params_path.empty() ? "" : " + " + options->params_path);
    fmt::print("{}", DumpParams(params));
  });
}

}  // namespace tubepick::cli

#include "clients/cli/cli_inputs.h"

#include <filesystem>
#include <fstream>

#include "core/common/errors.h"

namespace tubepick::cli {

CellConfig LoadCell(const CommonOptions& options) {
  if (options.cell_path.empty()) return CellConfig{};
  return LoadCellConfig(options.cell_path);
}

Params LoadParamsFor(const CommonOptions& options) {
  Params params = ProfileParams(options.profile);
  if (!options.params_path.empty()) params = LoadParams(options.params_path, params);
  return params;
}

void WriteTextFile(const std::string& path, const std::string& text) {
  const std::filesystem::path p(path);
  if (p.has_parent_path()) std::filesystem::create_directories(p.parent_path());
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InvalidArgument("cannot write '" + path + "'");
  out << text;
  if (!out) throw InvalidArgument("error writing '" + path + "'");
}

}  // namespace tubepick::cli

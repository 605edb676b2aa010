// libFuzzer target: the strict YAML readers (algorithm params, cell, server config, cell
// controller config).
//
// Input: one selector byte (0 params, 1 cell, 2 server, 3 controller; taken modulo 4), then the
// YAML text. Accepted: a config, or InvalidArgument naming the key path. Anything else (a yaml-cpp
// exception, a sanitizer report) is a crash, and so is an accepted config whose dump the same
// reader does not read back.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "clients/cell/cell_controller_config.h"
#include "core/common/cell_config.h"
#include "core/common/errors.h"
#include "core/params.h"
#include "server/server_config.h"

namespace {

using namespace tubepick;  // NOLINT(build/namespaces): a fuzz target's few names

// Relative file names in a server config (params_file, cell_file, tls.*) resolve here: nothing.
constexpr char kNoDir[] = "/nonexistent/tubepick-fuzz";

// `read_back` parses the dump of what was accepted; it must not throw.
template <typename ReadBack>
void ReadBackOrAbort(ReadBack read_back) {
  try {
    read_back();
  } catch (...) {
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const int selector = data[0] % 4;
  const std::string text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    switch (selector) {
      case 0: {
        static const Params base = ProfileParams("fast");
        const Params params = ParseParams(text, base);
        ReadBackOrAbort([&] {
          const std::string dump = DumpParams(params);
          if (DumpParams(ParseParams(dump, base)) != dump) std::abort();
        });
        break;
      }
      case 1: {
        const CellConfig cell = ParseCellConfig(text);
        ReadBackOrAbort([&] { ParseCellConfig(DumpCellConfig(cell)); });
        break;
      }
      case 2:
        server::ParseServerConfig(text, kNoDir);
        break;
      default: {
        const cell::CellControllerParams params = cell::ParseCellControllerParams(text);
        ReadBackOrAbort([&] { cell::ParseCellControllerParams(cell::DumpCellControllerParams(params)); });
        break;
      }
    }
  } catch (const InvalidArgument&) {
  }
  return 0;
}

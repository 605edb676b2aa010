#pragma once

// Running the `tubepick` binary from end-to-end tests (TUBEPICK_CLI is its path, set by CMake).
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

namespace tubepick::testing {

struct CliRun {
  int exit_code;
  std::string output;  ///< stdout and stderr
};

inline CliRun RunCli(const std::string& args) {
  const std::string cmd = std::string(TUBEPICK_CLI) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  std::string out;
  std::array<char, 4096> buf;
  while (std::fgets(buf.data(), buf.size(), pipe)) out += buf.data();
  const int status = pclose(pipe);
  return {WEXITSTATUS(status), out};
}

/// A fresh, empty directory for one test.
inline std::filesystem::path TempDir(const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("tubepick_cli_test_" + name + "_" + std::to_string(getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

inline std::string ReadText(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline nlohmann::json ReadJson(const std::filesystem::path& p) { return nlohmann::json::parse(ReadText(p)); }

}  // namespace tubepick::testing

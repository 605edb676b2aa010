#include "devices/exec_scanner.h"

#include <fmt/core.h>
#include <signal.h>
#include <spawn.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <thread>

#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"

extern char** environ;

namespace tubepick::devices {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string ShellQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string LastLine(const std::string& path) {
  std::ifstream in(path);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

std::string Describe(int status) {
  if (WIFEXITED(status)) return fmt::format("exit status {}", WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return fmt::format("killed by signal {}", WTERMSIG(status));
  return fmt::format("wait status {}", status);
}

/// Runs `command` with /bin/sh -c in a new process group, stderr to `stderr_path`; its wait status,
/// or nullopt after killing the group when `deadline` passed.
std::optional<int> RunUntil(const std::string& command, const std::string& stderr_path,
                            Clock::time_point deadline) {
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, stderr_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                   0600);
  posix_spawnattr_t attr;
  posix_spawnattr_init(&attr);
  posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETPGROUP);
  posix_spawnattr_setpgroup(&attr, 0);
  const char* argv[] = {"/bin/sh", "-c", command.c_str(), nullptr};
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, "/bin/sh", &actions, &attr, const_cast<char* const*>(argv), environ);
  posix_spawn_file_actions_destroy(&actions);
  posix_spawnattr_destroy(&attr);
  if (rc != 0) throw DeviceFault(fmt::format("exec scanner: cannot start /bin/sh: {}", std::strerror(rc)));
  auto sleep = std::chrono::milliseconds(1);
  for (;;) {
    int status = 0;
    const pid_t done = waitpid(pid, &status, WNOHANG);
    if (done == pid) return status;
    if (done < 0 && errno != EINTR)
      throw DeviceFault(fmt::format("exec scanner: waitpid: {}", std::strerror(errno)));
    if (Clock::now() >= deadline) {
      kill(-pid, SIGKILL);
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      return std::nullopt;
    }
    std::this_thread::sleep_for(sleep);
    sleep = std::min(sleep * 2, std::chrono::milliseconds(20));
  }
}

}  // namespace

ExecScanner::ExecScanner(ExecScannerParams params) : params_(std::move(params)) {
  if (params_.command.find("{out}") == std::string::npos)
    throw InvalidArgument(
        fmt::format("exec scanner: command '{}' has no {{out}} for the file it must write", params_.command));
  if (params_.format != "ply" && params_.format != "pcd")
    throw InvalidArgument(fmt::format("exec scanner: format ply or pcd, got '{}'", params_.format));
  if (params_.work_dir.empty()) {
    const char* tmp = std::getenv("TMPDIR");
    params_.work_dir = tmp != nullptr && *tmp != '\0' ? tmp : "/tmp";
  }
}

std::string ExecScanner::CommandFor(const std::string& out_path) const {
  std::string command = params_.command;
  const std::string quoted = ShellQuote(out_path);
  for (std::size_t at = command.find("{out}"); at != std::string::npos;
       at = command.find("{out}", at + quoted.size()))
    command.replace(at, 5, quoted);
  return command;
}

Capture ExecScanner::Scan(Timeout timeout) {
  const auto deadline = Clock::now() + timeout;
  const std::string stem =
      (fs::path(params_.work_dir) / fmt::format("tubepick-scan-{}-{}", ::getpid(), ++scans_)).string();
  const std::string out = stem + "." + params_.format;
  const std::string err = stem + ".stderr";
  std::error_code ec;
  fs::remove(out, ec);
  const std::string command = CommandFor(out);
  spdlog::debug("exec scanner: {}", command);
  const std::optional<int> status = RunUntil(command, err, deadline);
  const std::string last_err = LastLine(err);
  fs::remove(err, ec);
  if (!status) {
    fs::remove(out, ec);
    throw DeviceTimeout(fmt::format("exec scanner: '{}' still running after {} ms (killed){}", command,
                                    timeout.count(), last_err.empty() ? "" : ": " + last_err));
  }
  if (!WIFEXITED(*status) || WEXITSTATUS(*status) != 0) {
    fs::remove(out, ec);
    throw DeviceFault(fmt::format("exec scanner: '{}' failed ({}){}", command, Describe(*status),
                                  last_err.empty() ? "" : ": " + last_err));
  }
  if (!fs::exists(out, ec))
    throw DeviceFault(fmt::format("exec scanner: '{}' exited 0 but wrote no file {}", command, out));
  CloudFile cloud;
  try {
    cloud = ReadCloudFile(out);
  } catch (const std::exception& e) {
    fs::remove(out, ec);
    throw DeviceFault(fmt::format("exec scanner: the file '{}' wrote is not a cloud: {}", command, e.what()));
  }
  fs::remove(out, ec);
  return CaptureOf(std::move(cloud.points), params_.sensor);
}

}  // namespace tubepick::devices

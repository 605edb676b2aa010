#pragma once

#include <sys/types.h>

#include <chrono>
#include <deque>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace tubepick::cli {

/// A tubepick-server child process for `tubepick cell --server auto`: started on loopback with an
/// ephemeral port, its address taken from its "listening on HOST:PORT" log line, stopped with
/// SIGTERM (the server's graceful shutdown). Its output is drained in a thread and logged at debug
/// level; the last lines are kept for error messages.
class ServerProcess {
 public:
  /// Starts `binary args...` and waits up to `startup_timeout` for the listening line.
  /// @throws std::runtime_error when it cannot start, exits early or does not listen in time (the
  /// message carries its last output lines).
  static std::unique_ptr<ServerProcess> Start(const std::string& binary, const std::vector<std::string>& args,
                                              std::chrono::milliseconds startup_timeout);
  /// Stop(10 s) if still running.
  ~ServerProcess();
  ServerProcess(const ServerProcess&) = delete;
  ServerProcess& operator=(const ServerProcess&) = delete;

  /// HOST:PORT the server listens on.
  const std::string& address() const { return address_; }
  pid_t pid() const { return pid_; }
  /// SIGTERM, wait up to `grace` (then SIGKILL). Returns the exit status (128 + signal when killed
  /// by one). Idempotent.
  int Stop(std::chrono::milliseconds grace);
  /// The last output lines (up to 50).
  std::string Tail() const;

 private:
  ServerProcess() = default;
  void Drain();

  pid_t pid_ = -1;
  int output_fd_ = -1;
  std::string address_;
  std::thread drain_;
  mutable std::mutex mutex_;
  std::deque<std::string> tail_;
  std::string partial_;
  int exit_status_ = -1;
};

/// The path of `name` in the directory of the running executable (/proc/self/exe).
std::string SiblingExecutable(const std::string& name);

}  // namespace tubepick::cli

#pragma once

#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "clients/cli/remote/server_process.h"

namespace tubepick::cli {

/// The `--server auto` planner, which can be taken away for a while: Kill / StartAgain, or Restart
/// (kill, then start again on the same address in the background); the controller's channel
/// reconnects by itself.
class RestartableServer {
 public:
  /// Starts `binary args...` (args must not carry --address: it is added).
  RestartableServer(std::string binary, std::vector<std::string> args);
  ~RestartableServer();
  RestartableServer(const RestartableServer&) = delete;
  RestartableServer& operator=(const RestartableServer&) = delete;

  const std::string& address() const { return address_; }
  pid_t pid() const;
  /// Kills the server now (a restart under way is waited for first); it stays down until StartAgain.
  void Kill();
  /// Starts the server again on the same address if it is down; waits until it listens.
  void StartAgain();
  /// Kills the server now and starts it again `seconds` later in the background. Returns at once.
  void Restart(double seconds);
  /// Waits for a restart under way (the next round starts with the planner up).
  void AwaitBack() {
    if (restart_.joinable()) restart_.join();
  }
  /// Waits for a restart under way, then SIGTERM with `grace`; the exit status.
  int Stop(std::chrono::milliseconds grace);

 private:
  std::string binary_;
  std::vector<std::string> args_;
  std::string address_;
  mutable std::mutex mutex_;
  std::unique_ptr<ServerProcess> server_;
  std::thread restart_;
};

}  // namespace tubepick::cli

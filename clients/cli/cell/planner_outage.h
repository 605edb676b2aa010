#pragma once

#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "clients/cli/remote/server_process.h"

namespace tubepick::cli {

/// The `--server auto` planner, which can be taken away for a while: Outage kills it and starts it
/// again on the same address in the background, so the controller's channel reconnects by itself.
class RestartableServer {
 public:
  /// Starts `binary args...` (args must not carry --address: it is added).
  RestartableServer(std::string binary, std::vector<std::string> args);
  ~RestartableServer();
  RestartableServer(const RestartableServer&) = delete;
  RestartableServer& operator=(const RestartableServer&) = delete;

  const std::string& address() const { return address_; }
  pid_t pid() const;
  /// Kills the server now and starts it again `seconds` later (a restart already under way is
  /// waited for first). Returns at once.
  void Outage(double seconds);
  /// Waits for a restart under way (the next round starts with the planner up).
  void AwaitBack() {
    if (restart_.joinable()) restart_.join();
  }
  /// Outages so far.
  int outages() const { return outages_; }
  /// Waits for a restart under way, then SIGTERM with `grace`; the exit status.
  int Stop(std::chrono::milliseconds grace);

 private:
  std::string binary_;
  std::vector<std::string> args_;
  std::string address_;
  mutable std::mutex mutex_;
  std::unique_ptr<ServerProcess> server_;
  std::thread restart_;
  int outages_ = 0;
};

}  // namespace tubepick::cli

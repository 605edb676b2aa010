#include "clients/cli/cell/planner_outage.h"

#include <spdlog/spdlog.h>

namespace tubepick::cli {
namespace {

constexpr std::chrono::seconds kStartupTimeout{60};

std::vector<std::string> WithAddress(std::vector<std::string> args, const std::string& address) {
  args.insert(args.begin(), {"--address", address});
  return args;
}

}  // namespace

RestartableServer::RestartableServer(std::string binary, std::vector<std::string> args)
    : binary_(std::move(binary)), args_(std::move(args)) {
  server_ = ServerProcess::Start(binary_, WithAddress(args_, "127.0.0.1:0"), kStartupTimeout);
  address_ = server_->address();
}

RestartableServer::~RestartableServer() {
  if (restart_.joinable()) restart_.join();
}

pid_t RestartableServer::pid() const {
  std::lock_guard lock(mutex_);
  return server_ ? server_->pid() : -1;
}

void RestartableServer::Kill() {
  if (restart_.joinable()) restart_.join();
  std::lock_guard lock(mutex_);
  if (!server_) return;
  server_->Stop(std::chrono::milliseconds(0));
  server_.reset();
  spdlog::info("planner outage: tubepick-server killed");
}

void RestartableServer::StartAgain() {
  std::lock_guard lock(mutex_);
  if (server_) return;
  try {
    server_ = ServerProcess::Start(binary_, WithAddress(args_, address_), kStartupTimeout);
    spdlog::info("planner outage: tubepick-server back on {}", address_);
  } catch (const std::exception& e) {
    spdlog::error("planner outage: tubepick-server did not come back on {}: {}", address_, e.what());
  }
}

void RestartableServer::Restart(double seconds) {
  Kill();
  restart_ = std::thread([this, seconds] {
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    StartAgain();
  });
}

int RestartableServer::Stop(std::chrono::milliseconds grace) {
  if (restart_.joinable()) restart_.join();
  std::lock_guard lock(mutex_);
  return server_ ? server_->Stop(grace) : -1;
}

}  // namespace tubepick::cli

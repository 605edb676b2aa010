#include "clients/cli/cell/operator_stop.h"

#include <signal.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <stdexcept>

namespace tubepick::cli {
namespace {

std::atomic<int> g_signal{0};
std::atomic<bool> g_installed{false};
struct sigaction g_old_int, g_old_term;

void OnSignal(int signo) {
  if (g_signal.load() != 0) {
    // A second Ctrl-C while the safe stop runs: the operator insists; the default action ends us.
    ::signal(signo, SIG_DFL);
    ::raise(signo);
    return;
  }
  g_signal.store(signo);
}

}  // namespace

OperatorStop::OperatorStop() {
  if (g_installed.exchange(true)) throw std::logic_error("OperatorStop: one per process");
  g_signal.store(0);
  struct sigaction action {};
  action.sa_handler = OnSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART;
  sigaction(SIGINT, &action, &g_old_int);
  sigaction(SIGTERM, &action, &g_old_term);
  watcher_ = std::thread([this] { Run(); });
}

OperatorStop::~OperatorStop() {
  {
    std::lock_guard lock(mutex_);
    quit_ = true;
  }
  wake_.notify_all();
  watcher_.join();
  sigaction(SIGINT, &g_old_int, nullptr);
  sigaction(SIGTERM, &g_old_term, nullptr);
  g_installed.store(false);
}

int OperatorStop::signal() const { return g_signal.load(); }

std::string OperatorStop::SignalName() const {
  switch (g_signal.load()) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case 0:
      return "";
    default:
      return "signal " + std::to_string(g_signal.load());
  }
}

void OperatorStop::Run() {
  std::unique_lock lock(mutex_);
  while (!quit_) {
    // The handler cannot notify a condition variable: poll the flag every 20 ms.
    wake_.wait_for(lock, std::chrono::milliseconds(20));
    if (g_signal.load() != 0 && controller_ != nullptr && !stopped_controller_) {
      stopped_controller_ = true;
      spdlog::warn("{}: stopping the round (safe stop)", SignalName());
      controller_->RequestStop("operator stop (" + SignalName() + ")");
    }
  }
}

OperatorStop::Watch::Watch(OperatorStop& stop, cell::CellController& controller) : stop_(stop) {
  std::lock_guard lock(stop_.mutex_);
  stop_.controller_ = &controller;
  stop_.stopped_controller_ = false;
}

OperatorStop::Watch::~Watch() {
  std::lock_guard lock(stop_.mutex_);
  stop_.controller_ = nullptr;
}

}  // namespace tubepick::cli

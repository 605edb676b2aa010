#pragma once

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "clients/cell/cell_controller.h"

namespace tubepick::cli {

/// SIGINT / SIGTERM during `tubepick cell`: the signal handler only records the signal; a watcher
/// thread asks the controller of the round under way to stop (CellController::RequestStop), which
/// ends the round through the safe stop (a held tube is released over the bin). The command then
/// skips the remaining rounds and exits with 128 + the signal. One per process; the handlers it
/// replaced are restored when it is destroyed.
class OperatorStop {
 public:
  OperatorStop();
  ~OperatorStop();
  OperatorStop(const OperatorStop&) = delete;
  OperatorStop& operator=(const OperatorStop&) = delete;

  /// The signal received (SIGINT, SIGTERM), or 0.
  int signal() const;
  /// "SIGINT", "SIGTERM".
  std::string SignalName() const;

  /// While a Watch lives, a signal stops `controller` (at once when the signal came earlier).
  class Watch {
   public:
    Watch(OperatorStop& stop, cell::CellController& controller);
    ~Watch();
    Watch(const Watch&) = delete;
    Watch& operator=(const Watch&) = delete;

   private:
    OperatorStop& stop_;
  };

 private:
  void Run();

  std::mutex mutex_;
  std::condition_variable wake_;
  cell::CellController* controller_ = nullptr;
  bool stopped_controller_ = false;
  bool quit_ = false;
  std::thread watcher_;
};

}  // namespace tubepick::cli

#pragma once

#include <atomic>
#include <chrono>
#include <optional>

#include "core/common/errors.h"

namespace tubepick {

/// Cooperative cancellation polled inside long loops (modeling stages, simulation steps).
/// Thread-safe: one thread may RequestStop() while workers poll ThrowIfStopped().
class StopToken {
 public:
  using Clock = std::chrono::steady_clock;

  StopToken() = default;
  explicit StopToken(Clock::time_point deadline) : deadline_(deadline) {}

  void RequestStop() { stop_requested_.store(true, std::memory_order_relaxed); }
  void set_deadline(Clock::time_point deadline) { deadline_ = deadline; }

  bool stop_requested() const { return stop_requested_.load(std::memory_order_relaxed); }
  bool deadline_passed() const { return deadline_ && Clock::now() >= *deadline_; }
  bool should_stop() const { return stop_requested() || deadline_passed(); }

  /// @throws Cancelled when a stop was requested or the deadline passed.
  void ThrowIfStopped(const char* where) const {
    if (stop_requested()) throw Cancelled(std::string("cancelled during ") + where, false);
    if (deadline_passed()) throw Cancelled(std::string("deadline exceeded during ") + where, true);
  }

 private:
  std::atomic<bool> stop_requested_{false};
  std::optional<Clock::time_point> deadline_;
};

/// Polls an optional token; a null token never stops.
inline void ThrowIfStopped(const StopToken* token, const char* where) {
  if (token != nullptr) token->ThrowIfStopped(where);
}

}  // namespace tubepick

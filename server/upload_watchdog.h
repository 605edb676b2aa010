#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

namespace tubepick::server {

/// Decides who ends one upload: its reactor or the UploadWatchdog, never both. The reactor calls
/// Touch / StopWatching / ClaimFinish; once one of them says false, the watchdog has taken the call
/// over (and Finishes it): the reactor then neither reads nor finishes. Thread-safe.
class UploadWatch {
 public:
  using Clock = std::chrono::steady_clock;

  /// A message arrived: the upload is active now. False when the watchdog took the call over.
  bool Touch();
  /// The upload is over (complete or broken): the watchdog no longer ends it. False when the
  /// watchdog took the call over.
  bool StopWatching();
  /// The reactor is about to Finish the call. False when the watchdog took it over.
  bool ClaimFinish();

 private:
  friend class UploadWatchdog;
  explicit UploadWatch(std::function<void()> on_idle) : last_(Clock::now()), on_idle_(std::move(on_idle)) {}
  /// The watchdog takes the call over when nothing arrived for `timeout` before `now`.
  bool TakeOverIfIdle(Clock::time_point now, Clock::duration timeout);
  bool Settled();

  std::mutex mu_;
  Clock::time_point last_;
  bool watching_ = true;
  bool claimed_ = false;
  std::function<void()> on_idle_;
};

/// One thread that ends uploads that went quiet (server.stream_idle_timeout): a client that opens
/// a PlanPickStream and then sends nothing would otherwise hold its upload slot and memory forever.
class UploadWatchdog {
 public:
  explicit UploadWatchdog(UploadWatch::Clock::duration timeout);
  ~UploadWatchdog();
  UploadWatchdog(const UploadWatchdog&) = delete;
  UploadWatchdog& operator=(const UploadWatchdog&) = delete;

  /// Watches a new upload. `on_idle` runs on the watchdog's thread once the upload has been quiet
  /// for the timeout and the watchdog took it over; it must Finish the call (and may be the last
  /// thing that touches it).
  std::shared_ptr<UploadWatch> Watch(std::function<void()> on_idle);
  UploadWatch::Clock::duration timeout() const { return timeout_; }

 private:
  void Loop();

  const UploadWatch::Clock::duration timeout_;
  std::mutex mu_;
  std::condition_variable cv_;
  bool stopping_ = false;
  std::vector<std::shared_ptr<UploadWatch>> watched_;
  std::thread thread_;
};

}  // namespace tubepick::server

#include "server/upload_watchdog.h"

#include <algorithm>

namespace tubepick::server {

bool UploadWatch::Touch() {
  std::lock_guard lock(mu_);
  if (claimed_) return false;
  last_ = Clock::now();
  return true;
}

bool UploadWatch::StopWatching() {
  std::lock_guard lock(mu_);
  if (claimed_) return false;
  watching_ = false;
  return true;
}

bool UploadWatch::ClaimFinish() {
  std::lock_guard lock(mu_);
  if (claimed_) return false;
  claimed_ = true;
  watching_ = false;
  return true;
}

bool UploadWatch::TakeOverIfIdle(Clock::time_point now, Clock::duration timeout) {
  std::lock_guard lock(mu_);
  if (claimed_ || !watching_ || now - last_ < timeout) return false;
  claimed_ = true;
  watching_ = false;
  return true;
}

bool UploadWatch::Settled() {
  std::lock_guard lock(mu_);
  return !watching_;
}

UploadWatchdog::UploadWatchdog(UploadWatch::Clock::duration timeout)
    : timeout_(timeout), thread_([this] { Loop(); }) {}

UploadWatchdog::~UploadWatchdog() {
  {
    std::lock_guard lock(mu_);
    stopping_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

std::shared_ptr<UploadWatch> UploadWatchdog::Watch(std::function<void()> on_idle) {
  std::shared_ptr<UploadWatch> watch(new UploadWatch(std::move(on_idle)));
  std::lock_guard lock(mu_);
  watched_.push_back(watch);
  return watch;
}

void UploadWatchdog::Loop() {
  // A quarter of the timeout between checks (10 ms .. 1 s): an upload ends within 1.25 timeouts.
  const auto tick = std::clamp<UploadWatch::Clock::duration>(timeout_ / 4, std::chrono::milliseconds(10),
                                                             std::chrono::seconds(1));
  std::unique_lock lock(mu_);
  while (!cv_.wait_for(lock, tick, [this] { return stopping_; })) {
    std::erase_if(watched_, [](const std::shared_ptr<UploadWatch>& w) { return w->Settled(); });
    std::vector<std::shared_ptr<UploadWatch>> idle;
    const auto now = UploadWatch::Clock::now();
    for (const auto& w : watched_) {
      if (w->TakeOverIfIdle(now, timeout_)) idle.push_back(w);
    }
    // Outside the lock: finishing a call may run its OnDone, and new uploads register meanwhile.
    lock.unlock();
    for (const auto& w : idle) w->on_idle_();
    lock.lock();
  }
}

}  // namespace tubepick::server

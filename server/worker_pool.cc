#include "server/worker_pool.h"

#include <malloc.h>

#include <spdlog/spdlog.h>

#include <cassert>
#include <exception>
#include <utility>

namespace tubepick::server {

WorkerPool::WorkerPool(std::uint32_t workers, std::uint32_t queue_capacity,
                       std::chrono::milliseconds idle_trim_delay)
    : queue_capacity_(queue_capacity), idle_trim_delay_(idle_trim_delay) {
  assert(workers >= 1);
  threads_.reserve(workers);
  for (std::uint32_t i = 0; i < workers; ++i) threads_.emplace_back([this] { WorkerLoop(); });
}

WorkerPool::~WorkerPool() { Stop(); }

bool WorkerPool::HasRoomLocked() const {
  const std::size_t admitted = busy_ + queue_.size();
  return admitted < threads_.size() + queue_capacity_;
}

WorkerPool::Admission WorkerPool::TrySubmit(Job job) {
  {
    std::lock_guard lock(mu_);
    if (stopping_) return Admission::kStopped;
    if (!HasRoomLocked()) return Admission::kFull;
    queue_.push_back(std::move(job));
  }
  cv_.notify_one();
  return Admission::kAdmitted;
}

bool WorkerPool::HasRoom() const {
  std::lock_guard lock(mu_);
  return !stopping_ && HasRoomLocked();
}

PoolLoad WorkerPool::load() const {
  std::lock_guard lock(mu_);
  PoolLoad load;
  load.workers = static_cast<std::uint32_t>(threads_.size());
  load.busy = busy_;
  load.queued = static_cast<std::uint32_t>(queue_.size());
  return load;
}

void WorkerPool::WorkerLoop() {
  std::unique_lock lock(mu_);
  for (;;) {
    if (trim_pending_ && busy_ == 0 && queue_.empty() && !stopping_) TrimWhenIdle(lock);
    cv_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping and drained
    Job job = std::move(queue_.front());
    queue_.pop_front();
    ++busy_;
    lock.unlock();
    RunGuarded(job);
    job = nullptr;  // destroy captures outside the lock
    lock.lock();
    --busy_;
    trim_pending_ = true;
  }
}

void WorkerPool::TrimWhenIdle(std::unique_lock<std::mutex>& lock) {
  const bool work_came =
      cv_.wait_for(lock, idle_trim_delay_, [this] { return stopping_ || !queue_.empty(); });
  if (work_came || busy_ > 0 || !trim_pending_) return;
  trim_pending_ = false;
  lock.unlock();
#ifdef __GLIBC__
  // The heap tops and the whole free pages inside the arenas go back to the kernel. Not after every
  // call: the next call would fault the same pages in again (about 10 µs a page on a paravirtual
  // VM, a third of a 2.3 M-point call).
  malloc_trim(0);
#endif
  idle_trims_.fetch_add(1);
  lock.lock();
}

void WorkerPool::RunGuarded(const Job& job) {
  try {
    job();
  } catch (const std::exception& e) {
    escaped_exceptions_.fetch_add(1);
    spdlog::error("worker pool: a job threw (a bug; the worker goes on): {}", e.what());
  } catch (...) {
    escaped_exceptions_.fetch_add(1);
    spdlog::error("worker pool: a job threw a non-standard exception (a bug; the worker goes on)");
  }
}

void WorkerPool::Stop() {
  {
    std::lock_guard lock(mu_);
    stopping_ = true;
  }
  cv_.notify_all();
  std::lock_guard join_lock(join_mu_);
  for (std::thread& t : threads_) {
    if (t.joinable()) t.join();
  }
}

}  // namespace tubepick::server

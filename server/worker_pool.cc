#include "server/worker_pool.h"

#include <malloc.h>

#include <spdlog/spdlog.h>

#include <cassert>
#include <exception>
#include <utility>

#include "server/allocator.h"

namespace tubepick::server {
namespace {

// True when glibc's malloc serves this process: not jemalloc (it exports mallctl), not a sanitizer's
// allocator. Under a sanitizer glibc's arenas are never initialised, and two workers trimming them at
// once for the first time crash (seen under TSan).
bool GlibcHeap() {
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  return false;
#else
#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
  return false;
#endif
#endif
  return !UsesJemalloc();
#endif
}

}  // namespace

WorkerPool::WorkerPool(std::uint32_t workers, std::uint32_t queue_capacity)
    : queue_capacity_(queue_capacity) {
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
    cv_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (queue_.empty()) return;  // stopping and drained
    Job job = std::move(queue_.front());
    queue_.pop_front();
    ++busy_;
    lock.unlock();
    RunGuarded(job);
    job = nullptr;  // destroy captures outside the lock
#ifdef __GLIBC__
    // With glibc's allocator (tests, or a server built without jemalloc), give the freed pages of this
    // call back to the kernel (heap tops and whole free pages inside the arenas) so the resident set
    // tracks the calls in flight, not the history. tubepick-server runs on jemalloc, which purges on
    // its own.
    if (GlibcHeap()) malloc_trim(0);
#endif
    lock.lock();
    --busy_;
  }
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

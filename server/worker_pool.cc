#include "server/worker_pool.h"

#include <malloc.h>

#include <spdlog/spdlog.h>

#include <cassert>
#include <exception>
#include <utility>

namespace tubepick::server {

WorkerPool::Reservation::Reservation(Reservation&& other) noexcept
    : pool_(std::exchange(other.pool_, nullptr)) {}

WorkerPool::Reservation& WorkerPool::Reservation::operator=(Reservation&& other) noexcept {
  if (this != &other) {
    Release();
    pool_ = std::exchange(other.pool_, nullptr);
  }
  return *this;
}

WorkerPool::Reservation::~Reservation() { Release(); }

void WorkerPool::Reservation::Release() {
  if (pool_ != nullptr) std::exchange(pool_, nullptr)->ReleaseReservation();
}

WorkerPool::WorkerPool(std::uint32_t workers, std::uint32_t queue_capacity)
    : queue_capacity_(queue_capacity) {
  assert(workers >= 1);
  threads_.reserve(workers);
  for (std::uint32_t i = 0; i < workers; ++i) threads_.emplace_back([this] { WorkerLoop(); });
}

WorkerPool::~WorkerPool() { Stop(); }

bool WorkerPool::HasRoomLocked() const {
  const std::size_t admitted = busy_ + queue_.size() + reserved_;
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

std::optional<WorkerPool::Reservation> WorkerPool::TryReserve() {
  std::lock_guard lock(mu_);
  if (stopping_ || !HasRoomLocked()) return std::nullopt;
  ++reserved_;
  return Reservation(this);
}

WorkerPool::Admission WorkerPool::Submit(Reservation reservation, Job job) {
  assert(reservation.pool_ == this);
  {
    std::lock_guard lock(mu_);
    if (stopping_) return Admission::kStopped;  // ~Reservation releases the slot
    reservation.pool_ = nullptr;                // the slot becomes the queued job
    --reserved_;
    queue_.push_back(std::move(job));
  }
  cv_.notify_one();
  return Admission::kAdmitted;
}

void WorkerPool::ReleaseReservation() {
  std::lock_guard lock(mu_);
  assert(reserved_ > 0);
  --reserved_;
}

PoolLoad WorkerPool::load() const {
  std::lock_guard lock(mu_);
  PoolLoad load;
  load.workers = static_cast<std::uint32_t>(threads_.size());
  load.busy = busy_;
  load.queued = static_cast<std::uint32_t>(queue_.size());
  load.reserved = reserved_;
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
    // Give the freed pages of this call back to the kernel (heap tops and whole free pages inside
    // the arenas) so the resident set tracks the calls in flight, not the history: a few ms against
    // calls of 0.1-1 s.
    malloc_trim(0);
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

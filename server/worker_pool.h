#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

namespace tubepick::server {

/// What the pool is doing right now (metrics, rejection messages).
struct PoolLoad {
  /// Worker threads.
  std::uint32_t workers = 0;
  /// Jobs running on a worker.
  std::uint32_t busy = 0;
  /// Jobs waiting for a worker.
  std::uint32_t queued = 0;
};

/// The bounded planning worker pool with admission control. At most `workers + queue_capacity`
/// jobs are admitted at a time (running or queued); beyond that TrySubmit says no at once, so the server
/// answers RESOURCE_EXHAUSTED instead of letting memory grow. Jobs run in FIFO order. Thread-safe.
class WorkerPool {
 public:
  /// A unit of work. Jobs report their own errors (PlannerService answers every call itself); one
  /// that throws anyway is a bug: it is logged and counted (escaped_exceptions), and the worker goes
  /// on with the next job instead of terminating the process.
  using Job = std::function<void()>;

  /// `workers` ≥ 1 threads start at once.
  WorkerPool(std::uint32_t workers, std::uint32_t queue_capacity);
  ~WorkerPool();  // Stop()
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  enum class Admission { kAdmitted, kFull, kStopped };

  /// Queues `job` when there is room; otherwise drops it and says why.
  Admission TrySubmit(Job job);
  /// Whether TrySubmit would admit a job now (a hint: another caller may take the room first).
  bool HasRoom() const;

  PoolLoad load() const;
  std::uint32_t workers() const { return static_cast<std::uint32_t>(threads_.size()); }
  std::uint32_t queue_capacity() const { return queue_capacity_; }
  /// Jobs that threw although jobs must not (each one logged as an error).
  std::uint64_t escaped_exceptions() const { return escaped_exceptions_.load(); }

  /// Refuses new work, lets the workers finish what is queued, joins them. Idempotent.
  void Stop();

 private:
  void WorkerLoop();
  void RunGuarded(const Job& job);
  bool HasRoomLocked() const;

  const std::uint32_t queue_capacity_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<Job> queue_;
  std::uint32_t busy_ = 0;
  bool stopping_ = false;
  std::atomic<std::uint64_t> escaped_exceptions_{0};
  std::mutex join_mu_;
  std::vector<std::thread> threads_;
};

}  // namespace tubepick::server

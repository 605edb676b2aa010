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
  /// Admitted slots without a job yet (PlanPickStream uploads in progress).
  std::uint32_t reserved = 0;
};

/// The bounded planning worker pool with admission control. At most `workers + queue_capacity`
/// requests are admitted at a time (running, queued, or reserved by an upload in progress); beyond
/// that TrySubmit / TryReserve say no at once, so the server answers RESOURCE_EXHAUSTED instead of
/// letting memory grow. Jobs run in FIFO order. Thread-safe.
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

  /// One admitted slot that holds no job yet (a stream whose chunks are still arriving). Counts
  /// against admission until it is submitted or destroyed (destroying releases it). Movable.
  class Reservation {
   public:
    Reservation() = default;
    Reservation(Reservation&& other) noexcept;
    Reservation& operator=(Reservation&& other) noexcept;
    ~Reservation();
    bool valid() const { return pool_ != nullptr; }
    /// Gives the slot back without running anything.
    void Release();

   private:
    friend class WorkerPool;
    explicit Reservation(WorkerPool* pool) : pool_(pool) {}
    WorkerPool* pool_ = nullptr;
  };

  enum class Admission { kAdmitted, kFull, kStopped };

  /// Queues `job` when there is room; otherwise drops it and says why.
  Admission TrySubmit(Job job);
  /// Takes a slot without a job; nullopt when full or stopped.
  std::optional<Reservation> TryReserve();
  /// Queues `job` on a reservation (never refused for lack of room). kStopped (job dropped) after
  /// Stop(). The reservation is consumed either way.
  Admission Submit(Reservation reservation, Job job);

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
  void ReleaseReservation();

  const std::uint32_t queue_capacity_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::deque<Job> queue_;
  std::uint32_t busy_ = 0;
  std::uint32_t reserved_ = 0;
  bool stopping_ = false;
  std::atomic<std::uint64_t> escaped_exceptions_{0};
  std::mutex join_mu_;
  std::vector<std::thread> threads_;
};

}  // namespace tubepick::server

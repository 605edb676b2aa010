#pragma once

#include <atomic>
#include <cstdint>
#include <optional>

namespace tubepick::server {

/// Admission of PlanPickStream uploads, apart from the planning pool: at most `capacity` uploads
/// (header received, cloud incomplete) at a time. An upload holds no planning slot, so clients
/// that open streams and send slowly (or nothing) cannot keep planning calls out. Thread-safe.
class UploadSlots {
 public:
  explicit UploadSlots(std::uint32_t capacity) : capacity_(capacity) {}
  UploadSlots(const UploadSlots&) = delete;
  UploadSlots& operator=(const UploadSlots&) = delete;

  /// One upload's slot; released when destroyed or on Release(). Movable.
  class Slot {
   public:
    Slot() = default;
    Slot(Slot&& other) noexcept : slots_(other.slots_) { other.slots_ = nullptr; }
    Slot& operator=(Slot&& other) noexcept;
    ~Slot() { Release(); }
    bool valid() const { return slots_ != nullptr; }
    void Release();

   private:
    friend class UploadSlots;
    explicit Slot(UploadSlots* slots) : slots_(slots) {}
    UploadSlots* slots_ = nullptr;
  };

  /// A slot, or nullopt when `capacity` uploads are in progress.
  std::optional<Slot> TryAcquire();
  std::uint32_t in_use() const { return in_use_.load(); }
  std::uint32_t capacity() const { return capacity_; }

 private:
  const std::uint32_t capacity_;
  std::atomic<std::uint32_t> in_use_{0};
};

}  // namespace tubepick::server

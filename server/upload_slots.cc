#include "server/upload_slots.h"

namespace tubepick::server {

UploadSlots::Slot& UploadSlots::Slot::operator=(Slot&& other) noexcept {
  if (this != &other) {
    Release();
    slots_ = other.slots_;
    other.slots_ = nullptr;
  }
  return *this;
}

void UploadSlots::Slot::Release() {
  if (slots_ != nullptr) slots_->in_use_.fetch_sub(1);
  slots_ = nullptr;
}

std::optional<UploadSlots::Slot> UploadSlots::TryAcquire() {
  std::uint32_t used = in_use_.load();
  do {
    if (used >= capacity_) return std::nullopt;
  } while (!in_use_.compare_exchange_weak(used, used + 1));
  return Slot(this);
}

}  // namespace tubepick::server

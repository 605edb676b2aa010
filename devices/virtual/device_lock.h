#pragma once

#include <chrono>
#include <mutex>
#include <thread>

namespace tubepick::devices {

/// Tries to take `device_lock` for up to `wait`: the returned lock owns it, or does not (owns_lock()
/// false) when another thread kept it that long. For protocol answers that can fall back on the last
/// known state rather than keep a driver waiting behind a long device call (std::mutex has no timed
/// lock, so this polls try_lock).
inline std::unique_lock<std::mutex> LockWithin(std::mutex& device_lock, std::chrono::milliseconds wait) {
  std::unique_lock lock(device_lock, std::try_to_lock);
  const auto deadline = std::chrono::steady_clock::now() + wait;
  while (!lock.owns_lock() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::microseconds(200));
    lock.try_lock();
  }
  return lock;
}

}  // namespace tubepick::devices

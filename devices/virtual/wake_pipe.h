#pragma once

#include <string>

namespace tubepick::devices {

/// How the protocol servers' threads wait for their socket and are told to stop: Wait blocks
/// until `fd` is readable or Wake was called (from any thread). Closes its pipe when destroyed.
class WakePipe {
 public:
  /// @throws std::runtime_error naming `who` when the pipe cannot be made.
  explicit WakePipe(const std::string& who);
  ~WakePipe();
  WakePipe(const WakePipe&) = delete;
  WakePipe& operator=(const WakePipe&) = delete;

  /// Lets Wait return kWoken, now and on every later call.
  void Wake();

  enum class Event { kReadable, kWoken, kError };
  /// Waits for `fd` to be readable or for Wake; kError when poll fails (errno tells why; EINTR is
  /// retried).
  Event Wait(int fd) const;

 private:
  int fds_[2] = {-1, -1};
};

}  // namespace tubepick::devices

#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace tubepick::devices {

/// A UDP socket connected to one device (host:port): it only receives that device's datagrams.
/// Shared by the UDP drivers (ATI Net F/T RDT, Yaskawa HSES). Not thread-safe.
class UdpClient {
 public:
  using Clock = std::chrono::steady_clock;

  /// Resolves `host` and connects. `who` prefixes every error message.
  /// @throws DeviceFault when the host does not resolve or the socket cannot be made.
  UdpClient(const std::string& host, std::uint16_t port, std::string who);
  ~UdpClient();
  UdpClient(const UdpClient&) = delete;
  UdpClient& operator=(const UdpClient&) = delete;

  /// Discards datagrams already queued (late answers to an earlier, timed-out request).
  void DrainStale();
  /// @throws DeviceTimeout when the socket cannot send before `deadline`, DeviceFault on errors.
  void Send(std::span<const std::uint8_t> bytes, Clock::time_point deadline);
  /// Waits for one datagram until `deadline` (never returning early); its size, or nullopt when
  /// the deadline passed. @throws DeviceFault on socket errors (e.g. nothing listens at host:port).
  std::optional<std::size_t> Receive(std::span<std::uint8_t> buffer, Clock::time_point deadline);

 private:
  std::string who_;
  int fd_ = -1;
};

}  // namespace tubepick::devices

#pragma once

#include <array>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <span>
#include <vector>

#include "devices/testing/loopback_udp_server.h"
#include "devices/yaskawa_hses.h"

namespace tubepick::devices {

/// A loopback stand-in for a YRC1000's HSES server, for tests. Binds 127.0.0.1 on an
/// ephemeral UDP port and answers status read (0x72), base position read (0x75, instance 101),
/// servo on/off (0x83, instance 2) and straight moves (0x8A): a move reports "running" for
/// `move_duration`, then the position becomes its target. Unknown commands get status 0x08.
/// Can inject an error status or stay silent. One thread; the destructor stops and joins it.
class HsesFake {
 public:
  explicit HsesFake(std::chrono::milliseconds move_duration = std::chrono::milliseconds(50));

  std::uint16_t port() const { return server_.port(); }

  /// Every answer from now on carries this status and added status (0, 0 = normal).
  void SetErrorStatus(std::uint8_t status, std::uint16_t added_status);
  /// While silent the fake receives and records requests but answers none.
  void SetSilent(bool silent);
  /// The base position words (x, y, z µm; Rx, Ry, Rz 0.0001°).
  void SetPosition(const std::array<std::int32_t, 6>& words);
  std::array<std::int32_t, 6> position() const;

  bool servo_on() const;
  int status_reads() const;
  std::vector<hses::Request> requests() const;
  /// The data words of every move request received.
  std::vector<std::array<std::int32_t, hses::kMoveWords>> moves() const;

 private:
  std::vector<LoopbackUdpServer::Datagram> Serve(std::span<const std::uint8_t> datagram);
  hses::Answer Handle(const hses::Request& request);

  std::chrono::milliseconds move_duration_;

  mutable std::mutex mutex_;
  std::uint8_t error_status_ = 0;
  std::uint16_t error_added_ = 0;
  bool silent_ = false;
  bool servo_on_ = false;
  int status_reads_ = 0;
  std::array<std::int32_t, 6> position_{};
  std::array<std::int32_t, 6> target_{};
  bool moving_ = false;
  std::chrono::steady_clock::time_point move_end_{};
  std::vector<hses::Request> requests_;
  std::vector<std::array<std::int32_t, hses::kMoveWords>> moves_;

  LoopbackUdpServer server_;  // last: its thread stops before the state above is destroyed
};

}  // namespace tubepick::devices

#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <deque>
#include <mutex>
#include <span>
#include <vector>

#include "devices/ati_netft.h"
#include "devices/testing/loopback_udp_server.h"

namespace tubepick::devices {

/// A loopback stand-in for an ATI Net F/T's RDT server, for tests. Binds 127.0.0.1 on an
/// ephemeral UDP port and answers each start-streaming request with `sample_count` records
/// (one when the count is 0: the fake does not stream) carrying the scripted counts/status.
/// Counts bias commands and keeps every request's raw bytes. One thread; the destructor
/// stops and joins it.
class RdtFake {
 public:
  RdtFake();

  std::uint16_t port() const { return server_.port(); }

  /// The counts (Fx, Fy, Fz, Tx, Ty, Tz) and status word of the records sent from now on.
  void SetReply(const std::array<std::int32_t, 6>& counts, std::uint32_t status = 0);
  /// While silent the fake receives and records requests but answers none.
  void SetSilent(bool silent);

  int bias_count() const;
  std::vector<rdt::RequestBytes> requests() const;

 private:
  std::vector<LoopbackUdpServer::Datagram> Handle(std::span<const std::uint8_t> datagram);

  mutable std::mutex mutex_;
  std::array<std::int32_t, 6> counts_{};
  std::uint32_t status_ = 0;
  bool silent_ = false;
  int bias_count_ = 0;
  std::uint32_t ft_sequence_ = 0;
  std::vector<rdt::RequestBytes> requests_;

  LoopbackUdpServer server_;  // last: its thread stops before the state above is destroyed
};

}  // namespace tubepick::devices

#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "devices/virtual/wake_pipe.h"

namespace tubepick::devices {

/// Where a datagram came from (IPv4, host byte order).
struct UdpPeer {
  std::uint32_t address = 0;
  std::uint16_t port = 0;
  /// "a.b.c.d:port".
  std::string ToString() const;
};

/// The socket side of the virtual devices' UDP protocol servers (HSES, RDT): binds host:port
/// (IPv4; port 0 = an ephemeral port) and, on its own thread, hands every datagram to `handle`,
/// sending back to the sender whatever datagrams it returns (none = stay silent). SendTo lets
/// another thread send too (e.g. a stream). The destructor stops and joins the thread.
class UdpServer {
 public:
  using Datagram = std::vector<std::uint8_t>;
  using Handler =
      std::function<std::vector<Datagram>(std::span<const std::uint8_t> request, const UdpPeer& from)>;

  /// @throws InvalidArgument naming `who` and the host when it does not resolve; std::runtime_error
  /// naming `who` when the socket cannot be made or bound (e.g. the port is taken).
  UdpServer(std::string who, const std::string& host, std::uint16_t port, Handler handle);
  ~UdpServer();
  UdpServer(const UdpServer&) = delete;
  UdpServer& operator=(const UdpServer&) = delete;

  /// The bound address and port (the ephemeral port when 0 was asked for).
  const std::string& host() const { return host_; }
  std::uint16_t port() const { return port_; }

  /// Sends one datagram to `to`; errors are logged, not thrown (UDP loses datagrams anyway).
  /// Thread-safe; valid until the destructor (also after Stop()).
  void SendTo(const UdpPeer& to, std::span<const std::uint8_t> bytes);
  /// Stops and joins the receive thread: `handle` is not called after this returns. Idempotent.
  /// Owners call it first in their destructors, before the state `handle` uses goes away.
  void Stop();

 private:
  void Run();

  std::string who_;
  Handler handle_;
  std::string host_;
  int fd_ = -1;
  WakePipe wake_;  // Stop() wakes the thread
  std::uint16_t port_ = 0;
  std::thread thread_;
};

}  // namespace tubepick::devices

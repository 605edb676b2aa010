#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <thread>
#include <vector>

namespace tubepick::devices {

/// The socket side of the UDP protocol fakes used by tests: binds 127.0.0.1 on an ephemeral
/// port and, on its own thread, hands every datagram to `handle`, sending back to the sender
/// whatever datagrams it returns (none = stay silent). The destructor stops and joins the thread.
class LoopbackUdpServer {
 public:
  using Datagram = std::vector<std::uint8_t>;
  using Handler = std::function<std::vector<Datagram>(std::span<const std::uint8_t> request)>;

  /// @throws std::runtime_error naming `who` when the socket cannot be made.
  LoopbackUdpServer(std::string who, Handler handle);
  ~LoopbackUdpServer();
  LoopbackUdpServer(const LoopbackUdpServer&) = delete;
  LoopbackUdpServer& operator=(const LoopbackUdpServer&) = delete;

  std::uint16_t port() const { return port_; }

 private:
  void Run();

  Handler handle_;
  int fd_ = -1;
  int wake_[2] = {-1, -1};  // pipe: the destructor writes to wake the thread
  std::uint16_t port_ = 0;
  std::thread thread_;
};

}  // namespace tubepick::devices

#include "devices/udp_client.h"

#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/types.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "devices/device_error.h"

namespace tubepick::devices {
namespace {

std::string Errno(const std::string& what) { return what + ": " + std::strerror(errno); }

// Milliseconds left until `deadline`, rounded up so a wait never ends before it.
int MillisecondsLeft(UdpClient::Clock::time_point deadline) {
  const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - UdpClient::Clock::now()).count();
  return left > 0 ? static_cast<int>(left) : 0;
}

}  // namespace

UdpClient::UdpClient(const std::string& host, std::uint16_t port, std::string who) : who_(std::move(who)) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  const std::string port_text = std::to_string(port);
  if (const int rc = ::getaddrinfo(host.c_str(), port_text.c_str(), &hints, &found); rc != 0) {
    throw DeviceFault(who_ + ": cannot resolve '" + host + "': " + ::gai_strerror(rc));
  }
  fd_ = ::socket(found->ai_family, found->ai_socktype | SOCK_CLOEXEC, found->ai_protocol);
  if (fd_ < 0) {
    ::freeaddrinfo(found);
    throw DeviceFault(Errno(who_ + ": socket"));
  }
  const int rc = ::connect(fd_, found->ai_addr, found->ai_addrlen);
  ::freeaddrinfo(found);
  if (rc != 0) {
    const std::string message = Errno(who_ + ": connect");
    ::close(fd_);
    throw DeviceFault(message);
  }
}

UdpClient::~UdpClient() {
  if (fd_ >= 0) ::close(fd_);
}

void UdpClient::DrainStale() {
  std::uint8_t buf[2048];
  while (::recv(fd_, buf, sizeof buf, MSG_DONTWAIT) >= 0) {
  }
}

void UdpClient::Send(std::span<const std::uint8_t> bytes, Clock::time_point deadline) {
  pollfd pfd{fd_, POLLOUT, 0};
  const int ready = ::poll(&pfd, 1, MillisecondsLeft(deadline));
  if (ready == 0) throw DeviceTimeout(who_ + ": send not possible before the deadline");
  if (ready < 0) throw DeviceFault(Errno(who_ + ": poll"));
  const ssize_t sent = ::send(fd_, bytes.data(), bytes.size(), MSG_DONTWAIT);
  if (sent != static_cast<ssize_t>(bytes.size())) throw DeviceFault(Errno(who_ + ": send"));
}

std::optional<std::size_t> UdpClient::Receive(std::span<std::uint8_t> buffer, Clock::time_point deadline) {
  for (;;) {
    const int left = MillisecondsLeft(deadline);
    pollfd pfd{fd_, POLLIN, 0};
    const int ready = left > 0 ? ::poll(&pfd, 1, left) : 0;
    if (ready == 0) return std::nullopt;
    if (ready < 0) {
      if (errno == EINTR) continue;
      throw DeviceFault(Errno(who_ + ": poll"));
    }
    const ssize_t got = ::recv(fd_, buffer.data(), buffer.size(), MSG_DONTWAIT);
    if (got < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) continue;
      // E.g. ECONNREFUSED from an ICMP port-unreachable: nothing listens at host:port.
      throw DeviceFault(Errno(who_ + ": recv"));
    }
    return static_cast<std::size_t>(got);
  }
}

}  // namespace tubepick::devices

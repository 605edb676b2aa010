#include "devices/virtual/udp_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <utility>

#include <spdlog/spdlog.h>

#include "core/common/errors.h"

namespace tubepick::devices {
namespace {

sockaddr_in ToSockaddr(const UdpPeer& peer) {
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(peer.address);
  addr.sin_port = htons(peer.port);
  return addr;
}

}  // namespace

std::string UdpPeer::ToString() const {
  return std::to_string((address >> 24) & 0xFF) + "." + std::to_string((address >> 16) & 0xFF) + "." +
         std::to_string((address >> 8) & 0xFF) + "." + std::to_string(address & 0xFF) + ":" +
         std::to_string(port);
}

UdpServer::UdpServer(std::string who, const std::string& host, std::uint16_t port, Handler handle)
    : who_(std::move(who)), handle_(std::move(handle)), wake_(who_) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  const std::string port_text = std::to_string(port);
  if (const int rc = ::getaddrinfo(host.c_str(), port_text.c_str(), &hints, &found); rc != 0) {
    throw InvalidArgument(who_ + ": cannot resolve bind host '" + host + "': " + ::gai_strerror(rc));
  }
  sockaddr_in addr{};
  std::memcpy(&addr, found->ai_addr, sizeof addr);
  ::freeaddrinfo(found);

  const auto fail = [this](const std::string& what) {
    const std::runtime_error error(who_ + ": " + what + ": " + std::strerror(errno));
    if (fd_ >= 0) ::close(fd_);
    return error;
  };
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) throw fail("socket");
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
    throw fail("bind " + host + ":" + port_text);
  }
  socklen_t len = sizeof addr;
  if (::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len) != 0) throw fail("getsockname");
  char text[INET_ADDRSTRLEN] = {};
  ::inet_ntop(AF_INET, &addr.sin_addr, text, sizeof text);
  host_ = text;
  port_ = ntohs(addr.sin_port);
  thread_ = std::thread([this] { Run(); });
}

UdpServer::~UdpServer() {
  Stop();
  ::close(fd_);
}

void UdpServer::Stop() {
  if (!thread_.joinable()) return;
  wake_.Wake();
  thread_.join();
}

void UdpServer::SendTo(const UdpPeer& to, std::span<const std::uint8_t> bytes) {
  const sockaddr_in addr = ToSockaddr(to);
  if (::sendto(fd_, bytes.data(), bytes.size(), 0, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) <
      0) {
    spdlog::warn("{}: send to {} failed: {}", who_, to.ToString(), std::strerror(errno));
  }
}

void UdpServer::Run() {
  for (;;) {
    const WakePipe::Event event = wake_.Wait(fd_);
    if (event == WakePipe::Event::kError)
      spdlog::error("{}: poll failed: {}; the server stops", who_, std::strerror(errno));
    if (event != WakePipe::Event::kReadable) return;
    std::uint8_t buf[2048];
    sockaddr_in addr{};
    socklen_t addr_len = sizeof addr;
    const ssize_t got =
        ::recvfrom(fd_, buf, sizeof buf, MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&addr), &addr_len);
    if (got < 0) continue;  // ECONNREFUSED from an earlier send to a closed peer, or EAGAIN
    const UdpPeer peer{ntohl(addr.sin_addr.s_addr), ntohs(addr.sin_port)};
    std::vector<Datagram> replies;
    try {
      replies = handle_(std::span<const std::uint8_t>(buf, static_cast<std::size_t>(got)), peer);
    } catch (const std::exception& e) {
      spdlog::error("{}: request from {} failed: {}", who_, peer.ToString(), e.what());
    }
    for (const Datagram& reply : replies) SendTo(peer, reply);
  }
}

}  // namespace tubepick::devices

#include "devices/virtual/netft_http_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <fmt/core.h>
#include <netinet/in.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace tubepick::devices {
namespace {

std::string ReadRequestLine(int fd) {
  std::string request;
  char buf[1024];
  while (request.find("\r\n\r\n") == std::string::npos && request.size() < 8192) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 1000) <= 0) break;
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    request.append(buf, static_cast<std::size_t>(n));
  }
  return request.substr(0, request.find("\r\n"));
}

}  // namespace

NetFtHttpServer::NetFtHttpServer(const std::string& host, std::uint16_t port, NetFtCalibration calibration)
    : calibration_(std::move(calibration)) {
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  if (::inet_pton(AF_INET, host.c_str(), &address.sin_addr) != 1)
    throw std::runtime_error(fmt::format("Net F/T web server: '{}' is not an IPv4 address", host));
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  const int on = 1;
  if (fd_ >= 0) ::setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
  socklen_t length = sizeof address;
  if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      ::listen(fd_, 8) != 0 || ::getsockname(fd_, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    const std::string why = std::strerror(errno);
    if (fd_ >= 0) ::close(fd_);
    throw std::runtime_error(fmt::format("Net F/T web server {}:{}: {}", host, port, why));
  }
  port_ = ntohs(address.sin_port);
  thread_ = std::thread([this] { Run(); });
}

NetFtHttpServer::~NetFtHttpServer() {
  wake_.Wake();
  thread_.join();
  ::close(fd_);
}

void NetFtHttpServer::Run() {
  for (;;) {
    if (wake_.Wait(fd_) != WakePipe::Event::kReadable) return;
    const int client = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (client < 0) continue;
    const std::string line = ReadRequestLine(client);
    std::string response;
    if (line.rfind("GET /netftapi2.xml ", 0) == 0) {
      const std::string body = fmt::format(
          "<?xml version=\"1.0\"?>\n<netft>\n<cfgcpf>{}</cfgcpf>\n<cfgcpt>{}</cfgcpt>\n<scfgfu>{}</scfgfu>\n"
          "<scfgtu>{}</scfgtu>\n</netft>\n",
          calibration_.counts_per_force, calibration_.counts_per_torque, calibration_.force_unit,
          calibration_.torque_unit);
      response = fmt::format("HTTP/1.0 200 OK\r\nContent-Type: text/xml\r\nContent-Length: {}\r\n\r\n{}",
                             body.size(), body);
    } else {
      response = "HTTP/1.0 404 Not Found\r\nContent-Length: 0\r\n\r\n";
      spdlog::debug("Net F/T web server: 404 for '{}'", line);
    }
    [[maybe_unused]] const ssize_t sent = ::send(client, response.data(), response.size(), MSG_NOSIGNAL);
    ::close(client);
  }
}

}  // namespace tubepick::devices

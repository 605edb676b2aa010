#include "server/metrics_http.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <stdexcept>

#include "core/common/errors.h"

namespace tubepick::server {
namespace {

constexpr std::size_t kMaxRequestHead = 8192;

const char* ReasonPhrase(int status) {
  switch (status) {
    case 200:
      return "OK";
    case 400:
      return "Bad Request";
    case 404:
      return "Not Found";
    case 405:
      return "Method Not Allowed";
    case 408:
      return "Request Timeout";
    case 431:
      return "Request Header Fields Too Large";
    case 500:
      return "Internal Server Error";
    case 503:
      return "Service Unavailable";
    default:
      return "Error";
  }
}

HttpReply Plain(int status, std::string body) {
  HttpReply r;
  r.status = status;
  r.content_type = "text/plain; charset=utf-8";
  r.body = std::move(body);
  return r;
}

std::string Serialize(const HttpReply& r, bool head_only) {
  std::string out =
      fmt::format("HTTP/1.1 {} {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nConnection: close\r\n{}\r\n",
                  r.status, ReasonPhrase(r.status), r.content_type, r.body.size(), r.extra_headers);
  if (!head_only) out += r.body;
  return out;
}

int RemainingMs(std::chrono::steady_clock::time_point deadline) {
  const auto left =
      std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
  return left.count() > 0 ? static_cast<int>(left.count()) : 0;
}

// Writes everything or gives up at the deadline (a client that does not read).
void SendAll(int fd, std::string_view data, std::chrono::steady_clock::time_point deadline) {
  while (!data.empty()) {
    pollfd p{fd, POLLOUT, 0};
    const int ms = RemainingMs(deadline);
    if (ms == 0 || ::poll(&p, 1, ms) <= 0) return;
    const ssize_t n = ::send(fd, data.data(), data.size(), MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      return;
    }
    data.remove_prefix(static_cast<std::size_t>(n));
  }
}

}  // namespace

std::pair<std::string, int> SplitHostPort(std::string_view address, const std::string& field) {
  const std::size_t colon = address.rfind(':');
  if (colon == std::string_view::npos || colon + 1 == address.size())
    throw InvalidArgument(fmt::format("{}: '{}' is not HOST:PORT", field, address));
  std::string_view host = address.substr(0, colon);
  const std::string_view port_text = address.substr(colon + 1);
  int port = -1;
  const auto [end, ec] = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
  if (ec != std::errc() || end != port_text.data() + port_text.size() || port < 0 || port > 65535)
    throw InvalidArgument(fmt::format("{}: port '{}' of '{}' is not 0..65535", field, port_text, address));
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  return {std::string(host), port};
}

HttpReply HandleMetricsRequest(std::string_view head, const std::function<std::string()>& render,
                               const std::function<bool()>& serving) {
  const std::size_t line_end = head.find("\r\n");
  const std::string_view line = head.substr(0, line_end);
  // request-line = method SP request-target SP HTTP-version
  const std::size_t sp1 = line.find(' ');
  const std::size_t sp2 = sp1 == std::string_view::npos ? sp1 : line.find(' ', sp1 + 1);
  if (sp1 == std::string_view::npos || sp2 == std::string_view::npos || sp1 == 0 || sp2 == sp1 + 1 ||
      line.find(' ', sp2 + 1) != std::string_view::npos)
    return Plain(400, "malformed request line\n");
  const std::string_view method = line.substr(0, sp1);
  std::string_view target = line.substr(sp1 + 1, sp2 - sp1 - 1);
  const std::string_view version = line.substr(sp2 + 1);
  if (version.rfind("HTTP/1.", 0) != 0 || version.size() != 8)
    return Plain(400, "unsupported HTTP version\n");
  for (char c : line) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e)
      return Plain(400, "invalid character in request line\n");
  }
  if (method != "GET" && method != "HEAD") {
    HttpReply r = Plain(405, "only GET and HEAD\n");
    r.extra_headers = "Allow: GET, HEAD\r\n";
    return r;
  }
  target = target.substr(0, target.find('?'));
  if (target == "/healthz" && serving)
    return serving() ? Plain(200, "SERVING\n") : Plain(503, "NOT_SERVING\n");
  if (target != "/metrics") return Plain(404, "not found; metrics are at /metrics\n");
  HttpReply r;
  r.content_type = "text/plain; version=0.0.4; charset=utf-8";
  r.body = render();
  return r;
}

MetricsHttpServer::MetricsHttpServer(const std::string& address, std::function<std::string()> render,
                                     std::chrono::milliseconds io_timeout, std::function<bool()> serving)
    : render_(std::move(render)), serving_(std::move(serving)), io_timeout_(io_timeout) {
  const auto [host, port] = SplitHostPort(address, "metrics_address");
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  const std::string service = std::to_string(port);
  const int gai = ::getaddrinfo(host.empty() ? nullptr : host.c_str(), service.c_str(), &hints, &found);
  if (gai != 0)
    throw std::runtime_error(fmt::format("metrics: cannot resolve '{}': {}", address, ::gai_strerror(gai)));
  std::string error = "no address";
  for (addrinfo* a = found; a != nullptr && listen_fd_ < 0; a = a->ai_next) {
    const int fd = ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    const int one = 1;
    ::setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (::bind(fd, a->ai_addr, a->ai_addrlen) == 0 && ::listen(fd, 16) == 0) {
      listen_fd_ = fd;
    } else {
      error = std::strerror(errno);
      ::close(fd);
    }
  }
  ::freeaddrinfo(found);
  if (listen_fd_ < 0)
    throw std::runtime_error(fmt::format("metrics: cannot listen on {}: {}", address, error));
  sockaddr_storage bound{};
  socklen_t len = sizeof bound;
  ::getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&bound), &len);
  port_ = bound.ss_family == AF_INET6 ? ntohs(reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port)
                                      : ntohs(reinterpret_cast<sockaddr_in*>(&bound)->sin_port);
  if (::pipe2(wake_pipe_, O_CLOEXEC) != 0) {
    ::close(listen_fd_);
    throw std::runtime_error(fmt::format("metrics: pipe: {}", std::strerror(errno)));
  }
  thread_ = std::thread([this] { Serve(); });
}

MetricsHttpServer::~MetricsHttpServer() { Stop(); }

void MetricsHttpServer::Stop() {
  if (stopping_.exchange(true)) return;
  const char byte = 0;
  [[maybe_unused]] const ssize_t n = ::write(wake_pipe_[1], &byte, 1);
  if (thread_.joinable()) thread_.join();
  ::close(listen_fd_);
  ::close(wake_pipe_[0]);
  ::close(wake_pipe_[1]);
}

void MetricsHttpServer::Serve() {
  for (;;) {
    pollfd fds[2] = {{listen_fd_, POLLIN, 0}, {wake_pipe_[0], POLLIN, 0}};
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      spdlog::error("metrics: poll: {}", std::strerror(errno));
      return;
    }
    if (fds[1].revents != 0) return;
    if ((fds[0].revents & POLLIN) == 0) continue;
    const int fd = ::accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
    if (fd < 0) continue;  // ECONNABORTED, EMFILE, ...: try the next one
    HandleConnection(fd);
    ::close(fd);
  }
}

void MetricsHttpServer::HandleConnection(int fd) {
  const auto deadline = std::chrono::steady_clock::now() + io_timeout_;
  std::string head;
  char buffer[2048];
  for (;;) {
    const std::size_t end = head.find("\r\n\r\n");
    if (end != std::string::npos) {
      head.resize(end + 2);
      break;
    }
    if (head.size() > kMaxRequestHead) {
      Reply(fd, Serialize(Plain(431, "request head too large\n"), false));
      return;
    }
    pollfd p[2] = {{fd, POLLIN, 0}, {wake_pipe_[0], POLLIN, 0}};
    const int ms = RemainingMs(deadline);
    if (ms == 0) {
      Reply(fd, Serialize(Plain(408, "request timeout\n"), false));
      return;
    }
    if (::poll(p, 2, ms) < 0 && errno != EINTR) return;
    if (p[1].revents != 0) return;  // stopping
    if ((p[0].revents & (POLLIN | POLLHUP | POLLERR)) == 0) continue;
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n == 0) return;  // peer closed before a full request
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      return;
    }
    head.append(buffer, static_cast<std::size_t>(n));
  }
  const bool head_only = head.rfind("HEAD ", 0) == 0;
  HttpReply reply;
  try {
    reply = HandleMetricsRequest(head, render_, serving_);
  } catch (const std::exception& e) {
    spdlog::error("metrics: rendering failed: {}", e.what());
    reply = Plain(500, "internal error\n");
  }
  Reply(fd, Serialize(reply, head_only));
}

void MetricsHttpServer::Reply(int fd, std::string_view response) {
  const auto deadline = std::chrono::steady_clock::now() + io_timeout_;
  SendAll(fd, response, deadline);
  // Half-close and drain briefly, so unread request bytes do not turn close() into a reset that
  // destroys the response in flight.
  ::shutdown(fd, SHUT_WR);
  const auto drain_deadline =
      std::min(deadline, std::chrono::steady_clock::now() + std::chrono::milliseconds(100));
  char buffer[512];
  for (;;) {
    pollfd p{fd, POLLIN, 0};
    const int ms = RemainingMs(drain_deadline);
    if (ms == 0 || ::poll(&p, 1, ms) <= 0) return;
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n == 0 || (n < 0 && errno != EINTR && errno != EAGAIN)) return;
  }
}

}  // namespace tubepick::server

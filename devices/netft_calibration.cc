#include "devices/netft_calibration.h"

#include <fcntl.h>
#include <fmt/core.h>
#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>

#include "core/common/errors.h"

namespace tubepick::devices {
namespace {

using Clock = std::chrono::steady_clock;

std::string Element(const std::string& xml, const std::string& tag) {
  const std::string open = "<" + tag + ">", close = "</" + tag + ">";
  const auto begin = xml.find(open);
  const auto end = begin == std::string::npos ? std::string::npos : xml.find(close, begin);
  if (end == std::string::npos) throw DeviceFault("Net F/T netftapi2.xml: no <" + tag + "> element");
  std::string text = xml.substr(begin + open.size(), end - begin - open.size());
  const auto first = text.find_first_not_of(" \t\r\n"), last = text.find_last_not_of(" \t\r\n");
  return first == std::string::npos ? "" : text.substr(first, last - first + 1);
}

double Positive(const std::string& text, const std::string& tag) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || !(value > 0.0))
    throw DeviceFault(
        fmt::format("Net F/T netftapi2.xml: <{}> is '{}', expected a positive number", tag, text));
  return value;
}

int WaitFor(int fd, short events, Clock::time_point deadline) {
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) return 0;
    pollfd p{fd, events, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(left));
    if (ready < 0 && errno == EINTR) continue;
    return ready;
  }
}

}  // namespace

double NetFtCalibration::CountsPerNewton() const {
  // counts per unit / (N per unit)
  if (force_unit == "N") return counts_per_force;
  if (force_unit == "kN") return counts_per_force / 1000.0;
  if (force_unit == "lbf") return counts_per_force / 4.4482216152605;
  if (force_unit == "klbf") return counts_per_force / 4448.2216152605;
  if (force_unit == "g") return counts_per_force / 0.00980665;
  if (force_unit == "kg") return counts_per_force / 9.80665;
  throw InvalidArgument(
      fmt::format("Net F/T force unit '{}' (scfgfu) is not known: N, kN, lbf, klbf, g, kg", force_unit));
}

double NetFtCalibration::CountsPerNewtonMetre() const {
  if (torque_unit == "Nm" || torque_unit == "N-m") return counts_per_torque;
  if (torque_unit == "N-mm" || torque_unit == "Nmm") return counts_per_torque * 1000.0;
  if (torque_unit == "kN-m" || torque_unit == "kNm") return counts_per_torque / 1000.0;
  if (torque_unit == "lbf-in") return counts_per_torque / 0.112984829027617;
  if (torque_unit == "lbf-ft") return counts_per_torque / 1.3558179483314;
  throw InvalidArgument(fmt::format(
      "Net F/T torque unit '{}' (scfgtu) is not known: Nm, N-mm, kN-m, lbf-in, lbf-ft", torque_unit));
}

NetFtCalibration ParseNetFtApi2(const std::string& xml) {
  NetFtCalibration c;
  c.counts_per_force = Positive(Element(xml, "cfgcpf"), "cfgcpf");
  c.counts_per_torque = Positive(Element(xml, "cfgcpt"), "cfgcpt");
  c.force_unit = Element(xml, "scfgfu");
  c.torque_unit = Element(xml, "scfgtu");
  return c;
}

NetFtCalibration ReadNetFtCalibration(const std::string& host, std::uint16_t port, Timeout timeout) {
  const std::string who = fmt::format("Net F/T http://{}:{}/netftapi2.xml", host, port);
  const auto deadline = Clock::now() + timeout;
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  if (const int rc = ::getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found); rc != 0)
    throw DeviceFault(fmt::format("{}: {} does not resolve: {}", who, host, ::gai_strerror(rc)));
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  const int connected = fd < 0 ? -1 : ::connect(fd, found->ai_addr, found->ai_addrlen);
  ::freeaddrinfo(found);
  if (fd < 0) throw DeviceFault(fmt::format("{}: socket: {}", who, std::strerror(errno)));
  struct Closer {
    int fd;
    ~Closer() { ::close(fd); }
  } closer{fd};
  if (connected != 0 && errno != EINPROGRESS)
    throw DeviceFault(fmt::format("{}: connect: {}", who, std::strerror(errno)));
  if (WaitFor(fd, POLLOUT, deadline) <= 0) throw DeviceTimeout(who + ": no connection within the timeout");
  int error = 0;
  socklen_t length = sizeof error;
  ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &length);
  if (error != 0) throw DeviceFault(fmt::format("{}: connect: {}", who, std::strerror(error)));
  const std::string request = fmt::format("GET /netftapi2.xml HTTP/1.0\r\nHost: {}\r\n\r\n", host);
  if (::send(fd, request.data(), request.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(request.size()))
    throw DeviceFault(fmt::format("{}: send: {}", who, std::strerror(errno)));
  std::string response;
  char buf[4096];
  for (;;) {
    if (WaitFor(fd, POLLIN, deadline) <= 0)
      throw DeviceTimeout(who + ": no complete answer within the timeout");
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n < 0) throw DeviceFault(fmt::format("{}: recv: {}", who, std::strerror(errno)));
    if (n == 0) break;
    response.append(buf, static_cast<std::size_t>(n));
    if (response.size() > (1u << 20)) throw DeviceFault(who + ": answer larger than 1 MiB");
  }
  const auto line_end = response.find("\r\n");
  const std::string status = response.substr(0, line_end);
  if (status.find(" 200") == std::string::npos)
    throw DeviceFault(fmt::format("{}: answered '{}'", who, status));
  const auto body = response.find("\r\n\r\n");
  return ParseNetFtApi2(body == std::string::npos ? "" : response.substr(body + 4));
}

}  // namespace tubepick::devices

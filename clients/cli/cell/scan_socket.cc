#include "clients/cli/cell/scan_socket.h"

#include <fcntl.h>
#include <fmt/core.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace tubepick::cli {
namespace {

sockaddr_un Address(const std::string& path) {
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  if (path.size() >= sizeof(address.sun_path))
    throw std::runtime_error(
        fmt::format("scan socket {}: path longer than {} bytes", path, sizeof(address.sun_path) - 1));
  std::memcpy(address.sun_path, path.c_str(), path.size() + 1);
  return address;
}

/// Reads up to the first newline (or EOF), at most 4 KiB.
std::string ReadLine(int fd) {
  std::string line;
  char c = 0;
  while (line.size() < 4096) {
    const ssize_t n = ::read(fd, &c, 1);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0 || c == '\n') break;
    line += c;
  }
  return line;
}

void WriteAll(int fd, const std::string& text) {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    done += static_cast<std::size_t>(n);
  }
}

}  // namespace

ScanSocketServer::ScanSocketServer(std::string socket_path,
                                   std::function<std::string(const std::string&)> serve)
    : path_(std::move(socket_path)), serve_(std::move(serve)) {
  const sockaddr_un address = Address(path_);
  ::unlink(path_.c_str());
  fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0 || ::bind(fd_, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0 ||
      ::listen(fd_, 4) != 0) {
    const std::string why = std::strerror(errno);
    if (fd_ >= 0) ::close(fd_);
    throw std::runtime_error(fmt::format("scan socket {}: {}", path_, why));
  }
  thread_ = std::thread([this] { Run(); });
}

ScanSocketServer::~ScanSocketServer() {
  wake_.Wake();
  thread_.join();
  ::close(fd_);
  ::unlink(path_.c_str());
}

void ScanSocketServer::Run() {
  for (;;) {
    const devices::WakePipe::Event event = wake_.Wait(fd_);
    if (event == devices::WakePipe::Event::kError)
      spdlog::error("scan socket {}: poll: {}", path_, std::strerror(errno));
    if (event != devices::WakePipe::Event::kReadable) return;
    const int client = ::accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC);
    if (client < 0) continue;
    const std::string out = ReadLine(client);
    std::string error = out.empty() ? "empty request: expected the path to write" : "";
    if (error.empty()) {
      try {
        error = serve_(out);
      } catch (const std::exception& e) {
        error = e.what();
      }
    }
    WriteAll(client, error.empty() ? "ok\n" : "error: " + error + "\n");
    ::close(client);
  }
}

std::string RequestScan(const std::string& socket_path, const std::string& out_path) {
  const sockaddr_un address = Address(socket_path);
  const int fd = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return fmt::format("socket: {}", std::strerror(errno));
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    const std::string why =
        fmt::format("cannot reach the virtual cell at {}: {} (is `tubepick virtual-cell` running?)",
                    socket_path, std::strerror(errno));
    ::close(fd);
    return why;
  }
  WriteAll(fd, out_path + "\n");
  const std::string answer = ReadLine(fd);
  ::close(fd);
  if (answer == "ok") return "";
  if (answer.rfind("error: ", 0) == 0) return answer.substr(7);
  return answer.empty() ? "the virtual cell closed the connection without an answer"
                        : "unexpected answer: " + answer;
}

}  // namespace tubepick::cli

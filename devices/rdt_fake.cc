#include "devices/rdt_fake.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace tubepick::devices {
namespace {

std::runtime_error SysError(const char* what) {
  return std::runtime_error(std::string("RdtFake: ") + what + ": " + std::strerror(errno));
}

}  // namespace

RdtFake::RdtFake() {
  fd_ = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    throw SysError("socket");
  }
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  socklen_t len = sizeof addr;
  if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0 ||
      ::getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len) != 0 || ::pipe2(wake_, O_CLOEXEC) != 0) {
    const auto error = SysError("bind/getsockname/pipe");
    ::close(fd_);
    throw error;
  }
  port_ = ntohs(addr.sin_port);
  thread_ = std::thread([this] { Run(); });
}

RdtFake::~RdtFake() {
  const char byte = 0;
  [[maybe_unused]] const ssize_t n = ::write(wake_[1], &byte, 1);
  thread_.join();
  ::close(fd_);
  ::close(wake_[0]);
  ::close(wake_[1]);
}

void RdtFake::SetReply(const std::array<std::int32_t, 6>& counts, std::uint32_t status) {
  std::lock_guard lock(mutex_);
  counts_ = counts;
  status_ = status;
}

void RdtFake::SetSilent(bool silent) {
  std::lock_guard lock(mutex_);
  silent_ = silent;
}

int RdtFake::bias_count() const {
  std::lock_guard lock(mutex_);
  return bias_count_;
}

std::vector<rdt::RequestBytes> RdtFake::requests() const {
  std::lock_guard lock(mutex_);
  return requests_;
}

void RdtFake::Run() {
  for (;;) {
    pollfd fds[2] = {{fd_, POLLIN, 0}, {wake_[0], POLLIN, 0}};
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) {
        continue;
      }
      return;
    }
    if (fds[1].revents != 0) {
      return;
    }
    if ((fds[0].revents & POLLIN) == 0) {
      continue;
    }
    std::uint8_t buf[64];
    sockaddr_in peer{};
    socklen_t peer_len = sizeof peer;
    const ssize_t got =
        ::recvfrom(fd_, buf, sizeof buf, MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&peer), &peer_len);
    if (got != static_cast<ssize_t>(rdt::kRequestSize)) {
      continue;  // not an RDT request: a real Net F/T ignores it too
    }
    rdt::RequestBytes bytes{};
    std::memcpy(bytes.data(), buf, bytes.size());
    const rdt::Request request = rdt::DecodeRequest(bytes);

    std::vector<rdt::RecordBytes> replies;
    {
      std::lock_guard lock(mutex_);
      requests_.push_back(bytes);
      if (request.header != rdt::kHeader) {
        continue;
      }
      const auto command = static_cast<rdt::Command>(request.command);
      if (command == rdt::Command::kSetSoftwareBias) {
        ++bias_count_;
      } else if ((command == rdt::Command::kStartRealtime || command == rdt::Command::kStartBuffered) &&
                 !silent_) {
        const std::uint32_t n = request.sample_count == 0 ? 1 : request.sample_count;
        for (std::uint32_t i = 0; i < n; ++i) {
          rdt::Record record;
          record.rdt_sequence = i + 1;
          record.ft_sequence = ++ft_sequence_;
          record.status = status_;
          record.counts = counts_;
          replies.push_back(rdt::EncodeRecord(record));
        }
      }
    }
    for (const auto& reply : replies) {
      ::sendto(fd_, reply.data(), reply.size(), 0, reinterpret_cast<const sockaddr*>(&peer), peer_len);
    }
  }
}

}  // namespace tubepick::devices

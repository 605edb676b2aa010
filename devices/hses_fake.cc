#include "devices/hses_fake.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string>

namespace tubepick::devices {
namespace {

std::runtime_error SysError(const char* what) {
  return std::runtime_error(std::string("HsesFake: ") + what + ": " + std::strerror(errno));
}

constexpr std::uint8_t kStatusUndefinedCommand = 0x08;
constexpr std::uint8_t kStatusError = 0x1F;
constexpr std::uint16_t kAddedServoOff = 0x2070;  // "Servo OFF"
constexpr std::uint16_t kAddedBadData = 0xB004;   // "Out of range the data"
constexpr std::uint16_t kAddedUndefinedCommand = 0xA000;

}  // namespace

HsesFake::HsesFake(std::chrono::milliseconds move_duration) : move_duration_(move_duration) {
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

HsesFake::~HsesFake() {
  const char byte = 0;
  [[maybe_unused]] const ssize_t n = ::write(wake_[1], &byte, 1);
  thread_.join();
  ::close(fd_);
  ::close(wake_[0]);
  ::close(wake_[1]);
}

void HsesFake::SetErrorStatus(std::uint8_t status, std::uint16_t added_status) {
  std::lock_guard lock(mutex_);
  error_status_ = status;
  error_added_ = added_status;
}

void HsesFake::SetSilent(bool silent) {
  std::lock_guard lock(mutex_);
  silent_ = silent;
}

void HsesFake::SetPosition(const std::array<std::int32_t, 6>& words) {
  std::lock_guard lock(mutex_);
  position_ = words;
}

std::array<std::int32_t, 6> HsesFake::position() const {
  std::lock_guard lock(mutex_);
  return position_;
}

bool HsesFake::servo_on() const {
  std::lock_guard lock(mutex_);
  return servo_on_;
}

int HsesFake::status_reads() const {
  std::lock_guard lock(mutex_);
  return status_reads_;
}

std::vector<hses::Request> HsesFake::requests() const {
  std::lock_guard lock(mutex_);
  return requests_;
}

std::vector<std::array<std::int32_t, hses::kMoveWords>> HsesFake::moves() const {
  std::lock_guard lock(mutex_);
  return moves_;
}

// Called with mutex_ held.
hses::Answer HsesFake::Handle(const hses::Request& request) {
  hses::Answer answer;
  answer.request_id = request.request_id;
  answer.service = static_cast<std::uint8_t>(request.service | 0x80);
  const auto fail = [&answer](std::uint8_t status, std::uint16_t added) {
    answer.status = status;
    answer.added_status_size = added != 0 ? 1 : 0;
    answer.added_status = added;
    answer.data.clear();
    return answer;
  };
  if (error_status_ != 0) {
    return fail(error_status_, error_added_);
  }
  if (moving_ && std::chrono::steady_clock::now() >= move_end_) {
    moving_ = false;
    position_ = target_;
  }
  const std::vector<std::int32_t> words = hses::DecodeWords(request.data);
  switch (static_cast<hses::Command>(request.command)) {
    case hses::Command::kStatusRead: {
      ++status_reads_;
      const std::int32_t data[2] = {static_cast<std::int32_t>(moving_ ? hses::kStatus1Running : 0u),
                                    static_cast<std::int32_t>(servo_on_ ? hses::kStatus2ServoOn : 0u)};
      answer.data = hses::EncodeWords(data);
      return answer;
    }
    case hses::Command::kPositionRead: {
      if (request.instance != hses::kBasePositionInstance) {
        return fail(kStatusError, kAddedBadData);
      }
      std::array<std::int32_t, hses::kPositionWords> data{};
      data[0] = hses::kCoordinateBase;
      std::copy(position_.begin(), position_.end(), data.begin() + 5);
      answer.data = hses::EncodeWords(data);
      return answer;
    }
    case hses::Command::kHoldServo: {
      if (request.instance != hses::kServoInstance || words.size() != 1 ||
          (words[0] != hses::kOn && words[0] != hses::kOff)) {
        return fail(kStatusError, kAddedBadData);
      }
      servo_on_ = words[0] == hses::kOn;
      return answer;
    }
    case hses::Command::kMoveCartesian: {
      if (words.size() != hses::kMoveWords || request.instance != hses::kStraightAbsolute) {
        return fail(kStatusError, kAddedBadData);
      }
      std::array<std::int32_t, hses::kMoveWords> move{};
      std::copy(words.begin(), words.end(), move.begin());
      moves_.push_back(move);
      if (!servo_on_) {
        return fail(kStatusError, kAddedServoOff);
      }
      std::copy(move.begin() + 5, move.begin() + 11, target_.begin());
      moving_ = true;
      move_end_ = std::chrono::steady_clock::now() + move_duration_;
      return answer;
    }
  }
  return fail(kStatusUndefinedCommand, kAddedUndefinedCommand);
}

void HsesFake::Run() {
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
    std::uint8_t buf[512];
    sockaddr_in peer{};
    socklen_t peer_len = sizeof peer;
    const ssize_t got =
        ::recvfrom(fd_, buf, sizeof buf, MSG_DONTWAIT, reinterpret_cast<sockaddr*>(&peer), &peer_len);
    if (got < 0) {
      continue;
    }
    const auto request =
        hses::DecodeRequest(std::span<const std::uint8_t>(buf, static_cast<std::size_t>(got)));
    if (!request) {
      continue;
    }
    std::vector<std::uint8_t> reply;
    {
      std::lock_guard lock(mutex_);
      requests_.push_back(*request);
      if (silent_) {
        continue;
      }
      reply = hses::EncodeAnswer(Handle(*request));
    }
    ::sendto(fd_, reply.data(), reply.size(), 0, reinterpret_cast<const sockaddr*>(&peer), peer_len);
  }
}

}  // namespace tubepick::devices

#include "devices/virtual/wake_pipe.h"

#include <fcntl.h>
#include <poll.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace tubepick::devices {

WakePipe::WakePipe(const std::string& who) {
  if (::pipe2(fds_, O_CLOEXEC) != 0) throw std::runtime_error(who + ": pipe: " + std::strerror(errno));
}

WakePipe::~WakePipe() {
  ::close(fds_[0]);
  ::close(fds_[1]);
}

void WakePipe::Wake() {
  const char byte = 0;
  [[maybe_unused]] const ssize_t n = ::write(fds_[1], &byte, 1);
}

WakePipe::Event WakePipe::Wait(int fd) const {
  for (;;) {
    pollfd fds[2] = {{fd, POLLIN, 0}, {fds_[0], POLLIN, 0}};
    if (::poll(fds, 2, -1) < 0) {
      if (errno == EINTR) continue;
      return Event::kError;
    }
    if (fds[1].revents != 0) return Event::kWoken;
    return Event::kReadable;
  }
}

}  // namespace tubepick::devices

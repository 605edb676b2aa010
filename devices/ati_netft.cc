#include "devices/ati_netft.h"

#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/types.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace tubepick::devices {
namespace rdt {
namespace {

void PutU16(std::uint8_t* out, std::uint16_t v) {
  out[0] = static_cast<std::uint8_t>(v >> 8);
  out[1] = static_cast<std::uint8_t>(v);
}

void PutU32(std::uint8_t* out, std::uint32_t v) {
  out[0] = static_cast<std::uint8_t>(v >> 24);
  out[1] = static_cast<std::uint8_t>(v >> 16);
  out[2] = static_cast<std::uint8_t>(v >> 8);
  out[3] = static_cast<std::uint8_t>(v);
}

std::uint16_t GetU16(const std::uint8_t* in) {
  return static_cast<std::uint16_t>((std::uint16_t{in[0]} << 8) | in[1]);
}

std::uint32_t GetU32(const std::uint8_t* in) {
  return (std::uint32_t{in[0]} << 24) | (std::uint32_t{in[1]} << 16) | (std::uint32_t{in[2]} << 8) |
         std::uint32_t{in[3]};
}

}  // namespace

RequestBytes EncodeRequest(Command command, std::uint32_t sample_count) {
  RequestBytes out{};
  PutU16(out.data(), kHeader);
  PutU16(out.data() + 2, static_cast<std::uint16_t>(command));
  PutU32(out.data() + 4, sample_count);
  return out;
}

Request DecodeRequest(std::span<const std::uint8_t, kRequestSize> bytes) {
  return Request{GetU16(bytes.data()), GetU16(bytes.data() + 2), GetU32(bytes.data() + 4)};
}

RecordBytes EncodeRecord(const Record& record) {
  RecordBytes out{};
  PutU32(out.data(), record.rdt_sequence);
  PutU32(out.data() + 4, record.ft_sequence);
  PutU32(out.data() + 8, record.status);
  for (std::size_t i = 0; i < record.counts.size(); ++i) {
    PutU32(out.data() + 12 + 4 * i, static_cast<std::uint32_t>(record.counts[i]));
  }
  return out;
}

Record DecodeRecord(std::span<const std::uint8_t, kRecordSize> bytes) {
  Record record;
  record.rdt_sequence = GetU32(bytes.data());
  record.ft_sequence = GetU32(bytes.data() + 4);
  record.status = GetU32(bytes.data() + 8);
  for (std::size_t i = 0; i < record.counts.size(); ++i) {
    // Two's complement: the conversion from uint32 is well defined in C++20.
    record.counts[i] = static_cast<std::int32_t>(GetU32(bytes.data() + 12 + 4 * i));
  }
  return record;
}

}  // namespace rdt

namespace {

using Clock = std::chrono::steady_clock;

std::string Errno(const char* what) { return std::string(what) + ": " + std::strerror(errno); }

std::string Hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", v);
  return buf;
}

}  // namespace

AtiNetFt::AtiNetFt(AtiNetFtParams params) : params_(std::move(params)) {
  if (params_.counts_per_force == 0.0 || params_.counts_per_torque == 0.0) {
    throw std::invalid_argument("AtiNetFt: counts per force/torque must be non-zero");
  }
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  const std::string port = std::to_string(params_.port);
  if (const int rc = ::getaddrinfo(params_.host.c_str(), port.c_str(), &hints, &found); rc != 0) {
    throw DeviceFault("ATI Net F/T: cannot resolve '" + params_.host + "': " + ::gai_strerror(rc));
  }
  fd_ = ::socket(found->ai_family, found->ai_socktype | SOCK_CLOEXEC, found->ai_protocol);
  if (fd_ < 0) {
    ::freeaddrinfo(found);
    throw DeviceFault(Errno("ATI Net F/T: socket"));
  }
  // A connected UDP socket only receives datagrams from the sensor's address.
  const int rc = ::connect(fd_, found->ai_addr, found->ai_addrlen);
  ::freeaddrinfo(found);
  if (rc != 0) {
    const std::string message = Errno("ATI Net F/T: connect");
    ::close(fd_);
    throw DeviceFault(message);
  }
}

AtiNetFt::~AtiNetFt() {
  if (fd_ >= 0) {
    ::close(fd_);
  }
}

void AtiNetFt::DrainStale() {
  // Late records of an earlier, timed-out request must not answer this one.
  std::uint8_t buf[256];
  while (::recv(fd_, buf, sizeof buf, MSG_DONTWAIT) >= 0) {
  }
}

void AtiNetFt::Send(const rdt::RequestBytes& bytes, Timeout timeout) {
  pollfd pfd{fd_, POLLOUT, 0};
  const int ready = ::poll(&pfd, 1, static_cast<int>(timeout.count()));
  if (ready == 0) {
    throw DeviceTimeout("ATI Net F/T: send not possible within " + std::to_string(timeout.count()) + " ms");
  }
  if (ready < 0) {
    throw DeviceFault(Errno("ATI Net F/T: poll"));
  }
  const ssize_t sent = ::send(fd_, bytes.data(), bytes.size(), MSG_DONTWAIT);
  if (sent != static_cast<ssize_t>(bytes.size())) {
    throw DeviceFault(Errno("ATI Net F/T: send"));
  }
}

WrenchReading AtiNetFt::Read(Timeout timeout) {
  const auto deadline = Clock::now() + timeout;
  DrainStale();
  Send(rdt::EncodeRequest(rdt::Command::kStartRealtime, 1), timeout);
  std::uint8_t buf[rdt::kRecordSize + 1];
  for (;;) {
    // Rounded up, so the wait never ends before the deadline.
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now()).count();
    pollfd pfd{fd_, POLLIN, 0};
    const int ready = left > 0 ? ::poll(&pfd, 1, static_cast<int>(left)) : 0;
    if (ready == 0) {
      throw DeviceTimeout("ATI Net F/T " + params_.host + ": no RDT record within " +
                          std::to_string(timeout.count()) + " ms");
    }
    if (ready < 0) {
      if (errno == EINTR) {
        continue;
      }
      throw DeviceFault(Errno("ATI Net F/T: poll"));
    }
    const ssize_t got = ::recv(fd_, buf, sizeof buf, MSG_DONTWAIT);
    if (got < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) {
        continue;
      }
      // E.g. ECONNREFUSED from an ICMP port-unreachable: nothing listens at host:port.
      throw DeviceFault(Errno(("ATI Net F/T " + params_.host + ": recv").c_str()));
    }
    if (got != static_cast<ssize_t>(rdt::kRecordSize)) {
      throw DeviceFault("ATI Net F/T: unexpected reply of " + std::to_string(got) +
                        " bytes (an RDT record has 36)");
    }
    const rdt::Record record =
        rdt::DecodeRecord(std::span<const std::uint8_t, rdt::kRecordSize>(buf, rdt::kRecordSize));
    if (record.status != 0) {
      throw DeviceFault("ATI Net F/T: status word " + Hex32(record.status));
    }
    WrenchReading reading;
    for (int i = 0; i < 3; ++i) {
      reading.force[i] = record.counts[i] / params_.counts_per_force;
      reading.torque[i] = record.counts[3 + i] / params_.counts_per_torque;
    }
    reading.sequence = record.ft_sequence;
    return reading;
  }
}

void AtiNetFt::Bias(Timeout timeout) { Send(rdt::EncodeRequest(rdt::Command::kSetSoftwareBias, 0), timeout); }

}  // namespace tubepick::devices

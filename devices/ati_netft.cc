#include "devices/ati_netft.h"

#include <chrono>
#include <cstdio>
#include <optional>
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

AtiNetFtParams Validated(AtiNetFtParams params) {
  if (params.counts_per_force == 0.0 || params.counts_per_torque == 0.0) {
    throw std::invalid_argument("AtiNetFt: counts per force/torque must be non-zero");
  }
  return params;
}

std::string Hex32(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X", v);
  return buf;
}

}  // namespace

AtiNetFt::AtiNetFt(AtiNetFtParams params)
    : params_(Validated(std::move(params))),
      udp_(params_.host, params_.port, "ATI Net F/T " + params_.host) {}

WrenchReading AtiNetFt::Read(Timeout timeout) {
  const auto deadline = Clock::now() + timeout;
  udp_.DrainStale();
  udp_.Send(rdt::EncodeRequest(rdt::Command::kStartRealtime, 1), deadline);
  std::uint8_t buf[rdt::kRecordSize + 1];
  const std::optional<std::size_t> got = udp_.Receive(buf, deadline);
  if (!got) {
    throw DeviceTimeout("ATI Net F/T " + params_.host + ": no RDT record within " +
                        std::to_string(timeout.count()) + " ms");
  }
  if (*got != rdt::kRecordSize) {
    throw DeviceFault("ATI Net F/T: unexpected reply of " + std::to_string(*got) +
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

void AtiNetFt::Bias(Timeout timeout) {
  udp_.Send(rdt::EncodeRequest(rdt::Command::kSetSoftwareBias, 0), Clock::now() + timeout);
}

}  // namespace tubepick::devices

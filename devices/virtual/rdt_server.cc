#include "devices/virtual/rdt_server.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <utility>

#include <spdlog/spdlog.h>

#include "core/common/errors.h"

namespace tubepick::devices {
namespace {

RdtServerOptions Validated(RdtServerOptions options) {
  const auto check = [](double v, const char* name) {
    if (!std::isfinite(v) || v <= 0.0) {
      throw InvalidArgument(std::string("RdtServer: ") + name + " must be positive and finite, got " +
                            std::to_string(v));
    }
  };
  check(options.counts_per_force, "counts_per_force");
  check(options.counts_per_torque, "counts_per_torque");
  return options;
}

/// Rounded counts, saturated to the int32 range.
std::int32_t Counts(double value, double counts_per_unit) {
  constexpr double kLo = std::numeric_limits<std::int32_t>::min();
  constexpr double kHi = std::numeric_limits<std::int32_t>::max();
  return static_cast<std::int32_t>(std::clamp(std::round(value * counts_per_unit), kLo, kHi));
}

}  // namespace

RdtServer::RdtServer(ForceTorqueSensor& ft, std::mutex& device_lock, RdtServerOptions options)
    : ft_(ft),
      device_lock_(device_lock),
      options_(Validated(std::move(options))),
      udp_("RDT server", options_.host, options_.port,
           [this](std::span<const std::uint8_t> d, const UdpPeer& from) { return Serve(d, from); }) {
  worker_ = std::thread([this] { Run(); });
  spdlog::info("RDT server on {}:{} (UDP)", udp_.host(), udp_.port());
}

RdtServer::~RdtServer() {
  udp_.Stop();
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  worker_.join();
}

std::uint64_t RdtServer::records_sent() const {
  std::lock_guard lock(mutex_);
  return records_sent_;
}

std::vector<UdpServer::Datagram> RdtServer::Serve(std::span<const std::uint8_t> datagram,
                                                  const UdpPeer& from) {
  if (datagram.size() != rdt::kRequestSize) {
    spdlog::debug("RDT server: ignored a datagram of {} bytes from {}", datagram.size(), from.ToString());
    return {};  // not an RDT request: a Net F/T ignores it too
  }
  const rdt::Request request = rdt::DecodeRequest(
      std::span<const std::uint8_t, rdt::kRequestSize>(datagram.data(), rdt::kRequestSize));
  if (request.header != rdt::kHeader) {
    spdlog::debug("RDT server: ignored a request with header 0x{:04X} from {}", request.header,
                  from.ToString());
    return {};
  }
  {
    std::lock_guard lock(mutex_);
    switch (static_cast<rdt::Command>(request.command)) {
      case rdt::Command::kStartRealtime:
        stream_ = Stream{++streams_, from, std::max<std::uint32_t>(request.sample_count, 1), 1};
        break;
      case rdt::Command::kStopStreaming:
        stream_.reset();
        break;
      case rdt::Command::kSetSoftwareBias:
        ++biases_pending_;
        break;
      case rdt::Command::kResetThresholdLatch:
        return {};  // no thresholds are emulated
      default:
        spdlog::warn("RDT server: command 0x{:04X} from {} is not emulated; ignored", request.command,
                     from.ToString());
        return {};
    }
  }
  wake_.notify_all();
  return {};  // records and bias run on the worker
}

std::optional<rdt::Record> RdtServer::Sample() {
  rdt::Record record;
  std::lock_guard device(device_lock_);
  try {
    const WrenchReading reading = ft_.Read(options_.call_timeout);
    if (!reading.force.allFinite() || !reading.torque.allFinite()) {
      throw DeviceFault("non-finite reading");
    }
    for (int i = 0; i < 3; ++i) {
      record.counts[i] = Counts(reading.force[i], options_.counts_per_force);
      record.counts[3 + i] = Counts(reading.torque[i], options_.counts_per_torque);
    }
    record.ft_sequence = static_cast<std::uint32_t>(reading.sequence);
  } catch (const DeviceTimeout& e) {
    spdlog::warn("RDT server: the sensor did not answer; no record: {}", e.what());
    return std::nullopt;
  } catch (const std::exception& e) {
    spdlog::error("RDT server: sensor fault; record with status 0x{:08X}: {}", kStatusError, e.what());
    record.status = kStatusError;
  }
  return record;
}

void RdtServer::Run() {
  for (;;) {
    bool bias = false;
    UdpPeer peer;
    std::uint64_t stream = 0;
    std::uint32_t rdt_sequence = 0;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || biases_pending_ > 0 || stream_.has_value(); });
      if (stop_) return;
      if (biases_pending_ > 0) {
        --biases_pending_;
        bias = true;
      } else {
        peer = stream_->peer;
        stream = stream_->id;
        rdt_sequence = stream_->next_rdt_sequence++;
        if (--stream_->remaining == 0) stream_.reset();
      }
    }
    if (bias) {
      std::lock_guard device(device_lock_);
      try {
        ft_.Bias(options_.call_timeout);
        spdlog::info("RDT server: software bias");
      } catch (const std::exception& e) {
        spdlog::error("RDT server: bias failed: {}", e.what());
      }
      continue;
    }
    std::optional<rdt::Record> record = Sample();
    std::lock_guard lock(mutex_);
    if (!record) {
      // A silent sensor ends the stream (unless a newer request replaced it meanwhile).
      if (stream_ && stream_->id == stream) stream_.reset();
      continue;
    }
    ++ft_sequence_;
    if (record->ft_sequence == 0) record->ft_sequence = ft_sequence_;
    record->rdt_sequence = rdt_sequence;
    ++records_sent_;
    const rdt::RecordBytes bytes = rdt::EncodeRecord(*record);
    udp_.SendTo(peer, bytes);
  }
}

}  // namespace tubepick::devices

#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "devices/ati_netft.h"
#include "devices/force_torque_sensor.h"
#include "devices/virtual/udp_server.h"

namespace tubepick::devices {

struct RdtServerOptions {
  /// Address to bind: an IPv4 address or a name that resolves to one.
  std::string host = "127.0.0.1";
  /// UDP port; 0 = an ephemeral port (RdtServer::port() tells which). A Net F/T listens on 49152.
  std::uint16_t port = 0;
  /// Counts per N and per N·m in the records: the driver's AtiNetFtParams must have the same.
  double counts_per_force = 1'000'000.0;
  double counts_per_torque = 1'000'000.0;
  /// Timeout of one ForceTorqueSensor call (Read, Bias).
  Timeout call_timeout{1000};
};

/// Serves a ForceTorqueSensor through the ATI Net F/T Raw Data Transfer protocol (UDP), as the
/// AtiNetFt driver speaks it.
///
/// - Start real-time streaming (0x0002) with sample_count N sends N records to the requester (N = 0,
///   "stream until stopped", sends one: the driver never streams), one ForceTorqueSensor::Read each:
///   the counts (rounded, saturated to int32), rdt_sequence 1, 2, … within the stream, ft_sequence =
///   the reading's sequence when it has one (else the server's own count). A DeviceFault from the
///   sensor sends a record with status kStatusError and zero counts; a DeviceTimeout sends nothing
///   and ends the stream (the driver times out, as with a silent box). A new start request
///   replaces a running stream; stop (0x0000) ends it.
/// - Set software bias (0x0042) calls ForceTorqueSensor::Bias (not acknowledged, like the box).
/// - Buffered streaming (0x0003) is not emulated; it and other commands are ignored (logged).
///
/// Every sensor call holds `device_lock`. One receive thread and one worker that calls the sensor
/// and sends the records; the destructor stops both, waiting for a running sensor call.
class RdtServer {
 public:
  /// The status word of a record for a reading the sensor failed (its top bit: an error).
  static constexpr std::uint32_t kStatusError = 0x80000000u;

  /// @throws InvalidArgument naming the option for non-positive or non-finite counts, or when
  /// options.host does not resolve; std::runtime_error when the socket cannot be bound.
  RdtServer(ForceTorqueSensor& ft, std::mutex& device_lock, RdtServerOptions options = {});
  ~RdtServer();
  RdtServer(const RdtServer&) = delete;
  RdtServer& operator=(const RdtServer&) = delete;

  const std::string& host() const { return udp_.host(); }
  std::uint16_t port() const { return udp_.port(); }

  /// Records sent so far (all streams).
  std::uint64_t records_sent() const;

 private:
  struct Stream {
    std::uint64_t id = 0;
    UdpPeer peer;
    std::uint32_t remaining = 0;
    std::uint32_t next_rdt_sequence = 1;
  };

  std::vector<UdpServer::Datagram> Serve(std::span<const std::uint8_t> datagram, const UdpPeer& from);
  void Run();
  /// One record from one sensor read; nullopt when the sensor did not answer.
  std::optional<rdt::Record> Sample();

  ForceTorqueSensor& ft_;
  std::mutex& device_lock_;
  RdtServerOptions options_;

  mutable std::mutex mutex_;  // the state below; never held while waiting for device_lock_
  std::condition_variable wake_;
  std::optional<Stream> stream_;
  std::uint64_t streams_ = 0;
  int biases_pending_ = 0;
  std::uint32_t ft_sequence_ = 0;
  std::uint64_t records_sent_ = 0;
  bool stop_ = false;

  std::thread worker_;
  UdpServer udp_;  // last: its thread starts once the state above exists
};

}  // namespace tubepick::devices

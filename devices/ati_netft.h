#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

#include "devices/force_torque_sensor.h"
#include "devices/udp_client.h"

namespace tubepick::devices {

/// The ATI Net F/T Raw Data Transfer (RDT) protocol over UDP: 8-byte requests, 36-byte
/// records, all fields big-endian (ATI Net F/T manual, "Raw Data Transfer").
namespace rdt {

inline constexpr std::uint16_t kHeader = 0x1234;
inline constexpr std::uint16_t kDefaultPort = 49152;
inline constexpr std::size_t kRequestSize = 8;
inline constexpr std::size_t kRecordSize = 36;

/// RDT request command codes.
enum class Command : std::uint16_t {
  kStopStreaming = 0x0000,
  kStartRealtime = 0x0002,  // high-speed real-time streaming
  kStartBuffered = 0x0003,  // high-speed buffered streaming
  kResetThresholdLatch = 0x0041,
  kSetSoftwareBias = 0x0042,
};

using RequestBytes = std::array<std::uint8_t, kRequestSize>;
using RecordBytes = std::array<std::uint8_t, kRecordSize>;

struct Request {
  std::uint16_t header = kHeader;
  std::uint16_t command = 0;
  /// Number of records to send (0 = stream until stopped).
  std::uint32_t sample_count = 0;
};

/// One RDT record: sequence numbers, status word and the six raw gauge counts
/// (Fx, Fy, Fz, Tx, Ty, Tz).
struct Record {
  std::uint32_t rdt_sequence = 0;
  std::uint32_t ft_sequence = 0;
  std::uint32_t status = 0;
  std::array<std::int32_t, 6> counts{};
};

RequestBytes EncodeRequest(Command command, std::uint32_t sample_count);
Request DecodeRequest(std::span<const std::uint8_t, kRequestSize> bytes);
RecordBytes EncodeRecord(const Record& record);
Record DecodeRecord(std::span<const std::uint8_t, kRecordSize> bytes);

}  // namespace rdt

/// Connection and scaling of one Net F/T box.
struct AtiNetFtParams {
  /// Net F/T address (numeric IPv4 or a resolvable name); the factory default is 192.168.1.1.
  std::string host = "192.168.1.1";
  std::uint16_t port = rdt::kDefaultPort;
  /// Counts per N and per N·m. The Net F/T's factory configuration outputs N and N·m with
  /// 1000000 counts per unit for both; read "cfgcpf"/"cfgcpt" on the box's netftapi2.xml
  /// (or its Configuration web page) if the active configuration differs.
  double counts_per_force = 1'000'000.0;
  double counts_per_torque = 1'000'000.0;
};

/// ATI Net F/T over RDT. Each Read() sends a one-record real-time request and waits for the
/// record; no background streaming. Not thread-safe: one caller at a time.
class AtiNetFt final : public ForceTorqueSensor {
 public:
  /// Opens the UDP socket towards params.host:params.port. @throws DeviceFault when the host
  /// does not resolve or the socket cannot be created; std::invalid_argument on zero counts.
  explicit AtiNetFt(AtiNetFtParams params);

  /// @throws DeviceTimeout when no record arrives in time; DeviceFault on a non-zero status
  /// word (hex in the message), a malformed reply or a socket error.
  WrenchReading Read(Timeout timeout) override;
  /// Sends the set-software-bias command. The Net F/T does not acknowledge it, so the timeout
  /// only bounds the send. @throws DeviceTimeout, DeviceFault on a socket error.
  void Bias(Timeout timeout) override;

  const AtiNetFtParams& params() const { return params_; }

 private:
  AtiNetFtParams params_;
  UdpClient udp_;
};

}  // namespace tubepick::devices

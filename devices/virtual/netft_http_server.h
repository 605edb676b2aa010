#pragma once

#include <cstdint>
#include <string>
#include <thread>

#include "devices/netft_calibration.h"
#include "devices/virtual/wake_pipe.h"

namespace tubepick::devices {

/// The part of a Net F/T's web server the driver reads: GET /netftapi2.xml answers the active
/// configuration's counts per unit and units (cfgcpf, cfgcpt, scfgfu, scfgtu); anything else 404.
/// HTTP/1.0, one request per connection, on its own thread; binds host:port (0 = ephemeral).
class NetFtHttpServer {
 public:
  /// @throws std::runtime_error when the socket cannot be bound.
  NetFtHttpServer(const std::string& host, std::uint16_t port, NetFtCalibration calibration);
  ~NetFtHttpServer();
  NetFtHttpServer(const NetFtHttpServer&) = delete;
  NetFtHttpServer& operator=(const NetFtHttpServer&) = delete;

  std::uint16_t port() const { return port_; }

 private:
  void Run();

  NetFtCalibration calibration_;
  int fd_ = -1;
  WakePipe wake_{"Net F/T web server"};
  std::uint16_t port_ = 0;
  std::thread thread_;
};

}  // namespace tubepick::devices

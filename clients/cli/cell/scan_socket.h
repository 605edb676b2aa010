#pragma once

#include <functional>
#include <string>
#include <thread>

#include "devices/virtual/wake_pipe.h"

namespace tubepick::cli {

/// The virtual cell's scanner bridge: a UNIX stream socket on which each connection asks for one
/// scan written to a file. The request is one line, the path to write; the answer one line, "ok"
/// or "error: <why>". `tubepick virtual-cell scan --socket S --out FILE` is the client, run by the
/// exec scanner driver like any vendor capture tool.
class ScanSocketServer {
 public:
  /// `serve(path)` writes the scan to `path` and returns "" or the error text; called on the
  /// server's thread, one request at a time.
  /// @throws std::runtime_error when the socket cannot be made (naming the path).
  ScanSocketServer(std::string socket_path, std::function<std::string(const std::string& out_path)> serve);
  ~ScanSocketServer();
  ScanSocketServer(const ScanSocketServer&) = delete;
  ScanSocketServer& operator=(const ScanSocketServer&) = delete;

  const std::string& path() const { return path_; }

 private:
  void Run();

  std::string path_;
  std::function<std::string(const std::string&)> serve_;
  int fd_ = -1;
  devices::WakePipe wake_{"scan socket"};
  std::thread thread_;
};

/// The client: asks the server at `socket_path` for a scan into `out_path`; "" on success, else why.
std::string RequestScan(const std::string& socket_path, const std::string& out_path);

}  // namespace tubepick::cli

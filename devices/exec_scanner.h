#pragma once

#include <cstdint>
#include <string>

#include "core/common/cell_config.h"
#include "devices/scanner.h"

namespace tubepick::devices {

struct ExecScannerParams {
  /// Run with /bin/sh -c for every scan; each `{out}` is replaced by the (shell-quoted) path of the
  /// file the command must write, one PLY or PCD cloud in the sensor's optical frame.
  std::string command;
  /// Extension of that file: "ply" or "pcd" (the reader goes by content, the vendor tool may not).
  std::string format = "ply";
  /// X_BinSensor and unit reported with every capture.
  SensorConfig sensor;
  /// Directory for the scan files; empty = $TMPDIR or /tmp. A scan's file is removed once read.
  std::string work_dir;
};

/// A Scanner that runs a vendor bridge command per scan (Zivid's or Photoneo's SDK samples, a
/// ROS bag extractor, a script that triggers the sensor): the command writes one cloud file and
/// exits 0. The command runs in its own process group; the scan's timeout kills the whole group.
class ExecScanner final : public Scanner {
 public:
  /// @throws InvalidArgument when the command has no {out} or the format is not ply/pcd.
  explicit ExecScanner(ExecScannerParams params);

  /// @throws DeviceTimeout when the command runs past `timeout` (it is killed), DeviceFault when it
  ///         exits non-zero (with its exit status and the last line of its stderr), writes no file
  ///         or a file that is not a cloud.
  Capture Scan(Timeout timeout) override;

  /// The command line of the next scan with {out} replaced (for logs and `devices check`).
  std::string CommandFor(const std::string& out_path) const;

 private:
  ExecScannerParams params_;
  std::uint64_t scans_ = 0;
};

}  // namespace tubepick::devices

#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/common/cell_config.h"
#include "devices/scanner.h"

namespace tubepick::devices {

struct FileReplayScannerParams {
  /// Directory holding the recorded clouds (*.ply, *.pcd; not searched recursively).
  std::string directory;
  /// X_BinSensor and unit reported with every capture.
  SensorConfig sensor;
  /// After the last file, restart at the first one instead of failing.
  bool loop = false;
};

/// A Scanner that replays recorded cloud files (PLY or PCD) in natural name order (scan2 before
/// scan10), one per Scan(). For offline runs and tests without a sensor.
class FileReplayScanner final : public Scanner {
 public:
  /// Lists the directory's *.ply and *.pcd files.
  /// @throws InvalidArgument naming the directory when it is missing, not a directory, or holds
  ///         no cloud file.
  explicit FileReplayScanner(FileReplayScannerParams params);

  /// Reads the next file. `timeout` is ignored (reading a file does not wait on a device).
  /// @throws DeviceFault after the last file (unless looping), or when the file cannot be read
  ///         (naming it and why; the following call moves on to the next file).
  Capture Scan(Timeout timeout) override;

  /// Files not yet replayed in the current pass (0 after the last one, even when looping).
  std::size_t remaining() const;
  /// Path of the file the last Scan() read (or tried to); empty before the first Scan().
  const std::string& current_file() const { return current_file_; }
  /// All files, in replay order.
  const std::vector<std::string>& files() const { return files_; }

 private:
  FileReplayScannerParams params_;
  std::vector<std::string> files_;
  std::size_t next_ = 0;
  std::size_t replayed_ = 0;
  std::string current_file_;
};

/// Natural ("human") order: digit runs compare by value, so "scan2" < "scan10".
bool NaturalLess(const std::string& a, const std::string& b);

}  // namespace tubepick::devices

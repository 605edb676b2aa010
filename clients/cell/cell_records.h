#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "devices/force_torque_sensor.h"
#include "devices/gripper.h"

namespace tubepick::cell {

/// Where the controller writes its structured records: one JSON object per picking attempt
/// ("type": "attempt"), per safe stop ("type": "safe_stop") and per run ("type": "end"). The fields
/// are listed in clients/cell/cell_controller.h.
class RecordSink {
 public:
  virtual ~RecordSink() = default;
  virtual void Write(const nlohmann::json& record) = 0;
};

/// JSON lines: one compact object per line, handed to the kernel as one write per record (a crash of
/// this process loses nothing written).
///
/// Writing never throws: the records are the cell's trace, and a full disk must not interrupt a
/// pick under way (an exception in the controller's record sink ends in a safe stop). A record that
/// cannot be written (disk full, quota, I/O error) is counted in lost(), the file is cut back to
/// its last whole line, and an error naming the file, the reason and the record's type is logged
/// for the first record of each run of failures; the next record tries again, and the first that
/// gets through logs how many were lost before it. The caller reports lost() when the run ends.
class JsonLinesFileSink final : public RecordSink {
 public:
  /// @param append keep what the file holds. @throws InvalidArgument when it cannot be opened.
  explicit JsonLinesFileSink(const std::string& path, bool append = false);
  ~JsonLinesFileSink() override;
  JsonLinesFileSink(const JsonLinesFileSink&) = delete;
  JsonLinesFileSink& operator=(const JsonLinesFileSink&) = delete;

  void Write(const nlohmann::json& record) override;

  const std::string& path() const { return path_; }
  /// Records written whole.
  std::uint64_t written() const { return written_; }
  /// Records that could not be written.
  std::uint64_t lost() const { return lost_; }
  /// Why the last lost record was lost ("No space left on device"); empty when none was.
  const std::string& last_error() const { return last_error_; }

 private:
  std::string path_;
  int fd_ = -1;
  // File size after the last whole record: a partial write is cut back to it.
  std::int64_t good_size_ = 0;
  std::uint64_t written_ = 0;
  std::uint64_t lost_ = 0;
  // Records lost since the last one written (the current run of failures).
  std::uint64_t failing_ = 0;
  std::string last_error_;
};

/// One line on a records file for the end of a run: "records: PATH" when every record was
/// written, else how many were lost and why.
std::string DescribeRecordsFile(const JsonLinesFileSink& sink);

/// Keeps the records in memory (statistics, tests).
class MemoryRecordSink final : public RecordSink {
 public:
  void Write(const nlohmann::json& record) override { records_.push_back(record); }
  const std::vector<nlohmann::json>& records() const { return records_; }

 private:
  std::vector<nlohmann::json> records_;
};

/// Writes to several sinks.
class TeeRecordSink final : public RecordSink {
 public:
  TeeRecordSink(RecordSink* a, RecordSink* b) : a_(a), b_(b) {}
  void Write(const nlohmann::json& record) override {
    if (a_) a_->Write(record);
    if (b_) b_->Write(record);
  }

 private:
  RecordSink* a_;
  RecordSink* b_;
};

/// Reads a JSON-lines file back (blank lines skipped). @throws InvalidArgument naming the line.
std::vector<nlohmann::json> ReadJsonLines(const std::string& path);

/// [x, y, z].
nlohmann::json VectorJson(const Eigen::Vector3d& v);
/// {"position": [x, y, z], "orientation_xyzw": [x, y, z, w]} of X_BinTcp (or any pose).
nlohmann::json PoseJson(const Eigen::Isometry3d& X);
/// {"force": [x, y, z], "torque": [x, y, z]}.
nlohmann::json WrenchJson(const devices::WrenchReading& reading);
/// {"activated", "object": "stopped_closing"|..., "opening", "fault", "fault_text"}.
nlohmann::json GripperJson(const devices::GripperStatus& status);
/// "moving", "stopped_opening", "stopped_closing", "at_position".
std::string GripperObjectName(devices::GripperObject object);

}  // namespace tubepick::cell

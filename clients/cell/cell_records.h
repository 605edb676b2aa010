#pragma once

#include <fstream>
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

/// JSON lines: one compact object per line, flushed after each record (a crash loses nothing).
class JsonLinesFileSink final : public RecordSink {
 public:
  /// @param append keep what the file holds. @throws InvalidArgument when it cannot be opened.
  explicit JsonLinesFileSink(const std::string& path, bool append = false);
  void Write(const nlohmann::json& record) override;

 private:
  std::string path_;
  std::ofstream out_;
};

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

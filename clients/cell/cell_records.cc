#include "clients/cell/cell_records.h"

#include <fmt/core.h>

#include "core/common/errors.h"

namespace tubepick::cell {

JsonLinesFileSink::JsonLinesFileSink(const std::string& path, bool append)
    : path_(path), out_(path, append ? std::ios::app : std::ios::trunc) {
  if (!out_) throw InvalidArgument(fmt::format("records file {}: cannot open for writing", path));
}

void JsonLinesFileSink::Write(const nlohmann::json& record) {
  out_ << record.dump() << '\n';
  out_.flush();
}

std::vector<nlohmann::json> ReadJsonLines(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InvalidArgument(fmt::format("records file {}: cannot open", path));
  std::vector<nlohmann::json> records;
  std::string line;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    try {
      records.push_back(nlohmann::json::parse(line));
    } catch (const nlohmann::json::exception& e) {
      throw InvalidArgument(fmt::format("records file {} line {}: {}", path, number, e.what()));
    }
  }
  return records;
}

nlohmann::json VectorJson(const Eigen::Vector3d& v) { return nlohmann::json::array({v.x(), v.y(), v.z()}); }

nlohmann::json PoseJson(const Eigen::Isometry3d& X) {
  const Eigen::Quaterniond q(X.rotation());
  return {{"position", VectorJson(X.translation())}, {"orientation_xyzw", {q.x(), q.y(), q.z(), q.w()}}};
}

nlohmann::json WrenchJson(const devices::WrenchReading& reading) {
  return {{"force", VectorJson(reading.force)}, {"torque", VectorJson(reading.torque)}};
}

std::string GripperObjectName(devices::GripperObject object) {
  switch (object) {
    case devices::GripperObject::kMoving:
      return "moving";
    case devices::GripperObject::kStoppedOpening:
      return "stopped_opening";
    case devices::GripperObject::kStoppedClosing:
      return "stopped_closing";
    case devices::GripperObject::kAtPosition:
      return "at_position";
  }
  return "unknown";
}

nlohmann::json GripperJson(const devices::GripperStatus& status) {
  return {{"activated", status.activated},
          {"object", GripperObjectName(status.object)},
          {"opening", status.opening},
          {"fault", status.fault},
          {"fault_text", status.fault_text}};
}

}  // namespace tubepick::cell

#include "clients/cell/cell_records.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include "core/common/errors.h"

namespace tubepick::cell {

JsonLinesFileSink::JsonLinesFileSink(const std::string& path, bool append)
    : path_(path),
      fd_(::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | (append ? O_APPEND : O_TRUNC), 0644)) {
  if (fd_ < 0)
    throw InvalidArgument(
        fmt::format("records file {}: cannot open for writing ({})", path, std::strerror(errno)));
  struct stat st {};
  if (::fstat(fd_, &st) == 0 && S_ISREG(st.st_mode)) good_size_ = st.st_size;
}

JsonLinesFileSink::~JsonLinesFileSink() {
  if (fd_ >= 0) ::close(fd_);
}

namespace {

// Writes all of `line`; the errno of the first failure, 0 when all was written.
int WriteAll(int fd, const std::string& line) {
  std::size_t done = 0;
  while (done < line.size()) {
    const ssize_t n = ::write(fd, line.data() + done, line.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return n < 0 ? errno : ENOSPC;
    done += static_cast<std::size_t>(n);
  }
  return 0;
}

}  // namespace

void JsonLinesFileSink::Write(const nlohmann::json& record) {
  const std::string line = record.dump() + '\n';
  const int error = WriteAll(fd_, line);
  // The record's type, for the logs only.
  auto type = [&record] {
    const auto it = record.find("type");
    return it != record.end() && it->is_string() ? it->get<std::string>() : std::string("record");
  };
  if (error == 0) {
    good_size_ += static_cast<std::int64_t>(line.size());
    ++written_;
    if (failing_ > 0)
      spdlog::warn("records file {}: writing again ('{}' record); {} record(s) before it were lost ({})",
                   path_, type(), failing_, last_error_);
    failing_ = 0;
    return;
  }
  // Cut a partial line back off, so that the file stays whole lines (a regular file only: a pipe
  // or a device cannot be cut, and keeps what got through).
  struct stat st {};
  if (::fstat(fd_, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > good_size_) {
    if (::ftruncate(fd_, good_size_) != 0)
      spdlog::error("records file {}: could not cut a partial line back off ({})", path_,
                    std::strerror(errno));
    ::lseek(fd_, good_size_, SEEK_SET);
  }
  last_error_ = std::strerror(error);
  ++lost_;
  if (failing_++ == 0)
    spdlog::error(
        "records file {}: '{}' record not written ({}); the cell goes on, and every record lost until "
        "writing works again is counted",
        path_, type(), last_error_);
}

std::string DescribeRecordsFile(const JsonLinesFileSink& sink) {
  if (sink.lost() == 0) return fmt::format("records: {}", sink.path());
  return fmt::format("records: {}: {} of {} records could not be written ({}); the file holds the other {}",
                     sink.path(), sink.lost(), sink.lost() + sink.written(), sink.last_error(),
                     sink.written());
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

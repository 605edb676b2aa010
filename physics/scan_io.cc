#include "physics/scan_io.h"

#include <charconv>
#include <fstream>

#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"

namespace tubepick::physics {

void WriteLabels(const std::string& path, const std::vector<std::int32_t>& labels) {
  std::string text;
  text.reserve(labels.size() * 3);
  char buffer[16];
  for (std::int32_t label : labels) {
    const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), label);
    text.append(buffer, end);
    text += '\n';
  }
  std::ofstream file(path, std::ios::binary);
  if (!file) throw InvalidArgument("cannot write labels file '" + path + "'");
  file << text;
  if (!file.flush()) throw InvalidArgument("error while writing labels file '" + path + "'");
}

std::vector<std::int32_t> ReadLabels(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw InvalidArgument("cannot open labels file '" + path + "'");
  std::vector<std::int32_t> labels;
  std::string line;
  int number = 0;
  while (std::getline(file, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    const auto last = line.find_last_not_of(" \t\r");
    std::int32_t label = 0;
    const char* begin = line.data() + first;
    const char* stop = line.data() + last + 1;
    const auto [end, ec] = std::from_chars(begin, stop, label);
    if (ec != std::errc() || end != stop) {
      throw InvalidArgument(path + ":" + std::to_string(number) + ": expected one integer label, got '" +
                            line + "'");
    }
    labels.push_back(label);
  }
  return labels;
}

void WriteScan(const std::string& ply_path, const std::string& labels_path, const ScanResult& scan) {
  if (scan.labels.size() != scan.points_Sensor.size()) {
    throw InvalidArgument("WriteScan: " + std::to_string(scan.labels.size()) + " labels for " +
                          std::to_string(scan.points_Sensor.size()) + " points");
  }
  std::vector<Rgb> colours;
  colours.reserve(scan.labels.size());
  for (std::int32_t label : scan.labels) colours.push_back(LabelColour(label));
  WritePly(ply_path, scan.points_Sensor, &colours);
  WriteLabels(labels_path, scan.labels);
}

}  // namespace tubepick::physics

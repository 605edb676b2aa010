#include "devices/file_replay_scanner.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"

namespace tubepick::devices {
namespace {

namespace fs = std::filesystem;

bool IsDigit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

char Lower(char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); }

bool IsCloudFile(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), Lower);
  return ext == ".ply" || ext == ".pcd";
}

}  // namespace

bool NaturalLess(const std::string& a, const std::string& b) {
  std::size_t i = 0;
  std::size_t j = 0;
  while (i < a.size() && j < b.size()) {
    if (IsDigit(a[i]) && IsDigit(b[j])) {
      std::size_t ie = i;
      std::size_t je = j;
      while (ie < a.size() && IsDigit(a[ie])) ++ie;
      while (je < b.size() && IsDigit(b[je])) ++je;
      // Compare by value without overflow: skip leading zeros, then length, then digits.
      std::size_t ia = i;
      std::size_t jb = j;
      while (ia + 1 < ie && a[ia] == '0') ++ia;
      while (jb + 1 < je && b[jb] == '0') ++jb;
      const std::size_t la = ie - ia;
      const std::size_t lb = je - jb;
      if (la != lb) return la < lb;
      const int cmp = a.compare(ia, la, b, jb, lb);
      if (cmp != 0) return cmp < 0;
      // Same value: fewer leading zeros first ("2" before "02").
      if (ie - i != je - j) return ie - i < je - j;
      i = ie;
      j = je;
    } else {
      if (a[i] != b[j]) return a[i] < b[j];
      ++i;
      ++j;
    }
  }
  return a.size() - i < b.size() - j;
}

FileReplayScanner::FileReplayScanner(FileReplayScannerParams params) : params_(std::move(params)) {
  const fs::path dir(params_.directory);
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw InvalidArgument("file replay scanner: directory '" + params_.directory +
                          "' does not exist or is not a directory");
  }
  std::vector<std::string> names;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code file_ec;
    if (it->is_regular_file(file_ec) && IsCloudFile(it->path()))
      names.push_back(it->path().filename().string());
  }
  if (ec) {
    throw InvalidArgument("file replay scanner: cannot list directory '" + params_.directory +
                          "': " + ec.message());
  }
  if (names.empty()) {
    throw InvalidArgument("file replay scanner: directory '" + params_.directory +
                          "' holds no *.ply or *.pcd file");
  }
  std::sort(names.begin(), names.end(), NaturalLess);
  files_.reserve(names.size());
  for (const std::string& name : names) files_.push_back((dir / name).string());
}

std::size_t FileReplayScanner::remaining() const { return files_.size() - next_; }

Capture FileReplayScanner::Scan(Timeout /*timeout*/) {
  if (next_ >= files_.size()) {
    if (!params_.loop) {
      throw DeviceFault("no more scans in " + params_.directory + " (" + std::to_string(replayed_) +
                        " replayed)");
    }
    next_ = 0;
  }
  current_file_ = files_[next_++];
  ++replayed_;
  CloudFile cloud;
  try {
    cloud = ReadCloudFile(current_file_);
  } catch (const std::exception& e) {
    throw DeviceFault("file replay scanner: cannot read " + current_file_ + ": " + e.what());
  }
  return CaptureOf(std::move(cloud.points), params_.sensor);
}

}  // namespace tubepick::devices

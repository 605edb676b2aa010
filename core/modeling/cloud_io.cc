#include "core/modeling/cloud_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <type_traits>

#include "core/common/errors.h"
#include "core/modeling/cloud_io_internal.h"

namespace tubepick {
namespace internal {

void ThrowCloudFileError(const std::string& path, const std::string& reason) {
  throw InvalidArgument("cloud file '" + path + "': " + reason);
}

bool NextLine(std::string_view bytes, std::size_t* pos, std::string_view* line) {
  if (*pos >= bytes.size()) return false;
  const std::size_t end = bytes.find('\n', *pos);
  const std::size_t stop = end == std::string_view::npos ? bytes.size() : end;
  *line = bytes.substr(*pos, stop - *pos);
  if (!line->empty() && line->back() == '\r') line->remove_suffix(1);
  *pos = end == std::string_view::npos ? bytes.size() : end + 1;
  return true;
}

static bool IsSpace(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f';
}

std::vector<std::string_view> SplitWords(std::string_view line) {
  std::vector<std::string_view> words;
  TokenReader reader(line);
  std::string_view word;
  while (reader.Next(&word)) words.push_back(word);
  return words;
}

bool TokenReader::Next(std::string_view* token) {
  while (pos_ < text_.size() && IsSpace(text_[pos_])) ++pos_;
  if (pos_ >= text_.size()) return false;
  const std::size_t start = pos_;
  while (pos_ < text_.size() && !IsSpace(text_[pos_])) ++pos_;
  *token = text_.substr(start, pos_ - start);
  return true;
}

template <typename T>
static bool ParseWhole(std::string_view token, T* value) {
  if (!token.empty() && token.front() == '+') token.remove_prefix(1);
  const char* first = token.data();
  const char* last = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(first, last, *value);
  // Out-of-range floats (e.g. 1e999) are read as ±inf: the caller counts non-finite points.
  if (ec == std::errc::result_out_of_range && ptr == last) {
    if constexpr (std::is_floating_point_v<T>) {
      *value =
          token.front() == '-' ? -std::numeric_limits<T>::infinity() : std::numeric_limits<T>::infinity();
      return true;
    }
  }
  return ec == std::errc() && ptr == last && first != last;
}

bool ParseNumber(std::string_view token, float* value) { return ParseWhole(token, value); }
bool ParseNumber(std::string_view token, double* value) { return ParseWhole(token, value); }
bool ParseNumber(std::string_view token, std::uint64_t* value) { return ParseWhole(token, value); }

void AppendNumber(std::string* out, float value) {
  if (std::isnan(value)) {
    out->append("nan");
    return;
  }
  char buffer[32];
  const auto [ptr, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  out->append(buffer, ec == std::errc() ? ptr : buffer);
}

void AppendAsciiPoints(std::string* out, const Points& points) {
  out->reserve(out->size() + points.size() * 30);
  for (const Eigen::Vector3f& p : points) {
    AppendNumber(out, p.x());
    *out += ' ';
    AppendNumber(out, p.y());
    *out += ' ';
    AppendNumber(out, p.z());
    *out += '\n';
  }
}

void StoreFloatLE(char* dst, float value) {
  const auto bits = std::bit_cast<std::uint32_t>(value);
  for (int i = 0; i < 4; ++i) dst[i] = static_cast<char>((bits >> (8 * i)) & 0xffu);
}

void WriteFileBytes(const std::string& path, std::string_view bytes) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) {
    throw InvalidArgument("cannot write cloud file '" + path + "': " + std::strerror(errno));
  }
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string reason = std::strerror(errno);
      ::close(fd);
      throw InvalidArgument("cannot write cloud file '" + path + "': " + reason);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::close(fd) != 0) {
    throw InvalidArgument("cannot write cloud file '" + path + "': " + std::strerror(errno));
  }
}

}  // namespace internal

namespace {

/// The whole file in memory (one read; clouds are tens of MB at most).
struct FileBytes {
  std::unique_ptr<char[]> data;
  std::size_t size = 0;
  std::string_view view() const { return {data.get(), size}; }
};

FileBytes ReadWholeFile(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) internal::ThrowCloudFileError(path, std::string("cannot open: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    ::close(fd);
    internal::ThrowCloudFileError(path, "not a regular file");
  }
  FileBytes file;
  file.size = static_cast<std::size_t>(st.st_size);
  file.data = std::make_unique_for_overwrite<char[]>(std::max<std::size_t>(file.size, 1));
  std::size_t done = 0;
  while (done < file.size) {
    const ssize_t n = ::read(fd, file.data.get() + done, file.size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string reason = n < 0 ? std::strerror(errno) : "file shrank while reading";
      ::close(fd);
      internal::ThrowCloudFileError(path, "read failed: " + reason);
    }
    done += static_cast<std::size_t>(n);
  }
  ::close(fd);
  return file;
}

}  // namespace

CloudFile ReadCloudFile(const std::string& path) {
  const FileBytes file = ReadWholeFile(path);
  const std::string_view bytes = file.view();
  if (bytes.empty()) internal::ThrowCloudFileError(path, "the file is empty");
  std::size_t pos = 0;
  std::string_view first_line;
  internal::NextLine(bytes, &pos, &first_line);
  if (first_line == "ply") return internal::ParsePly(path, bytes);
  if (internal::LooksLikePcd(bytes)) return internal::ParsePcd(path, bytes);
  internal::ThrowCloudFileError(
      path,
      "not a supported cloud file (expected a PLY file starting with 'ply' or a PCD "
      "file with a VERSION/FIELDS header)");
}

Rgb LabelColour(int label) {
  if (label < 0) return {128, 128, 128};
  // Golden-ratio hue steps keep consecutive labels far apart on the colour wheel; saturation and
  // value alternate so that labels whose hues nearly coincide still differ.
  constexpr double kGoldenRatioConjugate = 0.618033988749894848;
  const double hue = std::fmod(0.13 + label * kGoldenRatioConjugate, 1.0) * 6.0;
  const double saturation = (label % 2 == 0) ? 0.80 : 0.60;
  const double value = (label / 2) % 2 == 0 ? 0.95 : 0.75;
  const int sector = static_cast<int>(hue) % 6;
  const double f = hue - std::floor(hue);
  const double p = value * (1.0 - saturation);
  const double q = value * (1.0 - saturation * f);
  const double t = value * (1.0 - saturation * (1.0 - f));
  double r = 0, g = 0, b = 0;
  switch (sector) {
    case 0:
      r = value, g = t, b = p;
      break;
    case 1:
      r = q, g = value, b = p;
      break;
    case 2:
      r = p, g = value, b = t;
      break;
    case 3:
      r = p, g = q, b = value;
      break;
    case 4:
      r = t, g = p, b = value;
      break;
    default:
      r = value, g = p, b = q;
      break;
  }
  auto byte = [](double c) {
    return static_cast<std::uint8_t>(std::lround(std::clamp(c, 0.0, 1.0) * 255.0));
  };
  return {byte(r), byte(g), byte(b)};
}

}  // namespace tubepick

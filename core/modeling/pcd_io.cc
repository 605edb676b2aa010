// PCD v0.7 reader (ascii, binary, binary_compressed with LZF) and writer (ascii, binary).

#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <optional>
#include <string>

#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"
#include "core/modeling/cloud_io_internal.h"

namespace tubepick {
namespace internal {
namespace {

enum class PcdData { kAscii, kBinary, kBinaryCompressed };

struct PcdField {
  std::string name;
  std::size_t size = 4;
  char type = 'F';
  std::uint64_t count = 1;
  std::size_t bytes() const { return size * count; }
};

struct PcdHeader {
  std::vector<PcdField> fields;
  std::optional<std::uint64_t> width, height, points;
  PcdData data = PcdData::kAscii;
  std::size_t body_offset = 0;
  std::uint64_t point_count = 0;
};

std::uint64_t ParseCount(const std::string& path, std::string_view word, std::string_view line) {
  std::uint64_t value = 0;
  if (!ParseNumber(word, &value))
    ThrowCloudFileError(path, "bad PCD header line '" + std::string(line) + "'");
  return value;
}

PcdHeader ParsePcdHeader(const std::string& path, std::string_view bytes) {
  PcdHeader header;
  std::vector<std::string_view> sizes, types, counts;
  bool have_data = false;
  std::size_t pos = 0;
  std::string_view line;
  while (!have_data && NextLine(bytes, &pos, &line)) {
    const std::vector<std::string_view> words = SplitWords(line);
    if (words.empty() || words[0].front() == '#') continue;
    const std::string_view keyword = words[0];
    const std::vector<std::string_view> values(words.begin() + 1, words.end());
    if (keyword == "VERSION") {
      if (values.size() != 1 || (values[0] != "0.7" && values[0] != ".7")) {
        ThrowCloudFileError(path,
                            "unsupported PCD version '" + std::string(line) + "' (only 0.7 is supported)");
      }
    } else if (keyword == "FIELDS" || keyword == "COLUMNS") {
      for (std::string_view name : values) header.fields.push_back(PcdField{std::string(name)});
    } else if (keyword == "SIZE") {
      sizes = values;
    } else if (keyword == "TYPE") {
      types = values;
    } else if (keyword == "COUNT") {
      counts = values;
    } else if (keyword == "WIDTH" && values.size() == 1) {
      header.width = ParseCount(path, values[0], line);
    } else if (keyword == "HEIGHT" && values.size() == 1) {
      header.height = ParseCount(path, values[0], line);
    } else if (keyword == "POINTS" && values.size() == 1) {
      header.points = ParseCount(path, values[0], line);
    } else if (keyword == "VIEWPOINT") {
      // The acquisition viewpoint; the caller supplies X_BinSensor instead.
    } else if (keyword == "DATA" && values.size() == 1) {
      if (values[0] == "ascii") {
        header.data = PcdData::kAscii;
      } else if (values[0] == "binary") {
        header.data = PcdData::kBinary;
      } else if (values[0] == "binary_compressed") {
        header.data = PcdData::kBinaryCompressed;
      } else {
        ThrowCloudFileError(path, "unsupported PCD DATA type '" + std::string(values[0]) + "'");
      }
      have_data = true;
    } else {
      ThrowCloudFileError(path, "unexpected PCD header line '" + std::string(line) + "'");
    }
  }
  if (!have_data) ThrowCloudFileError(path, "PCD header has no DATA line");
  header.body_offset = pos;

  const std::size_t n = header.fields.size();
  if (n == 0) ThrowCloudFileError(path, "PCD header has no FIELDS");
  if (sizes.size() != n || types.size() != n || (!counts.empty() && counts.size() != n)) {
    ThrowCloudFileError(path, "PCD header has " + std::to_string(n) + " FIELDS but " +
                                  std::to_string(sizes.size()) + " SIZE, " + std::to_string(types.size()) +
                                  " TYPE and " + std::to_string(counts.size()) + " COUNT entries");
  }
  for (std::size_t i = 0; i < n; ++i) {
    PcdField& field = header.fields[i];
    std::uint64_t size = 0;
    const bool size_ok = ParseNumber(sizes[i], &size) && (size == 1 || size == 2 || size == 4 || size == 8);
    const bool type_ok =
        types[i].size() == 1 && (types[i][0] == 'F' || types[i][0] == 'I' || types[i][0] == 'U');
    if (!size_ok || !type_ok || (types[i] == "F" && size != 4 && size != 8)) {
      ThrowCloudFileError(path, "unsupported PCD field '" + field.name + "': SIZE " + std::string(sizes[i]) +
                                    ", TYPE " + std::string(types[i]));
    }
    field.size = size;
    field.type = types[i][0];
    constexpr std::uint64_t kMaxCount = 1u << 24;  // keeps byte sizes far from overflow
    if (!counts.empty() &&
        (!ParseNumber(counts[i], &field.count) || field.count == 0 || field.count > kMaxCount)) {
      ThrowCloudFileError(path,
                          "bad PCD COUNT '" + std::string(counts[i]) + "' for field '" + field.name + "'");
    }
  }
  const std::uint64_t organised = header.width.value_or(0) * header.height.value_or(1);
  if (header.points && header.width && *header.points != organised) {
    ThrowCloudFileError(path, "PCD header says POINTS " + std::to_string(*header.points) +
                                  " but WIDTH x HEIGHT = " + std::to_string(organised));
  }
  if (!header.points && !header.width) ThrowCloudFileError(path, "PCD header has neither POINTS nor WIDTH");
  header.point_count = header.points.value_or(organised);
  return header;
}

/// Index of x, y, z among the fields (each must be a single float or double).
std::array<std::size_t, 3> FindXyz(const std::string& path, const PcdHeader& header) {
  std::array<std::size_t, 3> index{};
  const char* names[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    const auto it = std::find_if(header.fields.begin(), header.fields.end(),
                                 [&](const PcdField& f) { return f.name == names[axis]; });
    if (it == header.fields.end()) {
      ThrowCloudFileError(path, std::string("the PCD file has no '") + names[axis] + "' field");
    }
    if (it->type != 'F' || it->count != 1) {
      ThrowCloudFileError(path, std::string("PCD field '") + names[axis] +
                                    "' must be a single float or double (TYPE F, COUNT 1)");
    }
    index[axis] = static_cast<std::size_t>(it - header.fields.begin());
  }
  return index;
}

/// Reads a little-endian float or double of `size` bytes at `p`.
float LoadFloat(const char* p, std::size_t size) {
  char buffer[8];
  std::memcpy(buffer, p, size);
  if constexpr (std::endian::native == std::endian::big) std::reverse(buffer, buffer + size);
  if (size == 4) {
    float value;
    std::memcpy(&value, buffer, 4);
    return value;
  }
  double value;
  std::memcpy(&value, buffer, 8);
  return static_cast<float>(value);
}

[[noreturn]] void ThrowTruncatedPoints(const std::string& path, std::uint64_t declared, std::uint64_t read) {
  ThrowCloudFileError(path, "truncated: the header declares " + std::to_string(declared) +
                                " points but the data ends after " + std::to_string(read));
}

Points ReadAscii(const std::string& path, const PcdHeader& header, std::string_view body) {
  const std::array<std::size_t, 3> xyz = FindXyz(path, header);
  std::vector<int> axis_of_field(header.fields.size(), -1);
  for (int axis = 0; axis < 3; ++axis) axis_of_field[xyz[axis]] = axis;
  TokenReader reader(body);
  std::string_view token;
  Points points;
  points.reserve(std::min<std::uint64_t>(header.point_count, body.size() / 6 + 1));
  for (std::uint64_t i = 0; i < header.point_count; ++i) {
    Eigen::Vector3f p;
    for (std::size_t f = 0; f < header.fields.size(); ++f) {
      for (std::uint64_t c = 0; c < header.fields[f].count; ++c) {
        if (!reader.Next(&token)) ThrowTruncatedPoints(path, header.point_count, i);
        const int axis = axis_of_field[f];
        if (axis >= 0 && !ParseNumber(token, &p[axis])) {
          ThrowCloudFileError(path, "point " + std::to_string(i) + ": cannot parse " + header.fields[f].name +
                                        " value '" + std::string(token) + "'");
        }
      }
    }
    points.push_back(p);
  }
  return points;
}

std::size_t PointBytes(const PcdHeader& header) {
  std::size_t bytes = 0;
  for (const PcdField& f : header.fields) bytes += f.bytes();
  return bytes;
}

Points ReadBinary(const std::string& path, const PcdHeader& header, std::string_view body) {
  const std::array<std::size_t, 3> xyz = FindXyz(path, header);
  const std::size_t stride = PointBytes(header);
  if (header.point_count > body.size() / stride) {
    ThrowCloudFileError(path, "truncated: the header declares " + std::to_string(header.point_count) +
                                  " points (" + ByteCountText(header.point_count, stride) +
                                  " bytes) but only " + std::to_string(body.size()) +
                                  " bytes of point data follow");
  }
  std::size_t offset[3] = {0, 0, 0};
  std::size_t size[3];
  for (int axis = 0; axis < 3; ++axis) {
    for (std::size_t f = 0; f < xyz[axis]; ++f) offset[axis] += header.fields[f].bytes();
    size[axis] = header.fields[xyz[axis]].size;
  }
  Points points(header.point_count);
  const char* data = body.data();
  if (size[0] == 4 && size[1] == 4 && size[2] == 4 && std::endian::native == std::endian::little) {
    for (std::size_t i = 0; i < points.size(); ++i, data += stride) {  // the common case, kept tight
      float* out = points[i].data();
      std::memcpy(out + 0, data + offset[0], 4);
      std::memcpy(out + 1, data + offset[1], 4);
      std::memcpy(out + 2, data + offset[2], 4);
    }
    return points;
  }
  for (std::size_t i = 0; i < points.size(); ++i, data += stride) {
    for (int axis = 0; axis < 3; ++axis) points[i][axis] = LoadFloat(data + offset[axis], size[axis]);
  }
  return points;
}

Points ReadBinaryCompressed(const std::string& path, const PcdHeader& header, std::string_view body) {
  const std::array<std::size_t, 3> xyz = FindXyz(path, header);
  if (body.size() < 8) ThrowCloudFileError(path, "truncated: binary_compressed data has no size header");
  auto load_u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i)
      v |= static_cast<std::uint32_t>(static_cast<unsigned char>(body[at + i])) << (8 * i);
    return v;
  };
  const std::uint32_t compressed_size = load_u32(0);
  const std::uint32_t uncompressed_size = load_u32(4);
  if (body.size() - 8 < compressed_size) {
    ThrowCloudFileError(path, "truncated: binary_compressed data declares " +
                                  std::to_string(compressed_size) + " compressed bytes but only " +
                                  std::to_string(body.size() - 8) + " follow");
  }
  const std::size_t stride = PointBytes(header);
  if (header.point_count > uncompressed_size / stride) {
    ThrowCloudFileError(path, "binary_compressed data holds " + std::to_string(uncompressed_size) +
                                  " bytes but " + std::to_string(header.point_count) + " points need " +
                                  ByteCountText(header.point_count, stride));
  }
  // An LZF back reference (3 bytes) expands to at most 264 bytes: reject absurd sizes before allocating.
  if (uncompressed_size > 88 * static_cast<std::uint64_t>(compressed_size) + 64) {
    ThrowCloudFileError(path, "corrupt binary_compressed data: " + std::to_string(compressed_size) +
                                  " compressed bytes cannot hold " + std::to_string(uncompressed_size));
  }
  const std::vector<char> data = LzfDecompress(path, body.substr(8, compressed_size), uncompressed_size);
  // Field-major layout: all x, then all y, ... (each field's values for every point in a row).
  Points points(header.point_count);
  for (int axis = 0; axis < 3; ++axis) {
    std::size_t start = 0;
    for (std::size_t f = 0; f < xyz[axis]; ++f) start += header.point_count * header.fields[f].bytes();
    const std::size_t size = header.fields[xyz[axis]].size;
    const char* column = data.data() + start;
    for (std::size_t i = 0; i < points.size(); ++i) points[i][axis] = LoadFloat(column + i * size, size);
  }
  return points;
}

}  // namespace

bool LooksLikePcd(std::string_view bytes) {
  std::size_t pos = 0;
  std::string_view line;
  for (int i = 0; i < 64 && NextLine(bytes.substr(0, 65536), &pos, &line); ++i) {
    const std::vector<std::string_view> words = SplitWords(line);
    if (words.empty() || words[0].front() == '#') continue;
    return words[0] == "VERSION" || words[0] == "FIELDS";
  }
  return false;
}

std::vector<char> LzfDecompress(const std::string& path, std::string_view compressed,
                                std::size_t expected_size) {
  std::vector<char> out(expected_size);
  auto corrupt = [&](const std::string& why) {
    ThrowCloudFileError(path, "corrupt binary_compressed (LZF) data: " + why);
  };
  const auto* ip = reinterpret_cast<const unsigned char*>(compressed.data());
  const unsigned char* const in_end = ip + compressed.size();
  std::size_t op = 0;
  while (ip < in_end) {
    const unsigned ctrl = *ip++;
    if (ctrl < 32) {  // literal run of ctrl + 1 bytes
      const std::size_t length = ctrl + 1;
      if (static_cast<std::size_t>(in_end - ip) < length) corrupt("literal run past the end of the input");
      if (expected_size - op < length) corrupt("output longer than the declared size");
      std::memcpy(out.data() + op, ip, length);
      ip += length;
      op += length;
      continue;
    }
    // Back reference: 3 bits of length (7 = more in the next byte), 13 bits of offset.
    std::size_t length = ctrl >> 5;
    if (length == 7) {
      if (ip >= in_end) corrupt("back reference past the end of the input");
      length += *ip++;
    }
    if (ip >= in_end) corrupt("back reference past the end of the input");
    const std::size_t back = ((static_cast<std::size_t>(ctrl & 0x1f) << 8) | *ip++) + 1;
    length += 2;
    if (back > op) corrupt("back reference before the start of the output");
    if (expected_size - op < length) corrupt("output longer than the declared size");
    for (std::size_t k = 0; k < length; ++k, ++op) out[op] = out[op - back];  // may overlap
  }
  if (op != expected_size) {
    corrupt("decompressed to " + std::to_string(op) + " bytes, expected " + std::to_string(expected_size));
  }
  return out;
}

CloudFile ParsePcd(const std::string& path, std::string_view bytes) {
  const PcdHeader header = ParsePcdHeader(path, bytes);
  const std::string_view body = bytes.substr(header.body_offset);
  CloudFile cloud;
  switch (header.data) {
    case PcdData::kAscii:
      cloud.points = ReadAscii(path, header, body);
      cloud.format = "pcd-ascii";
      break;
    case PcdData::kBinary:
      cloud.points = ReadBinary(path, header, body);
      cloud.format = "pcd-binary";
      break;
    case PcdData::kBinaryCompressed:
      cloud.points = ReadBinaryCompressed(path, header, body);
      cloud.format = "pcd-binary-compressed";
      break;
  }
  return cloud;
}

}  // namespace internal

void WritePcd(const std::string& path, const Points& points, bool binary) {
  const std::string n = std::to_string(points.size());
  std::string out =
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\n"
      "TYPE F F F\nCOUNT 1 1 1\nWIDTH " +
      n + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + n + "\nDATA " + (binary ? "binary" : "ascii") +
      "\n";
  if (binary) {
    const std::size_t header_size = out.size();
    out.resize(header_size + points.size() * 12);
    char* data = out.data() + header_size;
    for (const Eigen::Vector3f& p : points) {
      for (int axis = 0; axis < 3; ++axis, data += 4) internal::StoreFloatLE(data, p[axis]);
    }
  } else {
    internal::AppendAsciiPoints(&out, points);
  }
  internal::WriteFileBytes(path, out);
}

}  // namespace tubepick

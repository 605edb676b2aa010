// PLY reader (ascii, binary little/big endian) and writers.

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstring>
#include <optional>
#include <string>

#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"
#include "core/modeling/cloud_io_internal.h"

namespace tubepick {
namespace internal {
namespace {

enum class ScalarType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };
enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyProperty {
  std::string name;
  ScalarType type = ScalarType::kFloat32;  // item type for lists
  bool is_list = false;
  ScalarType count_type = ScalarType::kUint8;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> properties;
  bool has_list() const {
    return std::any_of(properties.begin(), properties.end(), [](const PlyProperty& p) { return p.is_list; });
  }
};

struct PlyHeader {
  PlyFormat format = PlyFormat::kAscii;
  std::vector<PlyElement> elements;
  std::size_t body_offset = 0;
};

std::optional<ScalarType> ParseScalarType(std::string_view word) {
  if (word == "char" || word == "int8") return ScalarType::kInt8;
  if (word == "uchar" || word == "uint8") return ScalarType::kUint8;
  if (word == "short" || word == "int16") return ScalarType::kInt16;
  if (word == "ushort" || word == "uint16") return ScalarType::kUint16;
  if (word == "int" || word == "int32") return ScalarType::kInt32;
  if (word == "uint" || word == "uint32") return ScalarType::kUint32;
  if (word == "float" || word == "float32") return ScalarType::kFloat32;
  if (word == "double" || word == "float64") return ScalarType::kFloat64;
  return std::nullopt;
}

const char* TypeName(ScalarType type) {
  switch (type) {
    case ScalarType::kInt8:
      return "char";
    case ScalarType::kUint8:
      return "uchar";
    case ScalarType::kInt16:
      return "short";
    case ScalarType::kUint16:
      return "ushort";
    case ScalarType::kInt32:
      return "int";
    case ScalarType::kUint32:
      return "uint";
    case ScalarType::kFloat32:
      return "float";
    case ScalarType::kFloat64:
      return "double";
  }
  return "?";
}

std::size_t SizeOf(ScalarType type) {
  switch (type) {
    case ScalarType::kInt8:
    case ScalarType::kUint8:
      return 1;
    case ScalarType::kInt16:
    case ScalarType::kUint16:
      return 2;
    case ScalarType::kInt32:
    case ScalarType::kUint32:
    case ScalarType::kFloat32:
      return 4;
    case ScalarType::kFloat64:
      return 8;
  }
  return 0;
}

template <typename T>
T Load(const char* p, bool swap) {
  char buffer[sizeof(T)];
  std::memcpy(buffer, p, sizeof(T));
  if (swap) std::reverse(buffer, buffer + sizeof(T));
  T value;
  std::memcpy(&value, buffer, sizeof(T));
  return value;
}

double LoadAsDouble(const char* p, ScalarType type, bool swap) {
  switch (type) {
    case ScalarType::kInt8:
      return Load<std::int8_t>(p, swap);
    case ScalarType::kUint8:
      return Load<std::uint8_t>(p, swap);
    case ScalarType::kInt16:
      return Load<std::int16_t>(p, swap);
    case ScalarType::kUint16:
      return Load<std::uint16_t>(p, swap);
    case ScalarType::kInt32:
      return Load<std::int32_t>(p, swap);
    case ScalarType::kUint32:
      return Load<std::uint32_t>(p, swap);
    case ScalarType::kFloat32:
      return Load<float>(p, swap);
    case ScalarType::kFloat64:
      return Load<double>(p, swap);
  }
  return 0.0;
}

PlyHeader ParsePlyHeader(const std::string& path, std::string_view bytes) {
  PlyHeader header;
  std::size_t pos = 0;
  std::string_view line;
  NextLine(bytes, &pos, &line);  // "ply", checked by the caller
  bool have_format = false;
  while (true) {
    if (!NextLine(bytes, &pos, &line)) ThrowCloudFileError(path, "PLY header has no 'end_header' line");
    const std::vector<std::string_view> words = SplitWords(line);
    if (words.empty()) continue;
    const std::string_view keyword = words[0];
    if (keyword == "end_header") break;
    if (keyword == "comment" || keyword == "obj_info") continue;
    if (keyword == "format") {
      if (words.size() != 3) ThrowCloudFileError(path, "bad PLY format line '" + std::string(line) + "'");
      if (words[1] == "ascii") {
        header.format = PlyFormat::kAscii;
      } else if (words[1] == "binary_little_endian") {
        header.format = PlyFormat::kBinaryLittleEndian;
      } else if (words[1] == "binary_big_endian") {
        header.format = PlyFormat::kBinaryBigEndian;
      } else {
        ThrowCloudFileError(path, "unsupported PLY format '" + std::string(words[1]) + "'");
      }
      have_format = true;
    } else if (keyword == "element") {
      PlyElement element;
      if (words.size() != 3 || !ParseNumber(words[2], &element.count)) {
        ThrowCloudFileError(path, "bad PLY element line '" + std::string(line) + "'");
      }
      element.name = std::string(words[1]);
      header.elements.push_back(std::move(element));
    } else if (keyword == "property") {
      if (header.elements.empty()) {
        ThrowCloudFileError(path, "PLY property before any element: '" + std::string(line) + "'");
      }
      PlyProperty property;
      const bool is_list = words.size() >= 2 && words[1] == "list";
      const std::size_t expected = is_list ? 5 : 3;
      std::optional<ScalarType> type =
          words.size() == expected ? ParseScalarType(words[expected - 2]) : std::nullopt;
      std::optional<ScalarType> count_type =
          is_list && words.size() == 5 ? ParseScalarType(words[2]) : std::nullopt;
      if (!type || (is_list && !count_type)) {
        ThrowCloudFileError(path, "bad or unsupported PLY property line '" + std::string(line) + "'");
      }
      property.is_list = is_list;
      property.type = *type;
      if (count_type) property.count_type = *count_type;
      property.name = std::string(words[expected - 1]);
      header.elements.back().properties.push_back(std::move(property));
    } else {
      ThrowCloudFileError(path, "unexpected PLY header line '" + std::string(line) + "'");
    }
  }
  if (!have_format) ThrowCloudFileError(path, "PLY header has no 'format' line");
  header.body_offset = pos;
  return header;
}

/// Where x, y, z sit in a vertex.
struct XyzLayout {
  std::size_t property[3] = {0, 0, 0};
};

XyzLayout FindXyz(const std::string& path, const PlyElement& vertex) {
  XyzLayout layout;
  const char* names[3] = {"x", "y", "z"};
  for (int axis = 0; axis < 3; ++axis) {
    const auto it = std::find_if(vertex.properties.begin(), vertex.properties.end(),
                                 [&](const PlyProperty& p) { return p.name == names[axis]; });
    if (it == vertex.properties.end()) {
      ThrowCloudFileError(path, std::string("the PLY vertex element has no '") + names[axis] + "' property");
    }
    if (it->is_list || (it->type != ScalarType::kFloat32 && it->type != ScalarType::kFloat64)) {
      ThrowCloudFileError(path, std::string("PLY vertex property '") + names[axis] + "' has type " +
                                    (it->is_list ? "list" : TypeName(it->type)) +
                                    "; only float and double are supported");
    }
    layout.property[axis] = static_cast<std::size_t>(it - vertex.properties.begin());
  }
  return layout;
}

/// `value` in its shortest exact decimal form ("nan", "-1", "2.5") for error messages.
std::string NumberText(double value) {
  char buffer[32];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return ec == std::errc() ? std::string(buffer, end) : std::string("?");
}

[[noreturn]] void ThrowTruncated(const std::string& path, const PlyElement& element, std::uint64_t read) {
  ThrowCloudFileError(path, "truncated: the header declares " + std::to_string(element.count) + " " +
                                element.name + " elements but the data ends after " + std::to_string(read));
}

/// Skips one binary property value (a scalar or a whole list) starting at `*offset`.
void SkipBinaryProperty(const std::string& path, const PlyElement& element, std::uint64_t index,
                        const PlyProperty& property, std::string_view body, bool swap, std::size_t* offset) {
  if (!property.is_list) {
    if (body.size() - *offset < SizeOf(property.type)) ThrowTruncated(path, element, index);
    *offset += SizeOf(property.type);
    return;
  }
  if (body.size() - *offset < SizeOf(property.count_type)) ThrowTruncated(path, element, index);
  const double count = LoadAsDouble(body.data() + *offset, property.count_type, swap);
  *offset += SizeOf(property.count_type);
  // A float or double count type is legal in the header, so the value may be anything: only a
  // whole, non-negative number is a length (casting NaN or 1e300 to an integer is undefined).
  if (!(count >= 0.0) || count != std::floor(count)) {
    ThrowCloudFileError(path, "bad list length " + NumberText(count) + " in PLY element '" + element.name +
                                  "' " + std::to_string(index));
  }
  const std::size_t item_size = SizeOf(property.type);
  if (count > static_cast<double>((body.size() - *offset) / item_size)) ThrowTruncated(path, element, index);
  *offset += static_cast<std::size_t>(count) * item_size;
}

/// Skips one binary element instance (with list properties) starting at `*offset`.
void SkipBinaryInstance(const std::string& path, const PlyElement& element, std::uint64_t index,
                        std::string_view body, bool swap, std::size_t* offset) {
  for (const PlyProperty& property : element.properties) {
    SkipBinaryProperty(path, element, index, property, body, swap, offset);
  }
}

std::size_t FixedStride(const PlyElement& element) {
  std::size_t stride = 0;
  for (const PlyProperty& p : element.properties) stride += SizeOf(p.type);
  return stride;
}

Points ReadBinaryVertices(const std::string& path, const PlyHeader& header, std::size_t vertex_index,
                          std::string_view body) {
  const bool big_endian_file = header.format == PlyFormat::kBinaryBigEndian;
  const bool swap = big_endian_file != (std::endian::native == std::endian::big);
  std::size_t offset = 0;
  for (std::size_t e = 0; e < vertex_index; ++e) {
    const PlyElement& element = header.elements[e];
    if (!element.has_list()) {
      const std::size_t stride = FixedStride(element);
      if (stride != 0 && element.count > (body.size() - offset) / stride) {
        ThrowTruncated(path, element, (body.size() - offset) / stride);
      }
      offset += element.count * stride;
      continue;
    }
    for (std::uint64_t i = 0; i < element.count; ++i)
      SkipBinaryInstance(path, element, i, body, swap, &offset);
  }

  const PlyElement& vertex = header.elements[vertex_index];
  const XyzLayout xyz = FindXyz(path, vertex);
  std::size_t property_offset[3] = {0, 0, 0};
  ScalarType type[3];
  for (int axis = 0; axis < 3; ++axis) {
    type[axis] = vertex.properties[xyz.property[axis]].type;
    for (std::size_t p = 0; p < xyz.property[axis]; ++p)
      property_offset[axis] += SizeOf(vertex.properties[p].type);
  }

  if (vertex.has_list()) {
    // Rare: a list inside the vertex element. Walk vertex by vertex, property by property.
    Points points;
    points.reserve(std::min<std::uint64_t>(vertex.count, (body.size() - offset) / 3));
    for (std::uint64_t i = 0; i < vertex.count; ++i) {
      Eigen::Vector3f p;
      for (std::size_t k = 0; k < vertex.properties.size(); ++k) {
        int axis = -1;
        for (int a = 0; a < 3; ++a) axis = xyz.property[a] == k ? a : axis;
        if (axis >= 0) {
          if (body.size() - offset < SizeOf(type[axis])) ThrowTruncated(path, vertex, i);
          p[axis] = static_cast<float>(LoadAsDouble(body.data() + offset, type[axis], swap));
        }
        SkipBinaryProperty(path, vertex, i, vertex.properties[k], body, swap, &offset);
      }
      points.push_back(p);
    }
    return points;
  }

  const std::size_t stride = FixedStride(vertex);
  const std::size_t available = body.size() - offset;
  if (vertex.count > available / stride) {
    ThrowCloudFileError(path, "truncated: the header declares " + std::to_string(vertex.count) +
                                  " vertices (" + ByteCountText(vertex.count, stride) + " bytes) but only " +
                                  std::to_string(available) + " bytes of vertex data follow");
  }
  Points points(vertex.count);
  const char* data = body.data() + offset;
  const bool all_float =
      type[0] == ScalarType::kFloat32 && type[1] == ScalarType::kFloat32 && type[2] == ScalarType::kFloat32;
  if (all_float && !swap) {
    for (std::size_t i = 0; i < points.size(); ++i, data += stride) {
      float* out = points[i].data();
      std::memcpy(out + 0, data + property_offset[0], 4);
      std::memcpy(out + 1, data + property_offset[1], 4);
      std::memcpy(out + 2, data + property_offset[2], 4);
    }
  } else {
    for (std::size_t i = 0; i < points.size(); ++i, data += stride) {
      for (int axis = 0; axis < 3; ++axis) {
        points[i][axis] = type[axis] == ScalarType::kFloat32
                              ? Load<float>(data + property_offset[axis], swap)
                              : static_cast<float>(Load<double>(data + property_offset[axis], swap));
      }
    }
  }
  return points;
}

Points ReadAsciiVertices(const std::string& path, const PlyHeader& header, std::size_t vertex_index,
                         std::string_view body) {
  TokenReader reader(body);
  std::string_view token;
  // Skips one property value (a scalar or a whole list).
  auto skip_property = [&](const PlyElement& element, const PlyProperty& property, std::uint64_t index) {
    if (!reader.Next(&token)) ThrowTruncated(path, element, index);
    if (!property.is_list) return;
    std::uint64_t count = 0;
    if (!ParseNumber(token, &count)) {
      ThrowCloudFileError(path, "bad list length '" + std::string(token) + "' in PLY element '" +
                                    element.name + "' " + std::to_string(index));
    }
    for (std::uint64_t k = 0; k < count; ++k) {
      if (!reader.Next(&token)) ThrowTruncated(path, element, index);
    }
  };
  auto skip_instance = [&](const PlyElement& element, std::uint64_t index) {
    for (const PlyProperty& property : element.properties) skip_property(element, property, index);
  };
  for (std::size_t e = 0; e < vertex_index; ++e) {
    const PlyElement& element = header.elements[e];
    // An element without properties has no text at all, whatever its count (up to 2^64 - 1).
    if (element.properties.empty()) continue;
    for (std::uint64_t i = 0; i < element.count; ++i) skip_instance(element, i);
  }

  const PlyElement& vertex = header.elements[vertex_index];
  const XyzLayout xyz = FindXyz(path, vertex);
  const std::size_t property_count = vertex.properties.size();
  std::vector<int> axis_of_property(property_count, -1);
  for (int axis = 0; axis < 3; ++axis) axis_of_property[xyz.property[axis]] = axis;

  Points points;
  // Each vertex takes at least two characters per property, so this never over-allocates much.
  points.reserve(std::min<std::uint64_t>(vertex.count, body.size() / (2 * property_count) + 1));
  for (std::uint64_t i = 0; i < vertex.count; ++i) {
    Eigen::Vector3f p;
    for (std::size_t k = 0; k < property_count; ++k) {
      const PlyProperty& property = vertex.properties[k];
      if (property.is_list) {
        skip_property(vertex, property, i);
        continue;
      }
      if (!reader.Next(&token)) ThrowTruncated(path, vertex, i);
      const int axis = axis_of_property[k];
      if (axis < 0) continue;
      bool ok = false;
      if (property.type == ScalarType::kFloat32) {
        ok = ParseNumber(token, &p[axis]);
      } else {
        double value = 0.0;
        ok = ParseNumber(token, &value);
        p[axis] = static_cast<float>(value);
      }
      if (!ok) {
        ThrowCloudFileError(path, "vertex " + std::to_string(i) + ": cannot parse " + property.name +
                                      " value '" + std::string(token) + "'");
      }
    }
    points.push_back(p);
  }
  return points;
}

}  // namespace

CloudFile ParsePly(const std::string& path, std::string_view bytes) {
  const PlyHeader header = ParsePlyHeader(path, bytes);
  const auto vertex = std::find_if(header.elements.begin(), header.elements.end(),
                                   [](const PlyElement& e) { return e.name == "vertex"; });
  if (vertex == header.elements.end()) ThrowCloudFileError(path, "the PLY file has no 'vertex' element");
  const auto vertex_index = static_cast<std::size_t>(vertex - header.elements.begin());
  const std::string_view body = bytes.substr(header.body_offset);
  CloudFile cloud;
  switch (header.format) {
    case PlyFormat::kAscii:
      cloud.points = ReadAsciiVertices(path, header, vertex_index, body);
      cloud.format = "ply-ascii";
      break;
    case PlyFormat::kBinaryLittleEndian:
      cloud.points = ReadBinaryVertices(path, header, vertex_index, body);
      cloud.format = "ply-binary-le";
      break;
    case PlyFormat::kBinaryBigEndian:
      cloud.points = ReadBinaryVertices(path, header, vertex_index, body);
      cloud.format = "ply-binary-be";
      break;
  }
  return cloud;
}

}  // namespace internal

void WritePly(const std::string& path, const Points& points, const std::vector<Rgb>* colours) {
  if (colours != nullptr && colours->size() != points.size()) {
    throw InvalidArgument("WritePly('" + path + "'): " + std::to_string(colours->size()) + " colours for " +
                          std::to_string(points.size()) + " points");
  }
  std::string header = "ply\nformat binary_little_endian 1.0\ncomment written by tubepick\nelement vertex " +
                       std::to_string(points.size()) +
                       "\nproperty float x\nproperty float y\nproperty float z\n";
  if (colours != nullptr) header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  header += "end_header\n";
  const std::size_t stride = colours != nullptr ? 15 : 12;
  std::string out = header;
  out.resize(header.size() + points.size() * stride);
  char* data = out.data() + header.size();
  for (std::size_t i = 0; i < points.size(); ++i, data += stride) {
    for (int axis = 0; axis < 3; ++axis) internal::StoreFloatLE(data + 4 * axis, points[i][axis]);
    if (colours != nullptr) std::memcpy(data + 12, (*colours)[i].data(), 3);
  }
  internal::WriteFileBytes(path, out);
}

void WritePlyAscii(const std::string& path, const Points& points) {
  std::string out = "ply\nformat ascii 1.0\ncomment written by tubepick\nelement vertex " +
                    std::to_string(points.size()) +
                    "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  internal::AppendAsciiPoints(&out, points);
  internal::WriteFileBytes(path, out);
}

}  // namespace tubepick

#include "core/common/config_fields.h"

#include <fmt/core.h>

#include <cctype>
#include <cmath>

#include "core/common/require.h"

namespace tubepick {
namespace {

constexpr double kMaxSeconds = 1e9;
// Largest deviation of |q| from 1 accepted for an orientation quaternion.
constexpr double kUnitQuaternionTol = 1e-3;
// Quaternion components below this are written as 0 (round-off of the rotation matrix).
constexpr double kQuaternionZero = 1e-15;
// A one-line comment follows its value on the same line when the line stays this short, characters.
constexpr std::size_t kMaxTrailingCommentLine = 100;

// Reads the list [x, y, z, w] at `map`'s key "orientation_xyzw" into `xyzw`, when present.
void ReadXyzw(YamlMap& map, Eigen::Vector4d& xyzw) {
  if (!map.Has("orientation_xyzw")) return;
  const std::string path = map.PathOf("orientation_xyzw");
  const YAML::Node n = map.Child("orientation_xyzw");
  if (!n.IsSequence() || n.size() != 4)
    throw InvalidArgument(path + ": expected a list of 4 numbers (x, y, z, w)");
  for (int i = 0; i < 4; ++i) {
    try {
      xyzw[i] = n[i].as<double>();
    } catch (const YAML::Exception&) {
      throw InvalidArgument(path + ": expected numbers");
    }
    RequireFinite(xyzw[i], path);
  }
}

// Reads position and orientation_xyzw of the pose mapping `map` over `pose`.
Eigen::Isometry3d ReadPoseFields(YamlMap& map, const Eigen::Isometry3d& pose) {
  Eigen::Vector3d position = pose.translation();
  const Eigen::Quaterniond q0(pose.linear());
  Eigen::Vector4d xyzw(q0.x(), q0.y(), q0.z(), q0.w());
  map.Read("position", position);
  ReadXyzw(map, xyzw);
  map.RejectUnknown();
  const double norm = xyzw.norm();
  if (std::abs(norm - 1.0) > kUnitQuaternionTol) {
    throw InvalidArgument(map.PathOf("orientation_xyzw") +
                          ": quaternion must be unit length, |q| = " + std::to_string(norm));
  }
  Eigen::Isometry3d result = Eigen::Isometry3d::Identity();
  result.linear() = Eigen::Quaterniond(xyzw[3], xyzw[0], xyzw[1], xyzw[2]).normalized().toRotationMatrix();
  result.translation() = position;
  return result;
}

double CleanQuaternionComponent(double c) { return std::abs(c) < kQuaternionZero ? 0.0 : c; }

// True when `text` reads back as the same string without quotes, in YAML 1.1 and 1.2 alike.
bool IsPlainSafe(const std::string& text) {
  if (text.empty() || !(std::isalpha(static_cast<unsigned char>(text[0])) || text[0] == '_')) return false;
  for (const char c : text) {
    const unsigned char u = static_cast<unsigned char>(c);
    if (!(std::isalnum(u) || c == '_' || c == '-' || c == '.' || c == '/')) return false;
  }
  std::string lower;
  for (const char c : text) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const char* word : {"true", "false", "yes", "no", "on", "off", "null", "y", "n"}) {
    if (lower == word) return false;
  }
  return true;
}

std::string Quoted(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else if (c == '\t') {
      out += "\\t";
    } else if (static_cast<unsigned char>(c) < 0x20) {
      out += fmt::format("\\x{:02x}", static_cast<unsigned char>(c));
    } else {
      out += c;
    }
  }
  return out + "\"";
}

}  // namespace

// ---- YamlFieldReader --------------------------------------------------------------------------

void YamlFieldReader::Seconds(const char* key, std::chrono::milliseconds& value, std::string_view) {
  double seconds = static_cast<double>(value.count()) / 1000.0;
  map_.Read(key, seconds);  // finite or throws
  if (std::abs(seconds) > kMaxSeconds) {
    throw InvalidArgument(fmt::format("{}: {} s is out of range (at most 1e9 s)", map_.PathOf(key), seconds));
  }
  value = std::chrono::milliseconds(std::llround(seconds * 1000.0));
}

void YamlFieldReader::Degrees(const char* key, double& radians, std::string_view) {
  map_.ReadDegrees(key, radians);
}

void YamlFieldReader::Pose(const char* key, Eigen::Isometry3d& pose, std::string_view) {
  YamlMap map(map_.Child(key), map_.PathOf(key));
  pose = ReadPoseFields(map, pose);
}

void YamlFieldReader::OptionalPose(const char* key, std::optional<Eigen::Isometry3d>& pose,
                                   std::string_view) {
  if (!map_.Has(key)) return;
  const YAML::Node node = map_.Child(key);
  if (node.IsNull()) {
    pose.reset();
    return;
  }
  YamlMap map(node, map_.PathOf(key));
  if (!map.Has("position") || !map.Has("orientation_xyzw")) {
    throw InvalidArgument(map_.PathOf(key) +
                          ": needs position and orientation_xyzw (or null for the default)");
  }
  pose = ReadPoseFields(map, Eigen::Isometry3d::Identity());
}

// ---- YamlFieldWriter --------------------------------------------------------------------------

void YamlFieldWriter::Seconds(const char* key, std::chrono::milliseconds& value, std::string_view comment) {
  Line(key, YamlValue(static_cast<double>(value.count()) / 1000.0), comment);
}

void YamlFieldWriter::Degrees(const char* key, double& radians, std::string_view comment) {
  Line(key, YamlValue(radians * 180.0 / M_PI), comment);
}

void YamlFieldWriter::Pose(const char* key, Eigen::Isometry3d& pose, std::string_view comment) {
  const Eigen::Quaterniond q(pose.linear());
  const std::string pad(indent_ + 2, ' ');
  const std::string body =
      pad + "position: " + YamlValue(Eigen::Vector3d(pose.translation())) + "\n" + pad +
      fmt::format("orientation_xyzw: [{}, {}, {}, {}]\n", YamlValue(CleanQuaternionComponent(q.x())),
                  YamlValue(CleanQuaternionComponent(q.y())), YamlValue(CleanQuaternionComponent(q.z())),
                  YamlValue(CleanQuaternionComponent(q.w())));
  Block(key, body, comment);
}

void YamlFieldWriter::OptionalPose(const char* key, std::optional<Eigen::Isometry3d>& pose,
                                   std::string_view comment) {
  if (pose) {
    Pose(key, *pose, comment);
  } else {
    Line(key, "null", comment);
  }
}

void YamlFieldWriter::Heading(std::string_view text) {
  BlankLineAtTopLevel();
  Comment(text);
}

std::string YamlFieldWriter::Document(std::string_view header) const {
  if (header.empty()) return out_;
  YamlFieldWriter top;
  top.Comment(header);
  return top.out_ + "\n" + out_;
}

void YamlFieldWriter::Line(std::string_view key, std::string_view value, std::string_view comment) {
  Annotated(fmt::format("{:{}}{}: {}", "", indent_, key, value), comment);
}

void YamlFieldWriter::Block(std::string_view key, const std::string& body, std::string_view comment) {
  BlankLineAtTopLevel();
  if (body.empty()) {
    Line(key, "{}", comment);
    return;
  }
  Annotated(fmt::format("{:{}}{}:", "", indent_, key), comment);
  out_ += body;
}

void YamlFieldWriter::Annotated(const std::string& line, std::string_view comment) {
  const bool trailing = comment.find('\n') == std::string_view::npos &&
                        line.size() + 4 + comment.size() <= kMaxTrailingCommentLine;
  if (comment.empty() || !trailing) {
    Comment(comment);
    out_ += line + "\n";
  } else {
    out_ += fmt::format("{}  # {}\n", line, comment);
  }
}

void YamlFieldWriter::ListItem(std::string_view name, const std::string& fields) {
  out_ += fmt::format("{:{}}- {}:{}", "", indent_, name, fields.empty() ? " {}\n" : "\n");
  out_ += fields;
}

void YamlFieldWriter::Comment(std::string_view text) {
  while (!text.empty()) {
    const std::size_t end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    out_ += fmt::format("{:{}}#{}{}\n", "", indent_, line.empty() ? "" : " ", line);
    if (end == std::string_view::npos) break;
    text.remove_prefix(end + 1);
  }
}

void YamlFieldWriter::BlankLineAtTopLevel() {
  if (indent_ != 0 || out_.empty()) return;
  if (out_.size() >= 2 && out_.compare(out_.size() - 2, 2, "\n\n") == 0) return;
  out_ += '\n';
}

std::string YamlFieldWriter::YamlValue(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  std::string text = fmt::format("{}", value);  // shortest form that reads back exactly
  const std::size_t exponent = text.find_first_of("eE");
  if (text.find('.') == std::string::npos)
    text.insert(exponent == std::string::npos ? text.size() : exponent, ".0");
  return text;
}

std::string YamlFieldWriter::YamlValue(bool value) { return value ? "true" : "false"; }
std::string YamlFieldWriter::YamlValue(int value) { return std::to_string(value); }
std::string YamlFieldWriter::YamlValue(std::uint32_t value) { return std::to_string(value); }
std::string YamlFieldWriter::YamlValue(std::uint64_t value) { return std::to_string(value); }

std::string YamlFieldWriter::YamlValue(const std::string& value) {
  return IsPlainSafe(value) ? value : Quoted(value);
}

std::string YamlFieldWriter::YamlValue(const Eigen::Vector2d& value) {
  return "[" + YamlValue(value.x()) + ", " + YamlValue(value.y()) + "]";
}

std::string YamlFieldWriter::YamlValue(const Eigen::Vector3d& value) {
  return "[" + YamlValue(value.x()) + ", " + YamlValue(value.y()) + ", " + YamlValue(value.z()) + "]";
}

}  // namespace tubepick

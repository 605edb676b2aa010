#include "core/common/yaml_reader.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/common/require.h"

namespace tubepick {
namespace {

template <typename T>
T Convert(const YAML::Node& node, const std::string& path, const char* type_name) {
  if (!node.IsScalar()) throw InvalidArgument(path + ": expected " + type_name);
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw InvalidArgument(path + ": expected " + type_name + ", got '" + node.Scalar() + "'");
  }
}

}  // namespace

YamlMap::YamlMap(const YAML::Node& node, std::string path) : node_(node), path_(std::move(path)) {
  if (node_.IsDefined() && !node_.IsNull() && !node_.IsMap()) {
    throw InvalidArgument((path_.empty() ? std::string("document") : path_) + ": expected a mapping");
  }
}

bool YamlMap::Has(const std::string& key) const {
  const YAML::Node& map = node_;  // const access: operator[] must not insert the key
  return map.IsMap() && map[key].IsDefined();
}

std::optional<YAML::Node> YamlMap::Get(const std::string& key) {
  if (!Has(key)) return std::nullopt;
  used_.insert(key);
  const YAML::Node& map = node_;
  return map[key];
}

YAML::Node YamlMap::Child(const std::string& key) {
  const auto n = Get(key);
  return n ? *n : YAML::Node(YAML::NodeType::Null);
}

void YamlMap::Read(const std::string& key, double& value) {
  const auto n_opt = Get(key);
  if (!n_opt) return;
  const YAML::Node& n = *n_opt;
  value = Convert<double>(n, PathOf(key), "a number");
  RequireFinite(value, PathOf(key));
}

void YamlMap::Read(const std::string& key, bool& value) {
  if (const auto n = Get(key)) value = Convert<bool>(*n, PathOf(key), "true or false");
}

void YamlMap::Read(const std::string& key, int& value) {
  const auto n_opt = Get(key);
  if (!n_opt) return;
  const auto v = Convert<long long>(*n_opt, PathOf(key), "an integer");
  if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max()) {
    throw InvalidArgument(PathOf(key) + ": " + std::to_string(v) +
                          " is out of range [-2147483648, 2147483647]");
  }
  value = static_cast<int>(v);
}

void YamlMap::Read(const std::string& key, std::uint32_t& value) {
  const auto n_opt = Get(key);
  if (!n_opt) return;
  const YAML::Node& n = *n_opt;
  const auto v = Convert<long long>(n, PathOf(key), "a non-negative integer");
  if (v < 0 || v > 0xFFFFFFFFLL) {
    throw InvalidArgument(PathOf(key) + ": " + std::to_string(v) + " is out of range [0, 4294967295]");
  }
  value = static_cast<std::uint32_t>(v);
}

void YamlMap::Read(const std::string& key, std::uint64_t& value) {
  const auto n_opt = Get(key);
  if (!n_opt) return;
  const YAML::Node& n = *n_opt;
  const auto v = Convert<long long>(n, PathOf(key), "a non-negative integer");
  if (v < 0) throw InvalidArgument(PathOf(key) + ": " + std::to_string(v) + " must not be negative");
  value = static_cast<std::uint64_t>(v);
}

void YamlMap::Read(const std::string& key, std::string& value) {
  if (const auto n = Get(key)) value = Convert<std::string>(*n, PathOf(key), "a string");
}

void YamlMap::Read(const std::string& key, Eigen::Vector3d& value) {
  const auto n_opt = Get(key);
  if (!n_opt) return;
  const YAML::Node& n = *n_opt;
  if (!n.IsSequence() || n.size() != 3) throw InvalidArgument(PathOf(key) + ": expected a list of 3 numbers");
  for (int i = 0; i < 3; ++i) {
    value[i] = Convert<double>(n[i], PathOf(key) + "[" + std::to_string(i) + "]", "a number");
    RequireFinite(value[i], PathOf(key));
  }
}

void YamlMap::Read(const std::string& key, Eigen::Vector2d& value) {
  const auto n_opt = Get(key);
  if (!n_opt) return;
  const YAML::Node& n = *n_opt;
  if (!n.IsSequence() || n.size() != 2) throw InvalidArgument(PathOf(key) + ": expected a list of 2 numbers");
  for (int i = 0; i < 2; ++i) {
    value[i] = Convert<double>(n[i], PathOf(key) + "[" + std::to_string(i) + "]", "a number");
    RequireFinite(value[i], PathOf(key));
  }
}

void YamlMap::ReadDegrees(const std::string& key, double& radians) {
  double degrees = radians * 180.0 / M_PI;
  Read(key, degrees);
  radians = degrees * M_PI / 180.0;
}

void YamlMap::RejectUnknown() const {
  if (!node_.IsMap()) return;
  std::string unknown;
  for (const auto& kv : node_) {
    // Our keys are names: a list or a mapping as a key ("[a]: 1", "? {a: 1}") is none of them,
    // and would not convert to a string (yaml-cpp throws its own exception).
    if (!kv.first.IsScalar()) {
      throw InvalidArgument((path_.empty() ? std::string("document") : path_) +
                            ": a key must be a name, got " +
                            (kv.first.IsSequence() ? "a list"
                             : kv.first.IsMap()    ? "a mapping"
                                                   : "no key") +
                            " (line " + std::to_string(kv.first.Mark().line + 1) + ")");
    }
    const std::string key = kv.first.Scalar();
    if (!used_.count(key)) unknown += (unknown.empty() ? "" : ", ") + PathOf(key);
  }
  if (!unknown.empty()) throw InvalidArgument("unknown key(s): " + unknown);
}

YAML::Node ParseYaml(const std::string& text, const std::string& what) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InvalidArgument(what + ": YAML syntax error at line " + std::to_string(e.mark.line + 1) +
                          ", column " + std::to_string(e.mark.column + 1) + ": " + e.msg);
  }
}

std::string ReadTextFile(const std::string& path) {
  // Configs are kilobytes: a path to a device or a huge file is a mistake, not a config to read forever.
  constexpr std::size_t kMaxBytes = 16u << 20;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InvalidArgument("cannot open '" + path + "'");
  std::string text;
  char buffer[65536];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    text.append(buffer, static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxBytes) {
      throw InvalidArgument("'" + path + "' is larger than " + std::to_string(kMaxBytes >> 20) +
                            " MiB: not a config file");
    }
  }
  return text;
}

}  // namespace tubepick

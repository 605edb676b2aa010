#pragma once

#include <optional>
#include <set>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>
#include <Eigen/Core>

#include "core/common/errors.h"

namespace tubepick {

/// Strict reading of a YAML mapping: every key must be consumed, every value has the right type.
/// Errors name the full key path ("modeling.cylinders.min_radius") and the reason. Private to
/// core's config loaders (yaml-cpp does not leak into public headers).
class YamlMap {
 public:
  /// @throws InvalidArgument when `node` is neither a map nor null.
  YamlMap(const YAML::Node& node, std::string path);

  /// Each Read* leaves `value` untouched when the key is absent.
  void Read(const std::string& key, double& value);
  void Read(const std::string& key, bool& value);
  void Read(const std::string& key, int& value);
  void Read(const std::string& key, std::uint32_t& value);
  void Read(const std::string& key, std::uint64_t& value);
  void Read(const std::string& key, std::string& value);
  void Read(const std::string& key, Eigen::Vector3d& value);
  void Read(const std::string& key, Eigen::Vector2d& value);
  /// Reads a value given in degrees (key ends in _deg) into radians.
  void ReadDegrees(const std::string& key, double& radians);

  bool Has(const std::string& key) const;
  /// The sub-node (marked as consumed); a Null node when absent.
  YAML::Node Child(const std::string& key);
  std::string PathOf(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }

  /// @throws InvalidArgument naming every key that was present but never read.
  void RejectUnknown() const;

 private:
  std::optional<YAML::Node> Get(const std::string& key);
  YAML::Node node_;
  std::string path_;
  std::set<std::string> used_;
};

/// Parses YAML text; syntax errors become InvalidArgument with line and column.
YAML::Node ParseYaml(const std::string& text, const std::string& what);
/// Reads a file into a string. @throws InvalidArgument when it cannot be read.
std::string ReadTextFile(const std::string& path);

}  // namespace tubepick

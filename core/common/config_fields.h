#pragma once

// One declaration of a YAML config's fields, from which strict reading, commented dumping and the
// unknown-key check all follow. Private to core's config loaders and the server/cell config files
// (yaml-cpp does not leak into public headers).
//
// A config struct `S` declares its fields once, next to it (found by argument-dependent lookup,
// so in S's namespace):
//
//   template <typename Visitor>
//   void DescribeFields(Visitor& v, S& s) {
//     v("radius", s.radius, "metres");                   // double, bool, integers, string, vectors
//     v.Section("tube", s.tube, "the tubes in the bin");  // nested mapping: DescribeFields(v, s.tube)
//     v.Enum("unit", s.unit, ToText, FromText);           // text names; FromText(text, key path)
//     v.Seconds("robot_timeout", s.robot_timeout);        // milliseconds held, seconds in YAML
//     v.Pose("pose_in_bin", s.X_BinSensor);               // {position, orientation_xyzw}
//     v.Heading("limits");                                // a comment line in dumps only
//   }
//
// ReadFields(YamlMap&, S&) reads with YamlFieldReader (absent keys keep their value, type errors
// and unknown keys name the full key path); DumpFields(S) writes with YamlFieldWriter (every key,
// with their comments, numbers in their shortest exact form) a document that ReadFields reads
// back to the same values (poses through a quaternion and Degrees to round-off, ~1e-15). Range
// checks stay in each struct's Validate(), called once after reading.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <yaml-cpp/yaml.h>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/common/errors.h"
#include "core/common/yaml_reader.h"

namespace tubepick {

/// How a list of std::variant alternatives appears in YAML: every item is a one-key mapping from
/// the alternative's name to its fields, `- random_sample: {count: 40000}`. Each alternative type
/// has its own DescribeFields.
template <typename Variant>
struct VariantListSpec {
  /// Plural noun of the error "<key>: expected a list of <noun>".
  const char* noun;
  /// Example item of the error for a malformed item, e.g. "- random_sample: {count: 40000}".
  const char* example;
  /// The YAML name of an alternative.
  std::string (*name_of)(const Variant&);
  /// The default alternative called `name`. @throws InvalidArgument naming `path` for an unknown
  /// name.
  Variant (*make)(const std::string& name, const std::string& path);
};

/// The visitor that reads the fields of one YAML mapping (a YamlMap) into a struct. Every absent
/// key leaves its field as it is.
class YamlFieldReader {
 public:
  explicit YamlFieldReader(YamlMap& map) : map_(map) {}

  /// A scalar or vector field (the types of YamlMap::Read).
  /// @throws InvalidArgument "<path>: expected ..." for a value of the wrong type.
  template <typename T>
  void operator()(const char* key, T& value, std::string_view /*comment*/ = {}) {
    map_.Read(key, value);
  }

  /// A nested mapping read with DescribeFields(reader, section); its unknown keys are errors.
  /// @throws InvalidArgument "<path>: expected a mapping" when the value is not a mapping (null
  /// keeps the section).
  template <typename T>
  void Section(const char* key, T& section, std::string_view /*comment*/ = {});

  /// A nested mapping that may be absent (kept as it is) or null (nullopt). A mapping is read over
  /// the current value, or over T{} when there is none.
  template <typename T>
  void OptionalSection(const char* key, std::optional<T>& section, std::string_view /*comment*/ = {});

  /// An enum given by its text name. `from_text(text, path)` returns the value or throws
  /// InvalidArgument naming `path`; `to_text` is used by the writer only.
  template <typename E, typename ToText, typename FromText>
  void Enum(const char* key, E& value, ToText /*to_text*/, FromText from_text,
            std::string_view /*comment*/ = {}) {
    if (!map_.Has(key)) return;
    std::string text;
    map_.Read(key, text);
    value = from_text(text, map_.PathOf(key));
  }

  /// A duration held in milliseconds, given in seconds (rounded to the millisecond).
  /// @throws InvalidArgument when |seconds| > 1e9.
  void Seconds(const char* key, std::chrono::milliseconds& value, std::string_view comment = {});

  /// An angle held in radians, given in degrees.
  void Degrees(const char* key, double& radians, std::string_view comment = {});

  /// A pose {position: [x, y, z], orientation_xyzw: [x, y, z, w]}; either key may be left out and
  /// keeps its part of `pose`.
  /// @throws InvalidArgument for a quaternion that is not unit length (within 1e-3).
  void Pose(const char* key, Eigen::Isometry3d& pose, std::string_view comment = {});

  /// A pose that may be absent (kept as it is) or null (nullopt); a mapping needs both position and
  /// orientation_xyzw. @throws InvalidArgument as Pose, or when a part is missing.
  void OptionalPose(const char* key, std::optional<Eigen::Isometry3d>& pose, std::string_view comment = {});

  /// A list of variant alternatives (VariantListSpec); a given list replaces `list` entirely.
  template <typename Variant>
  void VariantList(const char* key, std::vector<Variant>& list, const VariantListSpec<Variant>& spec,
                   std::string_view /*comment*/ = {});

  /// A comment line between fields in dumps; nothing to read.
  void Heading(std::string_view /*text*/) {}

 private:
  YamlMap& map_;
};

/// Reads the fields DescribeFields(reader, value) declares from `map`, then rejects the keys of
/// `map` that no field claimed.
/// @throws InvalidArgument naming the key path of a wrong type or of the unknown keys.
template <typename T>
void ReadFields(YamlMap& map, T& value) {
  YamlFieldReader reader(map);
  DescribeFields(reader, value);
  map.RejectUnknown();
}

/// Parses YAML text (syntax errors name `what`) and reads it over `value` with ReadFields.
/// @throws InvalidArgument as ParseYaml and ReadFields.
template <typename T>
void ParseFields(const std::string& yaml_text, const std::string& what, T& value) {
  const YAML::Node root = ParseYaml(yaml_text, what);
  YamlMap top(root, "");
  ReadFields(top, value);
}

/// The visitor that writes every declared field as block YAML, top-level sections separated by a
/// blank line. A field's comment follows it on its line when short (one line, the line within 100
/// characters), else stands on the lines above it.
class YamlFieldWriter {
 public:
  YamlFieldWriter() = default;

  /// Writes `key: value` (YamlValue), after `comment`.
  template <typename T>
  void operator()(const char* key, T& value, std::string_view comment = {}) {
    Line(key, YamlValue(value), comment);
  }

  /// Writes `key:` and the fields of `section` indented below it (`key: {}` when it has none).
  template <typename T>
  void Section(const char* key, T& section, std::string_view comment = {}) {
    YamlFieldWriter body(indent_ + 2);
    DescribeFields(body, section);
    Block(key, body.out_, comment);
  }

  /// Writes the section, or `key: null` for nullopt.
  template <typename T>
  void OptionalSection(const char* key, std::optional<T>& section, std::string_view comment = {}) {
    if (section) {
      Section(key, *section, comment);
    } else {
      Line(key, "null", comment);
    }
  }

  /// Writes `key: to_text(value)`.
  template <typename E, typename ToText, typename FromText>
  void Enum(const char* key, E& value, ToText to_text, FromText /*from_text*/,
            std::string_view comment = {}) {
    Line(key, YamlValue(std::string(to_text(value))), comment);
  }

  /// Writes the duration in seconds.
  void Seconds(const char* key, std::chrono::milliseconds& value, std::string_view comment = {});
  /// Writes the angle in degrees.
  void Degrees(const char* key, double& radians, std::string_view comment = {});
  /// Writes {position, orientation_xyzw}; quaternion components below 1e-15 are written as 0.
  void Pose(const char* key, Eigen::Isometry3d& pose, std::string_view comment = {});
  /// Writes the pose, or `key: null` for nullopt.
  void OptionalPose(const char* key, std::optional<Eigen::Isometry3d>& pose, std::string_view comment = {});

  /// Writes one `- name:` item per element with its fields below it (`key: []` when empty).
  template <typename Variant>
  void VariantList(const char* key, std::vector<Variant>& list, const VariantListSpec<Variant>& spec,
                   std::string_view comment = {});

  /// A comment line (lines at '\n'), after a blank line at the top level.
  void Heading(std::string_view text);

  /// The YAML written so far, after `header` as comment lines and a blank line (no header: none).
  std::string Document(std::string_view header = {}) const;

  /// YAML text of a value: numbers in their shortest exact form (doubles always with a decimal
  /// point), flow lists for vectors, strings plain when that is unambiguous, else quoted.
  static std::string YamlValue(double value);
  static std::string YamlValue(bool value);
  static std::string YamlValue(int value);
  static std::string YamlValue(std::uint32_t value);
  static std::string YamlValue(std::uint64_t value);
  static std::string YamlValue(const std::string& value);
  static std::string YamlValue(const Eigen::Vector2d& value);
  static std::string YamlValue(const Eigen::Vector3d& value);

 private:
  explicit YamlFieldWriter(int indent) : indent_(indent) {}
  /// `key: value` and its comment.
  void Line(std::string_view key, std::string_view value, std::string_view comment);
  /// `key:` and its comment, the already indented `body` below it (`key: {}` when empty).
  void Block(std::string_view key, const std::string& body, std::string_view comment);
  /// `line`, with `comment` after it when it is one short line, else on the lines above.
  void Annotated(const std::string& line, std::string_view comment);
  /// One item `- name:` of a variant list and its already indented fields.
  void ListItem(std::string_view name, const std::string& fields);
  void Comment(std::string_view text);
  void BlankLineAtTopLevel();

  int indent_ = 0;
  std::string out_;
};

/// Every field DescribeFields(writer, value) declares, as a commented YAML document that
/// ParseFields reads back to `value`; `header` comes first as comment lines.
template <typename T>
std::string DumpFields(T value, std::string_view header = {}) {
  YamlFieldWriter writer;
  DescribeFields(writer, value);
  return writer.Document(header);
}

// ---- template definitions ---------------------------------------------------------------------

template <typename T>
void YamlFieldReader::Section(const char* key, T& section, std::string_view) {
  YamlMap child(map_.Child(key), map_.PathOf(key));
  ReadFields(child, section);
}

template <typename T>
void YamlFieldReader::OptionalSection(const char* key, std::optional<T>& section, std::string_view) {
  if (!map_.Has(key)) return;
  const YAML::Node node = map_.Child(key);
  if (node.IsNull()) {
    section.reset();
    return;
  }
  T value = section.value_or(T{});
  YamlMap child(node, map_.PathOf(key));
  ReadFields(child, value);
  section = std::move(value);
}

template <typename Variant>
void YamlFieldReader::VariantList(const char* key, std::vector<Variant>& list,
                                  const VariantListSpec<Variant>& spec, std::string_view) {
  if (!map_.Has(key)) return;
  const YAML::Node items = map_.Child(key);
  const std::string path = map_.PathOf(key);
  if (!items.IsSequence()) throw InvalidArgument(path + ": expected a list of " + spec.noun);
  std::vector<Variant> result;
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string item_path = path + "[" + std::to_string(i) + "]";
    const YAML::Node item = items[i];
    if (!item.IsMap() || item.size() != 1) {
      throw InvalidArgument(item_path + ": expected a one-key mapping such as '" + spec.example + "'");
    }
    const std::string name = item.begin()->first.as<std::string>();
    Variant alternative = spec.make(name, item_path);
    YamlMap fields(item.begin()->second, item_path + "." + name);
    std::visit([&fields](auto& a) { ReadFields(fields, a); }, alternative);
    result.push_back(std::move(alternative));
  }
  list = std::move(result);
}

template <typename Variant>
void YamlFieldWriter::VariantList(const char* key, std::vector<Variant>& list,
                                  const VariantListSpec<Variant>& spec, std::string_view comment) {
  if (list.empty()) {
    Line(key, "[]", comment);
    return;
  }
  YamlFieldWriter items(indent_ + 2);
  for (Variant& item : list) {
    YamlFieldWriter fields(indent_ + 6);
    std::visit([&fields](auto& a) { DescribeFields(fields, a); }, item);
    items.ListItem(spec.name_of(item), fields.out_);
  }
  Block(key, items.out_, comment);
}

}  // namespace tubepick

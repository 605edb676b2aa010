#include "core/params.h"

#include <cmath>
#include <sstream>
#include <type_traits>

#include <yaml-cpp/yaml.h>

#include "core/common/errors.h"
#include "core/common/yaml_reader.h"
#include "core/params_sections.h"

namespace tubepick {
namespace {

// ---- enums <-> text -------------------------------------------------------------------------

const char* AxisName(Axis a) { return a == Axis::kX ? "x" : a == Axis::kY ? "y" : "z"; }
Axis ParseAxis(const std::string& s, const std::string& key) {
  if (s == "x") return Axis::kX;
  if (s == "y") return Axis::kY;
  if (s == "z") return Axis::kZ;
  throw InvalidArgument(key + ": unknown axis '" + s + "' (expected x, y or z)");
}
const char* FrameName(FilterFrame f) { return f == FilterFrame::kBin ? "bin" : "sensor"; }
FilterFrame ParseFrame(const std::string& s, const std::string& key) {
  if (s == "bin") return FilterFrame::kBin;
  if (s == "sensor") return FilterFrame::kSensor;
  throw InvalidArgument(key + ": unknown frame '" + s + "' (expected bin or sensor)");
}
const char* SurfaceName(SearchSurface s) { return s == SearchSurface::kRaw ? "raw" : "filtered"; }
SearchSurface ParseSurface(const std::string& s, const std::string& key) {
  if (s == "raw") return SearchSurface::kRaw;
  if (s == "filtered") return SearchSurface::kFiltered;
  throw InvalidArgument(key + ": unknown search surface '" + s + "' (expected raw or filtered)");
}
const char* StrategyName(JoiningStrategy s) { return s == JoiningStrategy::kGreedy ? "greedy" : "global"; }
JoiningStrategy ParseStrategy(const std::string& s, const std::string& key) {
  if (s == "greedy") return JoiningStrategy::kGreedy;
  if (s == "global") return JoiningStrategy::kGlobal;
  throw InvalidArgument(key + ": unknown strategy '" + s + "' (expected greedy or global)");
}

// ---- reading ----------------------------------------------------------------------------------

struct FilterReader {
  YamlMap& m;
  void operator()(CropBoxParams& p) const {
    m.Read("from_bin", p.from_bin);
    m.Read("inset_xy", p.inset_xy);
    m.Read("min_z", p.min_z);
    m.Read("above_walls", p.above_walls);
    m.Read("min", p.min);
    m.Read("max", p.max);
  }
  void operator()(PassThroughParams& p) const {
    std::string axis = AxisName(p.axis), frame = FrameName(p.frame);
    m.Read("axis", axis);
    m.Read("frame", frame);
    p.axis = ParseAxis(axis, m.PathOf("axis"));
    p.frame = ParseFrame(frame, m.PathOf("frame"));
    m.Read("min", p.min);
    m.Read("max", p.max);
  }
  void operator()(VoxelGridParams& p) const { m.Read("leaf_size", p.leaf_size); }
  void operator()(RandomSampleParams& p) const { m.Read("count", p.count); }
  void operator()(RadiusOutlierParams& p) const {
    m.Read("radius", p.radius);
    m.Read("min_neighbours", p.min_neighbours);
  }
  void operator()(StatisticalOutlierParams& p) const {
    m.Read("neighbours", p.neighbours);
    m.Read("stddev_mult", p.stddev_mult);
  }
  void operator()(PlaneRemovalParams& p) const {
    m.Read("distance_threshold", p.distance_threshold);
    m.Read("normal_distance_weight", p.normal_distance_weight);
    m.Read("axis", p.axis);
    m.Read("eps_angle", p.eps_angle);
    m.Read("max_iterations", p.max_iterations);
    m.Read("probability", p.probability);
    m.Read("min_inliers", p.min_inliers);
  }
};

FilterStep DefaultFilter(const std::string& name, const std::string& key) {
  if (name == "crop_box") return CropBoxParams{};
  if (name == "pass_through") return PassThroughParams{};
  if (name == "voxel_grid") return VoxelGridParams{};
  if (name == "random_sample") return RandomSampleParams{};
  if (name == "radius_outlier") return RadiusOutlierParams{};
  if (name == "statistical_outlier") return StatisticalOutlierParams{};
  if (name == "plane_removal") return PlaneRemovalParams{};
  throw InvalidArgument(key + ": unknown filter '" + name +
                        "' (expected crop_box, pass_through, voxel_grid, random_sample, radius_outlier, "
                        "statistical_outlier or plane_removal)");
}

std::vector<FilterStep> ReadFilters(const YAML::Node& list, const std::string& path) {
  if (!list.IsSequence()) throw InvalidArgument(path + ": expected a list of filters");
  std::vector<FilterStep> filters;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string key = path + "[" + std::to_string(i) + "]";
    const YAML::Node item = list[i];
    if (!item.IsMap() || item.size() != 1) {
      throw InvalidArgument(key + ": expected a one-key mapping such as '- random_sample: {count: 40000}'");
    }
    const std::string name = item.begin()->first.as<std::string>();
    FilterStep step = DefaultFilter(name, key);
    YamlMap fields(item.begin()->second, key + "." + name);
    std::visit(FilterReader{fields}, step);
    fields.RejectUnknown();
    filters.push_back(step);
  }
  return filters;
}

void ReadModeling(YamlMap& m, ModelingParams& p) {
  m.Read("threads", p.threads);
  if (m.Has("filters")) p.filters = ReadFilters(m.Child("filters"), m.PathOf("filters"));
  {
    YamlMap n(m.Child("normals"), m.PathOf("normals"));
    n.Read("radius", p.normals.radius);
    n.Read("max_neighbours", p.normals.max_neighbours);
    std::string surface = SurfaceName(p.normals.search_surface);
    n.Read("search_surface", surface);
    p.normals.search_surface = ParseSurface(surface, n.PathOf("search_surface"));
    n.RejectUnknown();
  }
  {
    YamlMap s(m.Child("segmentation"), m.PathOf("segmentation"));
    auto& q = p.segmentation;
    s.Read("min_cluster_size", q.min_cluster_size);
    s.Read("max_cluster_size", q.max_cluster_size);
    s.Read("neighbours", q.neighbours);
    s.Read("smoothness_threshold", q.smoothness_threshold);
    s.Read("curvature_threshold", q.curvature_threshold);
    s.Read("residual_test", q.residual_test);
    s.Read("residual_threshold", q.residual_threshold);
    s.RejectUnknown();
  }
  {
    YamlMap c(m.Child("cylinders"), m.PathOf("cylinders"));
    auto& q = p.cylinders;
    c.Read("min_inliers", q.min_inliers);
    c.Read("min_radius", q.min_radius);
    c.Read("max_radius", q.max_radius);
    c.Read("distance_threshold", q.distance_threshold);
    c.Read("normal_distance_weight", q.normal_distance_weight);
    c.Read("max_iterations", q.max_iterations);
    c.Read("probability", q.probability);
    c.Read("safety_length", q.safety_length);
    c.Read("safety_radius", q.safety_radius);
    c.Read("refine", q.refine);
    c.RejectUnknown();
  }
  {
    YamlMap j(m.Child("joining"), m.PathOf("joining"));
    auto& q = p.joining;
    j.Read("max_distance", q.max_distance);
    j.Read("max_angle", q.max_angle);
    j.Read("angular_weight", q.angular_weight);
    j.Read("max_tube_length", q.max_tube_length);
    j.Read("radius_shortcut", q.radius_shortcut);
    j.Read("visibility_check", q.visibility_check);
    j.Read("visibility_pixel_angle", q.visibility_pixel_angle);
    j.Read("visibility_window", q.visibility_window);
    j.Read("visibility_min_gap", q.visibility_min_gap);
    std::string strategy = StrategyName(q.strategy);
    j.Read("strategy", strategy);
    q.strategy = ParseStrategy(strategy, j.PathOf("strategy"));
    j.RejectUnknown();
  }
  m.RejectUnknown();
}

// ---- writing ----------------------------------------------------------------------------------

void EmitVector(YAML::Emitter& e, const char* key, const Eigen::Vector3d& v) {
  e << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq << v.x() << v.y() << v.z()
    << YAML::EndSeq;
}

struct FilterWriter {
  YAML::Emitter& e;
  void operator()(const CropBoxParams& p) const {
    e << YAML::Key << "from_bin" << YAML::Value << p.from_bin;
    e << YAML::Key << "inset_xy" << YAML::Value << p.inset_xy;
    e << YAML::Key << "min_z" << YAML::Value << p.min_z;
    e << YAML::Key << "above_walls" << YAML::Value << p.above_walls;
    EmitVector(e, "min", p.min);
    EmitVector(e, "max", p.max);
  }
  void operator()(const PassThroughParams& p) const {
    e << YAML::Key << "axis" << YAML::Value << AxisName(p.axis);
    e << YAML::Key << "frame" << YAML::Value << FrameName(p.frame);
    e << YAML::Key << "min" << YAML::Value << p.min;
    e << YAML::Key << "max" << YAML::Value << p.max;
  }
  void operator()(const VoxelGridParams& p) const {
    e << YAML::Key << "leaf_size" << YAML::Value << p.leaf_size;
  }
  void operator()(const RandomSampleParams& p) const { e << YAML::Key << "count" << YAML::Value << p.count; }
  void operator()(const RadiusOutlierParams& p) const {
    e << YAML::Key << "radius" << YAML::Value << p.radius;
    e << YAML::Key << "min_neighbours" << YAML::Value << p.min_neighbours;
  }
  void operator()(const StatisticalOutlierParams& p) const {
    e << YAML::Key << "neighbours" << YAML::Value << p.neighbours;
    e << YAML::Key << "stddev_mult" << YAML::Value << p.stddev_mult;
  }
  void operator()(const PlaneRemovalParams& p) const {
    e << YAML::Key << "distance_threshold" << YAML::Value << p.distance_threshold;
    e << YAML::Key << "normal_distance_weight" << YAML::Value << p.normal_distance_weight;
    EmitVector(e, "axis", p.axis);
    e << YAML::Key << "eps_angle" << YAML::Value << p.eps_angle;
    e << YAML::Key << "max_iterations" << YAML::Value << p.max_iterations;
    e << YAML::Key << "probability" << YAML::Value << p.probability;
    e << YAML::Key << "min_inliers" << YAML::Value << p.min_inliers;
  }
};

void EmitModeling(YAML::Emitter& e, const ModelingParams& p) {
  e << YAML::BeginMap;
  e << YAML::Key << "threads" << YAML::Value << p.threads;
  e << YAML::Key << "filters" << YAML::Value << YAML::BeginSeq;
  for (const FilterStep& step : p.filters) {
    e << YAML::BeginMap << YAML::Key << FilterName(step) << YAML::Value << YAML::Flow << YAML::BeginMap;
    std::visit(FilterWriter{e}, step);
    e << YAML::EndMap << YAML::EndMap;
  }
  e << YAML::EndSeq;

  e << YAML::Key << "normals" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "radius" << YAML::Value << p.normals.radius;
  e << YAML::Key << "max_neighbours" << YAML::Value << p.normals.max_neighbours;
  e << YAML::Key << "search_surface" << YAML::Value << SurfaceName(p.normals.search_surface);
  e << YAML::EndMap;

  const auto& s = p.segmentation;
  e << YAML::Key << "segmentation" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "min_cluster_size" << YAML::Value << s.min_cluster_size;
  e << YAML::Key << "max_cluster_size" << YAML::Value << s.max_cluster_size;
  e << YAML::Key << "neighbours" << YAML::Value << s.neighbours;
  e << YAML::Key << "smoothness_threshold" << YAML::Value << s.smoothness_threshold
    << YAML::Comment("radians");
  e << YAML::Key << "curvature_threshold" << YAML::Value << s.curvature_threshold;
  e << YAML::Key << "residual_test" << YAML::Value << s.residual_test;
  e << YAML::Key << "residual_threshold" << YAML::Value << s.residual_threshold;
  e << YAML::EndMap;

  const auto& c = p.cylinders;
  e << YAML::Key << "cylinders" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "min_inliers" << YAML::Value << c.min_inliers;
  e << YAML::Key << "min_radius" << YAML::Value << c.min_radius;
  e << YAML::Key << "max_radius" << YAML::Value << c.max_radius;
  e << YAML::Key << "distance_threshold" << YAML::Value << c.distance_threshold;
  e << YAML::Key << "normal_distance_weight" << YAML::Value << c.normal_distance_weight;
  e << YAML::Key << "max_iterations" << YAML::Value << c.max_iterations;
  e << YAML::Key << "probability" << YAML::Value << c.probability;
  e << YAML::Key << "safety_length" << YAML::Value << c.safety_length << YAML::Comment("epsilon_delta_l");
  e << YAML::Key << "safety_radius" << YAML::Value << c.safety_radius << YAML::Comment("epsilon_r");
  e << YAML::Key << "refine" << YAML::Value << c.refine;
  e << YAML::EndMap;

  const auto& j = p.joining;
  e << YAML::Key << "joining" << YAML::Value << YAML::BeginMap;
  e << YAML::Key << "max_distance" << YAML::Value << j.max_distance;
  e << YAML::Key << "max_angle" << YAML::Value << j.max_angle << YAML::Comment("radians");
  e << YAML::Key << "angular_weight" << YAML::Value << j.angular_weight << YAML::Comment("metres per radian");
  e << YAML::Key << "max_tube_length" << YAML::Value << j.max_tube_length;
  e << YAML::Key << "radius_shortcut" << YAML::Value << j.radius_shortcut;
  e << YAML::Key << "visibility_check" << YAML::Value << j.visibility_check;
  e << YAML::Key << "visibility_pixel_angle" << YAML::Value << j.visibility_pixel_angle;
  e << YAML::Key << "visibility_window" << YAML::Value << j.visibility_window;
  e << YAML::Key << "visibility_min_gap" << YAML::Value << j.visibility_min_gap;
  e << YAML::Key << "strategy" << YAML::Value << StrategyName(j.strategy);
  e << YAML::EndMap;
  e << YAML::EndMap;
}

// ---- planning / wrench / placement: one field list (params_sections.h), two visitors ---------

struct SectionReader {
  YamlMap& m;
  template <typename T>
  void operator()(const char* key, T& value) {
    m.Read(key, value);
  }
  template <typename T>
  void Section(const char* key, T& section) {
    YamlMap child(m.Child(key), m.PathOf(key));
    SectionReader reader{child};
    internal::DescribeFields(reader, section);
    child.RejectUnknown();
  }
  template <typename E, typename ToText, typename FromText>
  void Enum(const char* key, E& value, ToText to_text, FromText from_text) {
    std::string text = to_text(value);
    m.Read(key, text);
    value = from_text(text, m.PathOf(key));
  }
};

struct SectionWriter {
  YAML::Emitter& e;
  template <typename T>
  void operator()(const char* key, T& value) {
    if constexpr (std::is_same_v<T, Eigen::Vector3d>) {
      EmitVector(e, key, value);
    } else {
      e << YAML::Key << key << YAML::Value << value;
    }
  }
  template <typename T>
  void Section(const char* key, T& section) {
    e << YAML::Key << key << YAML::Value << YAML::BeginMap;
    internal::DescribeFields(*this, section);
    e << YAML::EndMap;
  }
  template <typename E, typename ToText, typename FromText>
  void Enum(const char* key, E& value, ToText to_text, FromText) {
    e << YAML::Key << key << YAML::Value << to_text(value);
  }
};

template <typename T>
void ReadSection(YamlMap& top, const char* key, T& section) {
  SectionReader reader{top};
  reader.Section(key, section);
}

template <typename T>
void WriteSection(YAML::Emitter& e, const char* key, T section) {
  SectionWriter writer{e};
  writer.Section(key, section);
}

}  // namespace

void Params::Validate() const {
  modeling.Validate();
  planning.Validate();
  wrench.Validate();
  placement.Validate();
}

std::vector<std::string> ProfileNames() { return {"fast", "thesis"}; }

Params ProfileParams(const std::string& name) {
  Params p;
  if (name == "fast") {
    p.modeling = FastModelingProfile();
  } else if (name == "thesis") {
    p.modeling = ThesisModelingProfile();
  } else {
    throw InvalidArgument("profile: unknown profile '" + name + "' (expected fast or thesis)");
  }
  return p;
}

Params ParseParams(const std::string& yaml_text, const Params& base) {
  const YAML::Node root = ParseYaml(yaml_text, "params");
  YamlMap top(root, "");
  Params p = base;
  {
    YamlMap m(top.Child("modeling"), "modeling");
    ReadModeling(m, p.modeling);
  }
  ReadSection(top, "planning", p.planning);
  ReadSection(top, "wrench", p.wrench);
  ReadSection(top, "placement", p.placement);
  top.RejectUnknown();
  p.Validate();
  return p;
}

Params LoadParams(const std::string& path, const Params& base) {
  try {
    return ParseParams(ReadTextFile(path), base);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("params '" + path + "': " + e.what());
  }
}

std::string DumpParams(const Params& params) {
  YAML::Emitter e;
  e.SetDoublePrecision(9);
  e << YAML::BeginMap << YAML::Key << "modeling" << YAML::Value;
  EmitModeling(e, params.modeling);
  WriteSection(e, "planning", params.planning);
  WriteSection(e, "wrench", params.wrench);
  WriteSection(e, "placement", params.placement);
  e << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

}  // namespace tubepick

#include "clients/cell/cell_controller_config.h"

#include <fmt/core.h>

#include <cmath>
#include <string_view>

#include "core/common/errors.h"
#include "core/common/require.h"
#include "core/common/yaml_reader.h"

namespace tubepick::cell {
namespace {

struct VariantName {
  v1::ResolutionVariant variant;
  const char* name;
};
constexpr VariantName kVariants[] = {
    {v1::RESOLUTION_VARIANT_UNSPECIFIED, "unspecified"},
    {v1::RESOLUTION_VARIANT_TORQUE_AXIS, "torque_axis"},
    {v1::RESOLUTION_VARIANT_TORQUE_AXIS_NEGATIVE, "torque_axis_negative"},
    {v1::RESOLUTION_VARIANT_PERPENDICULAR, "perpendicular"},
    {v1::RESOLUTION_VARIANT_JOINT_SAFE, "joint_safe"},
};

std::string VariantToName(v1::ResolutionVariant variant) {
  for (const VariantName& v : kVariants)
    if (v.variant == variant) return v.name;
  return fmt::format("{}", static_cast<int>(variant));
}

v1::ResolutionVariant VariantFromName(const std::string& name, const std::string& path) {
  for (const VariantName& v : kVariants)
    if (name == v.name) return v.variant;
  throw InvalidArgument(fmt::format(
      "{}: unknown variant '{}' (unspecified, torque_axis, torque_axis_negative, perpendicular, joint_safe)",
      path, name));
}

/// Seconds in YAML, milliseconds in the struct.
void ReadSeconds(YamlMap& map, const std::string& key, std::chrono::milliseconds& value) {
  double seconds = static_cast<double>(value.count()) / 1000.0;
  map.Read(key, seconds);  // finite or throws
  if (std::abs(seconds) > 1e9)
    throw InvalidArgument(fmt::format("{}: {} s is out of range (at most 1e9 s)", map.PathOf(key), seconds));
  value = std::chrono::milliseconds(std::llround(seconds * 1000.0));
}

std::optional<Eigen::Isometry3d> ReadOptionalPose(YamlMap& parent, const std::string& key) {
  const YAML::Node node = parent.Child(key);
  if (!node || node.IsNull()) return std::nullopt;
  YamlMap map(node, parent.PathOf(key));
  if (!map.Has("position") || !map.Has("orientation_xyzw"))
    throw InvalidArgument(parent.PathOf(key) +
                          ": needs position and orientation_xyzw (or null for the default)");
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  map.Read("position", position);
  const std::string q_path = map.PathOf("orientation_xyzw");
  const YAML::Node q = map.Child("orientation_xyzw");
  if (!q.IsSequence() || q.size() != 4)
    throw InvalidArgument(q_path + ": expected a list of 4 numbers (x, y, z, w)");
  Eigen::Vector4d xyzw;
  for (int i = 0; i < 4; ++i) {
    try {
      xyzw[i] = q[i].as<double>();
    } catch (const YAML::Exception&) {
      throw InvalidArgument(q_path + ": expected numbers");
    }
    RequireFinite(xyzw[i], q_path);
  }
  map.RejectUnknown();
  if (std::abs(xyzw.norm() - 1.0) > 1e-3)
    throw InvalidArgument(fmt::format("{}: quaternion must be unit length, |q| = {}", q_path, xyzw.norm()));
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond(xyzw[3], xyzw[0], xyzw[1], xyzw[2]).normalized().toRotationMatrix();
  X.translation() = position;
  return X;
}

void ReadTool(YamlMap& parent, ToolGeometry& tool) {
  YamlMap map(parent.Child("tool"), parent.PathOf("tool"));
  map.Read("finger_size", tool.finger_size);
  map.Read("finger_tip_depth", tool.finger_tip_depth);
  map.Read("housing_size", tool.housing_size);
  map.Read("housing_gap", tool.housing_gap);
  map.Read("margin", tool.margin);
  map.RejectUnknown();
}

void ReadNudge(YamlMap& parent, NudgeParams& nudge) {
  YamlMap map(parent.Child("nudge"), parent.PathOf("nudge"));
  map.Read("enabled", nudge.enabled);
  map.Read("max_nudges_per_bin", nudge.max_nudges_per_bin);
  map.Read("near_wall_distance", nudge.near_wall_distance);
  map.Read("target_wall_distance", nudge.target_wall_distance);
  map.Read("push_gain", nudge.push_gain);
  map.Read("min_push", nudge.min_push);
  map.Read("max_push", nudge.max_push);
  map.Read("press_depth", nudge.press_depth);
  map.Read("tilt", nudge.tilt);
  map.Read("speed", nudge.speed);
  map.Read("sample_spacing", nudge.sample_spacing);
  map.RejectUnknown();
}

// --- dump -------------------------------------------------------------------------------------

std::string Num(double v) { return fmt::format("{}", v); }
std::string Vec(const Eigen::Vector3d& v) { return fmt::format("[{}, {}, {}]", v.x(), v.y(), v.z()); }
std::string Seconds(std::chrono::milliseconds v) { return Num(static_cast<double>(v.count()) / 1000.0); }

std::string Quoted(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

class Writer {
 public:
  void Comment(std::string_view text) { out_ += fmt::format("{}# {}\n", indent_, text); }
  void Line(std::string_view key, const std::string& value, std::string_view comment = {}) {
    out_ += fmt::format("{}{}: {}", indent_, key, value);
    if (!comment.empty()) out_ += fmt::format("  # {}", comment);
    out_ += '\n';
  }
  void Begin(std::string_view key, std::string_view comment = {}) {
    out_ += fmt::format("{}{}:", indent_, key);
    if (!comment.empty()) out_ += fmt::format("  # {}", comment);
    out_ += '\n';
    indent_ += "  ";
  }
  void End() { indent_.resize(indent_.size() - 2); }
  void Blank() { out_ += '\n'; }
  std::string str() const { return out_; }

 private:
  std::string out_;
  std::string indent_;
};

}  // namespace

CellControllerParams ParseCellControllerParams(const std::string& yaml_text) {
  const YAML::Node root = ParseYaml(yaml_text, "cell controller config");
  YamlMap top(root, "");
  CellControllerParams p;
  top.Read("transit_speed", p.transit_speed);
  top.Read("approach_speed", p.approach_speed);
  top.Read("lift_speed", p.lift_speed);
  top.Read("resolution_speed", p.resolution_speed);
  top.Read("approach_height", p.approach_height);
  top.Read("transit_clearance", p.transit_clearance);
  top.Read("release_height", p.release_height);
  top.Read("place_approach_height", p.place_approach_height);
  p.X_BinHome = ReadOptionalPose(top, "home_pose_in_bin");
  top.Read("check_tool_clearance", p.check_tool_clearance);
  ReadTool(top, p.tool);
  ReadNudge(top, p.nudge);
  top.Read("gripper_speed", p.gripper_speed);
  top.Read("gripper_force", p.gripper_force);
  top.Read("ft_settle_samples", p.ft_settle_samples);
  top.Read("ft_samples", p.ft_samples);
  top.Read("profile", p.profile);
  top.Read("seed", p.seed);
  top.Read("max_plans", p.max_plans);
  top.Read("max_plans_per_scan", p.max_plans_per_scan);
  top.Read("disable_simulation", p.disable_simulation);
  std::string variant = VariantToName(p.resolution_variant);
  top.Read("resolution_variant", variant);
  p.resolution_variant = VariantFromName(variant, "resolution_variant");
  ReadSeconds(top, "plan_deadline", p.plan_deadline);
  ReadSeconds(top, "analyze_deadline", p.analyze_deadline);
  top.Read("max_attempts_per_tube", p.max_attempts_per_tube);
  top.Read("max_attempts_per_bin", p.max_attempts_per_bin);
  top.Read("max_consecutive_failures", p.max_consecutive_failures);
  ReadSeconds(top, "scanner_timeout", p.scanner_timeout);
  ReadSeconds(top, "robot_timeout", p.robot_timeout);
  ReadSeconds(top, "gripper_timeout", p.gripper_timeout);
  ReadSeconds(top, "ft_timeout", p.ft_timeout);
  top.RejectUnknown();
  p.Validate();
  return p;
}

CellControllerParams LoadCellControllerParams(const std::string& path) {
  try {
    return ParseCellControllerParams(ReadTextFile(path));
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(fmt::format("cell controller config '{}': {}", path, e.what()));
  }
}

std::string DumpCellControllerParams(const CellControllerParams& p) {
  Writer w;
  w.Comment("Cell controller parameters (tubepick cell --controller FILE). Units: metres, m/s, N, radians;");
  w.Comment("durations (*_timeout, *_deadline) in seconds. Absent keys keep their defaults; unknown keys");
  w.Comment("are errors. Bin frame: z up from the floor, TCP z down along the approach.");
  w.Blank();
  w.Comment("motion");
  w.Line("transit_speed", Num(p.transit_speed), "m/s, free moves (home, transit, above the place)");
  w.Line("approach_speed", Num(p.approach_speed), "m/s, pre-grasp -> grasp, above place -> place");
  w.Line("lift_speed", Num(p.lift_speed), "m/s, along the plan's waypoints after the grasp");
  w.Line("resolution_speed", Num(p.resolution_speed), "m/s of the TCP, resolution rotations");
  w.Line("approach_height", Num(p.approach_height), "m, pre-grasp back from the grasp");
  w.Line("transit_clearance", Num(p.transit_clearance), "m above the bin's wall top");
  w.Line("release_height", Num(p.release_height), "m above the grasp to put back several tubes");
  w.Line("place_approach_height", Num(p.place_approach_height), "m above the place pose");
  if (p.X_BinHome) {
    const Eigen::Quaterniond q(p.X_BinHome->linear());
    w.Begin("home_pose_in_bin", "where the robot waits while the bin is scanned");
    w.Line("position", Vec(p.X_BinHome->translation()));
    w.Line("orientation_xyzw", fmt::format("[{}, {}, {}, {}]", q.x(), q.y(), q.z(), q.w()));
    w.End();
  } else {
    w.Line("home_pose_in_bin", "null", "null: above the place frame at transit height, TCP down");
  }
  w.Line("check_tool_clearance", p.check_tool_clearance ? "true" : "false",
         "skip plans whose tool path touches a wall or the floor");
  w.Begin("tool", "tool boxes in the TCP frame, m (the planner's planning.tool)");
  w.Line("finger_size", Vec(p.tool.finger_size), "one pad: along the tube, closing, height");
  w.Line("finger_tip_depth", Num(p.tool.finger_tip_depth), "tips past the TCP along z_Tcp");
  w.Line("housing_size", Vec(p.tool.housing_size));
  w.Line("housing_gap", Num(p.tool.housing_gap), "housing bottom above the pads' top");
  w.Line("margin", Num(p.tool.margin), "kept from the bin's walls and floor");
  w.End();
  w.Begin("nudge", "drag a tube off a wall when no plan is executable");
  w.Line("enabled", p.nudge.enabled ? "true" : "false");
  w.Line("max_nudges_per_bin", fmt::format("{}", p.nudge.max_nudges_per_bin));
  w.Line("near_wall_distance", Num(p.nudge.near_wall_distance), "m, a tube closer to a wall is along it");
  w.Line("target_wall_distance", Num(p.nudge.target_wall_distance), "m from the wall after the push");
  w.Line("push_gain", Num(p.nudge.push_gain), "push = gain * (target - distance), clamped:");
  w.Line("min_push", Num(p.nudge.min_push), "m");
  w.Line("max_push", Num(p.nudge.max_push), "m");
  w.Line("press_depth", Num(p.nudge.press_depth), "m of the pads below the tube's top");
  w.Line("tilt", Num(p.nudge.tilt), "rad from the vertical, tips towards the wall");
  w.Line("speed", Num(p.nudge.speed), "m/s");
  w.Line("sample_spacing", Num(p.nudge.sample_spacing), "m along the tube");
  w.End();
  w.Blank();
  w.Comment("gripper");
  w.Line("gripper_speed", Num(p.gripper_speed), "m/s closing");
  w.Line("gripper_force", Num(p.gripper_force), "N");
  w.Blank();
  w.Comment("force/torque");
  w.Line("ft_settle_samples", fmt::format("{}", p.ft_settle_samples), "readings discarded first");
  w.Line("ft_samples", fmt::format("{}", p.ft_samples), "readings averaged");
  w.Blank();
  w.Comment("planner");
  w.Line("profile", Quoted(p.profile), "\"\" = the server's");
  w.Line("seed", fmt::format("{}", p.seed), "scan k sends seed + k");
  w.Line("max_plans", fmt::format("{}", p.max_plans), "per scan, 0 = all");
  w.Line("max_plans_per_scan", fmt::format("{}", p.max_plans_per_scan), "executed before a rescan");
  w.Line("disable_simulation", p.disable_simulation ? "true" : "false");
  w.Line("resolution_variant", VariantToName(p.resolution_variant),
         "unspecified (the server's), torque_axis, torque_axis_negative, perpendicular, joint_safe");
  w.Line("plan_deadline", Seconds(p.plan_deadline), "s per PlanPick try");
  w.Line("analyze_deadline", Seconds(p.analyze_deadline), "s per AnalyzeWrench try");
  w.Blank();
  w.Comment("limits");
  w.Line("max_attempts_per_tube", fmt::format("{}", p.max_attempts_per_tube), "since the last pick");
  w.Line("max_attempts_per_bin", fmt::format("{}", p.max_attempts_per_bin));
  w.Line("max_consecutive_failures", fmt::format("{}", p.max_consecutive_failures));
  w.Blank();
  w.Comment("device timeouts, seconds");
  w.Line("scanner_timeout", Seconds(p.scanner_timeout));
  w.Line("robot_timeout", Seconds(p.robot_timeout), "one motion");
  w.Line("gripper_timeout", Seconds(p.gripper_timeout));
  w.Line("ft_timeout", Seconds(p.ft_timeout));
  return w.str();
}

}  // namespace tubepick::cell

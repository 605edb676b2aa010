#include "clients/cell/cell_controller_config.h"

#include <fmt/core.h>

#include <string_view>

#include "core/common/config_fields.h"
#include "core/common/errors.h"
#include "core/params_fields.h"

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
    {v1::RESOLUTION_VARIANT_TORQUE_AXIS_THEN_PERPENDICULAR, "torque_axis_then_perpendicular"},
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
      "{}: unknown variant '{}' (unspecified, torque_axis, torque_axis_negative, perpendicular, joint_safe, "
      "torque_axis_then_perpendicular)",
      path, name));
}

/// The `tool` section: the planner's tool boxes without ToolParams::check (the controller has
/// check_tool_clearance).
struct ToolSection {
  ToolGeometry& tool;
};

template <typename Visit>
void DescribeFields(Visit& v, ToolSection& section) {
  DescribeToolGeometryFields(v, section.tool);
}

constexpr std::string_view kHeader =
    "Cell controller parameters (tubepick cell --controller FILE). Units: metres, m/s, N, radians;\n"
    "durations (*_timeout, *_deadline) in seconds. Absent keys keep their defaults; unknown keys\n"
    "are errors. Bin frame: z up from the floor, TCP z down along the approach.";

}  // namespace

// The YAML fields (core/common/config_fields.h), in the namespace of the structs where the config
// visitors look for them.

template <typename Visit>
void DescribeFields(Visit& v, NudgeParams& n) {
  v("enabled", n.enabled);
  v("max_nudges_per_bin", n.max_nudges_per_bin);
  v("near_wall_distance", n.near_wall_distance, "m, a tube closer to a wall is along it");
  v("target_wall_distance", n.target_wall_distance, "m from the wall after the push");
  v("push_gain", n.push_gain, "push = gain * (target - distance), clamped to [min_push, max_push], m");
  v("min_push", n.min_push);
  v("max_push", n.max_push);
  v("press_depth", n.press_depth, "m of the pads below the tube's top");
  v("tube_clearance", n.tube_clearance,
    "m kept from other tubes and the pressed one's top; a push stops short");
  v("tilt", n.tilt, "rad from the vertical, tips towards the wall");
  v("speed", n.speed, "m/s");
  v("sample_spacing", n.sample_spacing, "m along the tube");
  v("repeat_radius", n.repeat_radius,
    "m: a nudge this close to an earlier one that moved nothing is not done");
}

template <typename Visit>
void DescribeFields(Visit& v, CellFrameCheckParams& c) {
  v("enabled", c.enabled, "check every plan against this controller's cell before any motion");
  v("bin_margin", c.bin_margin, "m: grasp in the bin's interior, pre-grasp and lift over it, grown by this");
  v("grasp_above_walls", c.grasp_above_walls,
    "m: the grasp also up to this above the wall top, for a heap meant to rise above the walls");
  v("place_position_tolerance", c.place_position_tolerance,
    "m between the place frame a plan implies and this cell's place frame");
  v("place_rotation_tolerance", c.place_rotation_tolerance,
    "rad, the same for the turn (a half turn about z is the same frame)");
}

template <typename Visit>
void DescribeFields(Visit& v, WallWatchParams& w) {
  v("enabled", w.enabled, "warn when a tube seen hanging over a wall is gone at the next scan");
  v("below_top", w.below_top, "m: a tube's top (axis + radius) this close below the wall top or higher ...");
  v("from_wall", w.from_wall, "m: ... and this close to the wall's inner face or past it hangs over it");
  v("gone_distance", w.gone_distance, "m: gone when the next scan has fewer than min_points this close");
  v("min_points", w.min_points, "(the wall's own points left out)");
}

template <typename Visit>
void DescribeFields(Visit& v, LiftWeightCheckParams& c) {
  v("enabled", c.enabled, "warn when the lifts' weights fit no whole number of tubes of tube.mass");
  v("window", c.limits.window, "the most recent lifts, judged together");
  v("min_lifts", c.limits.min_lifts, "of them, at least this many");
  v("max_tubes_per_lift", c.limits.max_tubes_per_lift, "the most tubes one lift is believed to hold");
  v("max_off_whole", c.limits.max_off_whole, "tubes' worth a lift may lie from a whole number and fit");
}

namespace {

template <typename Visit>
void DescribeMotionFields(Visit& v, CellControllerParams& p) {
  v.Heading("motion");
  v("transit_speed", p.transit_speed, "m/s, free moves (home, transit, above the place)");
  v("approach_speed", p.approach_speed, "m/s, pre-grasp -> grasp, above place -> place");
  v("lift_speed", p.lift_speed, "m/s, along the plan's waypoints after the grasp");
  v("resolution_speed", p.resolution_speed, "m/s of the TCP, resolution rotations");
  v("resolution_hold_over_bin", p.resolution_hold_over_bin,
    "carry several tubes over the bin's middle before the resolution rotation");
  v("resolution_wall_margin", p.resolution_wall_margin, "m, the TCP inside the bin walls while it does");
  v("resolution_dwell", p.resolution_dwell, "s, each resolution motion pauses at its tilt; 0 = none");
  v("resolution_replan", p.resolution_replan,
    "a motion that left several tubes: the next one planned from the reading after it, at the hold pose");
  v("resolution_extra_motions", p.resolution_extra_motions,
    "with resolution_replan: up to this many more motions after the plan's, each from the latest reading");
  v("resolution_rest_load", p.resolution_rest_load,
    "tube weights: each motion let down until less than this hangs on the tool; 0 = at the hold pose");
  v("approach_height", p.approach_height, "m, pre-grasp back from the grasp");
  v("transit_clearance", p.transit_clearance, "m above the bin's wall top");
  v("release_height", p.release_height, "m above the grasp to put back several tubes");
  v("put_back_margin", p.put_back_margin, "m, their centre of mass at least this inside the walls");
  v("put_back_step", p.put_back_step, "m: down to it in steps, opening where they rest; 0 = one move");
  v("place_approach_height", p.place_approach_height, "m above the place pose");
  v("place_recheck_height", p.place_recheck_height, "m higher again when the load there is light");
  v("place_surface_height", p.place_surface_height,
    "bin z of the surface tubes are placed on; the tool stays tool.margin above it");
  v("place_step", p.place_step,
    "m: down to the place pose in steps, opening where the tube rests; 0 = one move");
  v("safe_release_height", p.safe_release_height,
    "m above the bin floor: a safe stop holding a tube opens there, over the bin's middle");
  v("safe_release_step", p.safe_release_step,
    "m: down to it in steps, opening where the tube rests on the heap; 0 = one move");
  v.OptionalPose("home_pose_in_bin", p.X_BinHome,
                 "where the robot waits while the bin is scanned (X_BinHome);\n"
                 "null: above the place frame at transit height, TCP down");
  v("check_tool_clearance", p.check_tool_clearance, "skip plans whose tool path touches a wall or the floor");
  ToolSection tool{p.tool};
  v.Section("tool", tool, "tool boxes in the TCP frame, m (the planner's planning.tool)");
  v.Section("nudge", p.nudge, "drag a tube off a wall when no plan is executable");
  v.Section("cell_check", p.cell_check,
            "plans checked against this controller's bin and place frame (cell YAML): a planner\n"
            "configured with another cell (bin size, place frame, millimetres) must not drive the arm");
}

template <typename Visit>
void DescribePlannerFields(Visit& v, CellControllerParams& p) {
  v.Heading("planner");
  v("profile", p.profile, "\"\" = the server's");
  v("seed", p.seed, "scan k sends seed + k");
  v("max_plans", p.max_plans, "per scan, 0 = all");
  v("max_plans_per_scan", p.max_plans_per_scan, "executed before a rescan");
  v("failed_grasp_radius", p.failed_grasp_radius,
    "m: plans this close to a grasp that closed on or lifted nothing since tubes last moved are skipped; 0 = "
    "off");
  v("disable_simulation", p.disable_simulation);
  v.Enum("resolution_variant", p.resolution_variant, VariantToName, VariantFromName,
         "unspecified (the server's), torque_axis, torque_axis_negative, perpendicular, joint_safe, "
         "torque_axis_then_perpendicular");
  v.Seconds("plan_deadline", p.plan_deadline, "s per PlanPick try");
  v.Seconds("analyze_deadline", p.analyze_deadline, "s per AnalyzeWrench try");
}

template <typename Visit>
void DescribeLimitFields(Visit& v, CellControllerParams& p) {
  v.Heading("limits");
  v("max_attempts_per_tube", p.max_attempts_per_tube, "since the last pick");
  v("max_attempts_per_bin", p.max_attempts_per_bin);
  v("max_consecutive_failures", p.max_consecutive_failures);
  v.Heading("device timeouts, seconds");
  v.Seconds("scanner_timeout", p.scanner_timeout);
  v.Seconds("robot_timeout", p.robot_timeout, "one motion");
  v.Seconds("gripper_timeout", p.gripper_timeout);
  v.Seconds("ft_timeout", p.ft_timeout);
}

}  // namespace

template <typename Visit>
void DescribeFields(Visit& v, CellControllerParams& p) {
  DescribeMotionFields(v, p);
  v.Heading("gripper");
  v("gripper_speed", p.gripper_speed, "m/s closing");
  v("gripper_force", p.gripper_force, "N");
  v.Heading("force/torque");
  v("ft_settle_samples", p.ft_settle_samples, "readings discarded first");
  v("ft_samples", p.ft_samples, "readings averaged");
  v("ft_read_retries", p.ft_read_retries, "tries again after a reading timed out");
  v("ft_spike_force", p.ft_spike_force, "N off the median: a spike, dropped");
  v("ft_spike_torque", p.ft_spike_torque, "N*m off the median: a spike, dropped");
  v("ft_unsettled_retries", p.ft_unsettled_retries,
    "measures again after one whose readings mostly disagreed");
  v.Section("tube_mass_check", p.tube_mass_check,
            "each of the last `window` lifts more than max_off_whole from every whole number of\n"
            "tubes from 1 to max_tubes_per_lift: tube.mass is doubted (logged once, recorded with\n"
            "every attempt)");
  v.Heading("scanner");
  v("scan_retries", p.scan_retries, "scans again after a timeout or an empty scan");
  v.Section("wall_watch", p.wall_watch,
            "a tube a scan shows hanging over a wall that the next scan does not show, though no\n"
            "attempt took it, may have fallen out of the bin: logged, recorded, on the round's line");
  v("tubes_per_bin", p.tubes_per_bin,
    "tubes in a full bin, 0 = not known: a bin that looks empty with fewer placed says so");
  DescribePlannerFields(v, p);
  DescribeLimitFields(v, p);
}

v1::ResolutionVariant ResolutionVariantFromName(const std::string& name, const std::string& field) {
  return VariantFromName(name, field);
}

CellControllerParams ParseCellControllerParams(const std::string& yaml_text) {
  CellControllerParams p;
  ParseFields(yaml_text, "cell controller config", p);
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

std::string DumpCellControllerParams(const CellControllerParams& p) { return DumpFields(p, kHeader); }

}  // namespace tubepick::cell

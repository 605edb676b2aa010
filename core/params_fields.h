#pragma once

// The YAML fields of every params section (ParseParams / DumpParams in core/params.cc), declared
// once for the reader and the writer of core/common/config_fields.h. Private to core (and to the
// cell controller's config, which shares the tool section).

#include <string>

#include "core/common/config_fields.h"
#include "core/modeling/modeling_params.h"
#include "core/params.h"
#include "core/placement/placement.h"
#include "core/planning/pick_planner.h"
#include "core/wrench/wrench_params.h"

namespace tubepick {
namespace internal {

// Text names of the modeling enums. Parse* @throws InvalidArgument naming `key`.
const char* AxisName(Axis axis);
Axis ParseAxis(const std::string& text, const std::string& key);
const char* FrameName(FilterFrame frame);
FilterFrame ParseFrame(const std::string& text, const std::string& key);
const char* SurfaceName(SearchSurface surface);
SearchSurface ParseSurface(const std::string& text, const std::string& key);
const char* StrategyName(JoiningStrategy strategy);
JoiningStrategy ParseStrategy(const std::string& text, const std::string& key);

/// The filter pipeline as a YAML list: `- <FilterName>: {fields}`.
const VariantListSpec<FilterStep>& FilterListSpec();

}  // namespace internal

// ---- modeling ---------------------------------------------------------------------------------

template <typename Visit>
void DescribeFields(Visit& v, CropBoxParams& p) {
  v("from_bin", p.from_bin);
  v("inset_xy", p.inset_xy);
  v("min_z", p.min_z);
  v("above_walls", p.above_walls);
  v("min", p.min);
  v("max", p.max);
}

template <typename Visit>
void DescribeFields(Visit& v, PassThroughParams& p) {
  v.Enum("axis", p.axis, internal::AxisName, internal::ParseAxis);
  v.Enum("frame", p.frame, internal::FrameName, internal::ParseFrame);
  v("min", p.min);
  v("max", p.max);
}

template <typename Visit>
void DescribeFields(Visit& v, VoxelGridParams& p) {
  v("leaf_size", p.leaf_size);
}

template <typename Visit>
void DescribeFields(Visit& v, RandomSampleParams& p) {
  v("count", p.count);
}

template <typename Visit>
void DescribeFields(Visit& v, RadiusOutlierParams& p) {
  v("radius", p.radius);
  v("min_neighbours", p.min_neighbours);
}

template <typename Visit>
void DescribeFields(Visit& v, StatisticalOutlierParams& p) {
  v("neighbours", p.neighbours);
  v("stddev_mult", p.stddev_mult);
}

template <typename Visit>
void DescribeFields(Visit& v, PlaneRemovalParams& p) {
  v("distance_threshold", p.distance_threshold);
  v("normal_distance_weight", p.normal_distance_weight);
  v("axis", p.axis);
  v("eps_angle", p.eps_angle, "radians");
  v("max_iterations", p.max_iterations);
  v("probability", p.probability);
  v("min_inliers", p.min_inliers);
}

template <typename Visit>
void DescribeFields(Visit& v, NormalParams& p) {
  v("radius", p.radius, "metres");
  v("max_neighbours", p.max_neighbours, "0 = all within the radius");
  v.Enum("search_surface", p.search_surface, internal::SurfaceName, internal::ParseSurface,
         "raw or filtered");
}

template <typename Visit>
void DescribeFields(Visit& v, SegmentationParams& p) {
  v("min_cluster_size", p.min_cluster_size);
  v("max_cluster_size", p.max_cluster_size);
  v("neighbours", p.neighbours);
  v("smoothness_threshold", p.smoothness_threshold, "radians");
  v("curvature_threshold", p.curvature_threshold);
  v("residual_test", p.residual_test);
  v("residual_threshold", p.residual_threshold);
}

template <typename Visit>
void DescribeFields(Visit& v, CylinderFitParams& p) {
  v("min_inliers", p.min_inliers);
  v("min_radius", p.min_radius, "metres");
  v("max_radius", p.max_radius, "metres");
  v("distance_threshold", p.distance_threshold);
  v("normal_distance_weight", p.normal_distance_weight);
  v("max_iterations", p.max_iterations);
  v("probability", p.probability);
  v("safety_length", p.safety_length, "epsilon_delta_l");
  v("safety_radius", p.safety_radius, "epsilon_r");
  v("refine", p.refine);
}

template <typename Visit>
void DescribeFields(Visit& v, JoiningParams& p) {
  v("max_distance", p.max_distance);
  v("max_angle", p.max_angle, "radians");
  v("angular_weight", p.angular_weight, "metres per radian");
  v("max_tube_length", p.max_tube_length);
  v("max_length_share", p.max_length_share,
    "with tube.length known, no tube longer than this share of it; 0 = off");
  v("radius_shortcut", p.radius_shortcut);
  v("visibility_check", p.visibility_check);
  v("visibility_pixel_angle", p.visibility_pixel_angle);
  v("visibility_window", p.visibility_window);
  v("visibility_min_gap", p.visibility_min_gap);
  v.Enum("strategy", p.strategy, internal::StrategyName, internal::ParseStrategy, "greedy or global");
}

template <typename Visit>
void DescribeFields(Visit& v, EndRoomParams& p) {
  v("max_unfitted", p.max_unfitted,
    "unfitted surface past a free end lengthens its reach by up to this, m; 0 = off");
  v("attach_distance", p.attach_distance, "unfitted points this close to the end start that surface, m");
  v("link_distance", p.link_distance, "unfitted points in touching cells of this size are one surface, m");
  v("corridor", p.corridor, "that surface is followed within the radius plus this of the extended axis, m");
  v("free_space_check", p.free_space_check, "no reach past where the scanner saw through the branch's place");
  v("free_space_step", p.free_space_step, "free space: probe spacing along the extended axis, m");
  v("free_space_tolerance", p.free_space_tolerance,
    "free space: a surface up to this behind the axis hides it, m");
  v("free_space_window", p.free_space_window, "free space: range image pixels around each probe");
}

template <typename Visit>
void DescribeFields(Visit& v, JunctionCompletionParams& p) {
  v("enabled", p.enabled, "false: ends left after the nodes and links are not tried again");
  v("max_gap", p.max_gap, "as max_gap and side_max_gap, for the ends tried again, m");
  v("max_axis_offset", p.max_axis_offset, "as max_axis_offset and side_max_axis_offset, for them, m");
  v("facing_offset_mean", p.facing_offset_mean,
    "two ends facing across a gap: offset = mean of each from the other's axis (false: the second's)");
  v("max_length_share", p.max_length_share, "no tree they make longer than this share of tube.length");
}

template <typename Visit>
void DescribeFields(Visit& v, JunctionParams& p) {
  v("max_gap", p.max_gap, "Y-pieces: each free end's axis is extended by its radius plus this, m");
  v("max_axis_offset", p.max_axis_offset, "Y-pieces: between two extended axes where they meet, m");
  v("side_max_gap", p.side_max_gap, "T-pieces: from a free end to the surface of the tube it meets, m");
  v("side_max_axis_offset", p.side_max_axis_offset, "T-pieces: between the extended axis and the other, m");
  v("min_angle", p.min_angle, "radians, between the branch and the axis it meets");
  v("min_meeting_ends", p.min_meeting_ends, "free ends meeting at one point that make a node");
  v("max_branches_per_node", p.max_branches_per_node);
  v("max_meeting_ends", p.max_meeting_ends,
    "shape any: more free ends meeting than this are ambiguous, none of them a Y-node");
  v("shape_tolerance", p.shape_tolerance,
    "junction shape other than any: largest difference of an angle between arms, radians");
  v("node_spacing", p.node_spacing);
  v("chain_max_distance", p.chain_max_distance, "linear joining before junctions: at most this, m");
  v("chain_max_angle", p.chain_max_angle, "linear joining before junctions: at most this, radians");
  v("link_max_distance", p.link_max_distance, "two free ends meeting alone: linked within this, m");
  v("link_max_angle", p.link_max_angle, "two free ends meeting alone: linked within this α + β, radians");
  v("max_tube_length", p.max_tube_length);
  v("max_length_share", p.max_length_share, "with tube.length known, no tree longer than this share of it");
  v("layout_tolerance", p.layout_tolerance,
    "with tube.junctions, junction_spacing or branch_length known: runs within this of them, m");
  v("auto_min_junctions", p.auto_min_junctions,
    "topology auto: junctions a scene needs to count as branched");
  v("auto_min_per_tube", p.auto_min_per_tube, "topology auto: and this many per tube they leave");
  v("auto_min_y_pieces", p.auto_min_y_pieces, "topology auto: or this many Y-pieces");
  v.Section("end_room", p.end_room);
  v.Section("completion", p.completion);
}

template <typename Visit>
void DescribeFields(Visit& v, PlausibilityParams& p) {
  v("check", p.check, "false: no error for a cloud that misses the bin");
  v("margin_xy", p.margin_xy, "bin volume: inner x/y extent grown by this, m");
  v("below_floor", p.below_floor, "bin volume: from this far below the floor, m");
  v("above_walls", p.above_walls, "bin volume: to this far above the walls, m");
  v("min_inside_share", p.min_inside_share, "of the finite points, inside the bin volume");
  v("floor_tolerance", p.floor_tolerance, "on the floor: |z| at most this, m");
  v("min_floor_points", p.min_floor_points, "floor seen: at least this many points on it");
  v("min_floor_share", p.min_floor_share, "and this share of the points inside the bin volume");
  v("wall_tolerance", p.wall_tolerance, "the scan's inner wall faces within this of the cell's, m; 0 = off");
  v("wall_min_points", p.wall_min_points,
    "a wall face is seen with this many sampled points per height band");
}

template <typename Visit>
void DescribeFields(Visit& v, ModelingParams& p) {
  v("threads", p.threads, "0 = all cores");
  v.VariantList("filters", p.filters, internal::FilterListSpec(), "applied in order, bin frame");
  v.Section("normals", p.normals);
  v.Section("segmentation", p.segmentation);
  v.Section("cylinders", p.cylinders);
  v.Section("joining", p.joining);
  v.Section("junctions", p.junctions);
  v.Section("plausibility", p.plausibility);
}

// ---- planning, wrench, placement --------------------------------------------------------------

template <typename Visit>
void DescribeFields(Visit& v, ClassificationParams& p) {
  v("length_tolerance", p.length_tolerance);
  v("junction_gap", p.junction_gap);
  v("short_tubes_last_resort", p.short_tubes_last_resort,
    "beyond the thesis: when every tube is too short, plan them anyway (unsure or simulated)");
}

template <typename Visit>
void DescribeFields(Visit& v, TrajectoryParams& p) {
  v("upward_distance", p.upward_distance);
  v("escape_first_lift", p.escape_first_lift);
  v("escape_second_lift", p.escape_second_lift);
  v("escape_constant", p.escape_constant);
  v("safety_margin", p.safety_margin);
  v("min_escape_distance", p.min_escape_distance);
  v("occlusion_escapes", p.occlusion_escapes);
}

template <typename Visit>
void DescribeFields(Visit& v, GraspParams& p) {
  v("spacing", p.spacing);
  v("min_base_distance", p.min_base_distance);
  v("opening_width", p.opening_width);
  v("max_axis_inclination", p.max_axis_inclination);
  v("max_tilt", p.max_tilt);
  v("tilt_step", p.tilt_step);
}

template <typename Visit>
void DescribeFields(Visit& v, GraspFilterParams& p) {
  v("finger_thickness", p.finger_thickness);
  v("finger_width", p.finger_width);
  v("finger_length", p.finger_length);
  v("finger_tip_depth", p.finger_tip_depth);
  v("max_points_in_fingers", p.max_points_in_fingers);
  v("approach_check", p.approach_check, "beyond the thesis: the pads' and housing's way down");
  v("max_points_in_approach", p.max_points_in_approach);
  v("approach_column_height", p.approach_column_height, "m above the grasp point");
  v("grid_cell_size", p.grid_cell_size);
  v("workspace_min", p.workspace_min);
  v("workspace_max", p.workspace_max);
}

/// The tool boxes of ToolParams without `check`: also the cell controller's `tool` section.
template <typename Visit>
void DescribeToolGeometryFields(Visit& v, ToolParams& p) {
  v("finger_size", p.finger_size, "one pad: along the tube, closing, height, m");
  v("finger_tip_depth", p.finger_tip_depth, "tips past the TCP along z_Tcp, m");
  v("housing_size", p.housing_size, "m");
  v("housing_gap", p.housing_gap, "housing bottom above the pads' top, m");
  v("margin", p.margin, "kept from the bin's walls and floor, m");
}

template <typename Visit>
void DescribeFields(Visit& v, ToolParams& p) {
  v("check", p.check);
  DescribeToolGeometryFields(v, p);
}

template <typename Visit>
void DescribeFields(Visit& v, CostParams& p) {
  v("height_weight", p.height_weight);
  v("centre_weight", p.centre_weight);
  v("trajectory_weight", p.trajectory_weight);
  v("max_displacement", p.max_displacement);
}

template <typename Visit>
void DescribeFields(Visit& v, CertaintyParams& p) {
  v("safe_first", p.safe_first);
  v("safe_displacement", p.safe_displacement);
  v("contact_margin", p.contact_margin);
}

template <typename Visit>
void DescribeFields(Visit& v, PlanningParams& p) {
  v.Section("classification", p.classification);
  v.Section("trajectories", p.trajectories);
  v.Section("grasps", p.grasps);
  v.Section("filters", p.filters);
  v.Section("tool", p.tool);
  v.Section("cost", p.cost);
  v.Section("certainty", p.certainty);
  v("empty_max_points", p.empty_max_points);
  v("empty_min_height", p.empty_min_height);
  v("strongly_occluded_candidates", p.strongly_occluded_candidates);
  v("max_plans", p.max_plans);
}

template <typename Visit>
void DescribeFields(Visit& v, WrenchParams& p) {
  v("gravity", p.gravity);
  v("force_tolerance", p.force_tolerance);
  v("force_tolerance_share", p.force_tolerance_share);
  v("max_tilt", p.max_tilt);
  v("rotation_angle", p.rotation_angle);
  v("min_torque", p.min_torque);
  v.Enum(
      "variant", p.variant, [](ResolutionVariant x) { return ToString(x); }, ParseResolutionVariant);
  v("joint_safe_axis", p.joint_safe_axis);
  v.Enum(
      "joint_safe_frame", p.joint_safe_frame, [](JointSafeFrame x) { return ToString(x); },
      ParseJointSafeFrame);
  v("joint_safe_min_yaw", p.joint_safe_min_yaw);
}

template <typename Visit>
void DescribeFields(Visit& v, PlacementParams& p) {
  v("yaw_only", p.yaw_only);
  v.Enum(
      "origin", p.origin, [](TubeFrameOrigin x) { return ToString(x); }, ParseTubeFrameOrigin);
  v.Enum(
      "sign", p.sign, [](AxisSign x) { return ToString(x); }, ParseAxisSign);
  v("min_horizontal", p.min_horizontal);
  v("allow_flip", p.allow_flip);
}

template <typename Visit>
void DescribeFields(Visit& v, Params& p) {
  v.Section("modeling", p.modeling);
  v.Section("planning", p.planning);
  v.Section("wrench", p.wrench);
  v.Section("placement", p.placement);
}

}  // namespace tubepick

#pragma once

// Field lists of the planning, wrench and placement params, shared by the YAML reader and
// writer (core/params.cc) so the two can never disagree. Private to core.

#include "core/placement/placement.h"
#include "core/planning/pick_planner.h"
#include "core/wrench/wrench_params.h"

namespace tubepick::internal {

template <typename Visit>
void DescribeFields(Visit& v, ClassificationParams& p) {
  v("length_tolerance", p.length_tolerance);
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
}

template <typename Visit>
void DescribeFields(Visit& v, GraspFilterParams& p) {
  v("finger_thickness", p.finger_thickness);
  v("finger_width", p.finger_width);
  v("finger_length", p.finger_length);
  v("finger_tip_depth", p.finger_tip_depth);
  v("max_points_in_fingers", p.max_points_in_fingers);
  v("grid_cell_size", p.grid_cell_size);
  v("workspace_min", p.workspace_min);
  v("workspace_max", p.workspace_max);
}

template <typename Visit>
void DescribeFields(Visit& v, ToolParams& p) {
  v("check", p.check);
  v("finger_size", p.finger_size);
  v("finger_tip_depth", p.finger_tip_depth);
  v("housing_size", p.housing_size);
  v("housing_gap", p.housing_gap);
  v("margin", p.margin);
}

template <typename Visit>
void DescribeFields(Visit& v, CostParams& p) {
  v("height_weight", p.height_weight);
  v("centre_weight", p.centre_weight);
  v("trajectory_weight", p.trajectory_weight);
  v("max_displacement", p.max_displacement);
}

template <typename Visit>
void DescribeFields(Visit& v, PlanningParams& p) {
  v.Section("classification", p.classification);
  v.Section("trajectories", p.trajectories);
  v.Section("grasps", p.grasps);
  v.Section("filters", p.filters);
  v.Section("tool", p.tool);
  v.Section("cost", p.cost);
  v("empty_max_points", p.empty_max_points);
  v("empty_min_height", p.empty_min_height);
  v("strongly_occluded_candidates", p.strongly_occluded_candidates);
  v("max_plans", p.max_plans);
}

template <typename Visit>
void DescribeFields(Visit& v, WrenchParams& p) {
  v("gravity", p.gravity);
  v("force_tolerance", p.force_tolerance);
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

}  // namespace tubepick::internal

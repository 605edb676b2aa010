#pragma once

#include <string>

#include "clients/cell/cell_controller_params.h"

namespace tubepick::cell {

/// CellControllerParams as YAML (deploy/cell-controller.example.yaml is the dump of the defaults).
///
/// The keys are the field names of CellControllerParams, with `tool:` (ToolGeometry, the same keys as
/// the planner's `planning.tool` section, without `check`) and `nudge:` (NudgeParams) as nested
/// mappings. Units are the struct's: metres, m/s, N, radians. Durations are seconds in YAML
/// (`*_timeout`, `plan_deadline`, `analyze_deadline`: e.g. `robot_timeout: 60`) although the struct
/// holds milliseconds; they are rounded to the millisecond. `home_pose_in_bin` (X_BinHome) is absent
/// or null for the default home, else {position: [x, y, z], orientation_xyzw: [x, y, z, w]} in the
/// bin frame. `resolution_variant` is one of unspecified (the server's), torque_axis,
/// torque_axis_negative, perpendicular, joint_safe.
///
/// Reading is strict: every key absent keeps its default, an unknown key or a value of the wrong type
/// throws InvalidArgument naming the key path ("nudge.max_push"), and the result is validated
/// (CellControllerParams::Validate).

/// Parses YAML text over the defaults. @throws InvalidArgument (key path and reason).
CellControllerParams ParseCellControllerParams(const std::string& yaml_text);

/// The controller's resolution_variant names ("unspecified", "torque_axis", ...,
/// "torque_axis_then_perpendicular"). @throws InvalidArgument naming `field` and the name.
v1::ResolutionVariant ResolutionVariantFromName(const std::string& name, const std::string& field);

/// ParseCellControllerParams of the file at `path`. @throws InvalidArgument naming the file.
CellControllerParams LoadCellControllerParams(const std::string& path);

/// YAML of every field (with short comments) that ParseCellControllerParams reads back to the same
/// params: numbers are written in their shortest exact form; home_pose_in_bin goes through a
/// quaternion, so it returns equal to ~1e-15.
std::string DumpCellControllerParams(const CellControllerParams& params);

}  // namespace tubepick::cell

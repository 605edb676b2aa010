#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "core/common/cell_config.h"
#include "core/common/types.h"
#include "core/params.h"
#include "core/wrench/wrench.h"
#include "server/server_config.h"
#include "tubepick/v1/requests.pb.h"
#include "tubepick/v1/wrench.pb.h"
#include "wire/wrench_analysis.h"

namespace tubepick::server {

/// A validated ModelTubes / PlanPick request, ready to run. Every check happens while building it;
/// caller mistakes throw InvalidArgument whose message names the field ("cloud.xyz",
/// "cell.tube_radius", "options.profile", ...), the reason and the offending value. The server maps
/// that to INVALID_ARGUMENT.
struct PlanningJob {
  /// The cloud's packed float32 x, y, z bytes (sensor frame, in `unit`), checked but not decoded:
  /// modeling reads them in place (non-finite points included: it drops them). A view into the
  /// request (or the joined stream), which outlives the job.
  std::string_view xyz_Sensor;
  LengthUnit unit = LengthUnit::kMetre;
  CellConfig cell;
  std::string profile;
  Params params;
  std::uint64_t seed = 0;
  bool disable_simulation = false;
  std::uint32_t max_plans = 0;
};

/// Checks a packed float32 xyz byte string: non-empty, a multiple of 12, at most max_points points.
/// @returns `xyz` (not copied). @throws InvalidArgument (TooLarge past max_points) naming `field`.
std::string_view CheckCloudBytes(std::string_view xyz, std::uint64_t max_points, const std::string& field);

/// The cell of a request: `defaults.cell` when absent, else every field required and checked:
/// finite; poses with unit quaternions within 1e-3 (then normalised; a zero quaternion is an error);
/// bin sides in [0.01, 10] m; the sensor above the floor; tube radius in [0.001, 0.2] m, length in
/// [0, 10] m, mass in [0.001, 50] kg (CellConfig::Validate's limits, which planning applies again).
/// The sensor unit is the server cell's (CellDescription has none). `field` prefixes messages.
CellConfig ValidateCell(const v1::CellDescription* cell, const PlanningDefaults& defaults,
                        const std::string& field);

/// Cloud (CheckCloudBytes, `defaults.max_cloud_points`), cell (ValidateCell), cloud.unit (UNSPECIFIED ⇒
/// the cell's sensor unit; numbers the enum does not define are errors), options.profile (empty ⇒
/// defaults.profile; unknown ⇒ error listing the known ones), options.seed (absent ⇒ defaults.seed).
PlanningJob ValidateModelTubes(const v1::ModelTubesRequest& request, const PlanningDefaults& defaults);
/// The job views the request's cloud bytes: a temporary request would leave the view dangling.
PlanningJob ValidateModelTubes(v1::ModelTubesRequest&& request, const PlanningDefaults& defaults) = delete;
/// As ValidateModelTubes, and the tube must fit the profile's gripper opening
/// (2 · tube radius < planning.grasps.opening_width).
PlanningJob ValidatePlanPick(const v1::PlanPickRequest& request, const PlanningDefaults& defaults);
PlanningJob ValidatePlanPick(v1::PlanPickRequest&& request, const PlanningDefaults& defaults) = delete;
/// PlanPickStream: the header's request (whose cloud.xyz must be empty) and the joined bytes.
/// Fields are named as in the stream ("header.request.cell.tube_radius").
PlanningJob ValidatePlanPick(const v1::PlanPickRequest& request, std::string_view cloud_xyz,
                             const PlanningDefaults& defaults);

/// A validated AnalyzeWrench request.
/// reference, current and tcp_pose are required; tube_mass absent ⇒ defaults.cell's, in
/// [0.001, 50] kg and heavier than wrench.force_tolerance; variant UNSPECIFIED ⇒ the profile's. The
/// params are defaults.profiles[defaults.profile].wrench with up_Tcp = R_BinTcpᵀ · z_Bin: the pose
/// defines the vertical in the sensor frame (axes = TCP's), so a grasp TCP with z pointing down
/// gives (0, 0, −1). The TCP z axis must be within wrench.max_tilt of the vertical (the resolution
/// planner's own tilt check always passes with this up_Tcp); a joint-safe axis in the TCP frame is
/// re-projected onto the horizontal plane of this pose.
WrenchJob ValidateAnalyzeWrench(const v1::AnalyzeWrenchRequest& request, const PlanningDefaults& defaults);

}  // namespace tubepick::server

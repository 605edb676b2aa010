#include "server/request_validation.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/common/errors.h"
#include "core/common/require.h"
#include "wire/proto_convert.h"

namespace tubepick::server {
namespace {

// Limits of a request's cell. They equal CellConfig::Validate()'s, which PlanPick applies again:
// a request that passes here never fails there with a core key name.
constexpr double kMinBinSize = 0.01;  // m, each side
constexpr double kMaxBinSize = 10.0;
constexpr double kMinTubeRadius = 0.001;  // m
constexpr double kMaxTubeRadius = 0.2;
constexpr double kMaxTubeLength = 10.0;  // m
constexpr double kMinTubeMass = 0.001;   // kg
constexpr double kMaxTubeMass = 50.0;

// lo < value ≤ hi (lo_open) or lo ≤ value ≤ hi.
void RequireRange(double value, double lo, double hi, bool lo_open, const std::string& field,
                  const std::string& unit) {
  RequireFiniteField(value, field);
  const bool ok = (lo_open ? value > lo : value >= lo) && value <= hi;
  if (!ok) {
    throw InvalidArgument(field + ": " + FormatNumber(value) + " " + unit + " is out of range " +
                          (lo_open ? "(" : "[") + FormatNumber(lo) + ", " + FormatNumber(hi) + "] " + unit);
  }
}

std::string KnownProfiles(const PlanningDefaults& defaults) {
  std::string names;
  for (const auto& [name, params] : defaults.profiles) names += (names.empty() ? "" : ", ") + name;
  return names;
}

const Params& ProfileOf(const PlanningDefaults& defaults, const std::string& profile,
                        const std::string& field) {
  const auto it = defaults.profiles.find(profile);
  if (it == defaults.profiles.end()) {
    throw InvalidArgument(field + ": unknown profile '" + profile + "' (known: " + KnownProfiles(defaults) +
                          ")");
  }
  return it->second;
}

LengthUnit ToUnit(int unit, LengthUnit cell_unit, const std::string& field) {
  switch (unit) {
    case v1::LENGTH_UNIT_UNSPECIFIED:
      return cell_unit;
    case v1::LENGTH_UNIT_METRE:
      return LengthUnit::kMetre;
    case v1::LENGTH_UNIT_MILLIMETRE:
      return LengthUnit::kMillimetre;
    default:
      break;
  }
  throw InvalidArgument(field + ": unknown LengthUnit value " + std::to_string(unit) +
                        " (expected LENGTH_UNIT_UNSPECIFIED = 0, LENGTH_UNIT_METRE = 1 or "
                        "LENGTH_UNIT_MILLIMETRE = 2)");
}

// Everything of a ModelTubes / PlanPick request but the cloud bytes. `prefix` is "" for a unary
// request and "header.request." for a stream header.
PlanningJob ValidateContext(const v1::PlanPickRequest& request, const PlanningDefaults& defaults,
                            const std::string& prefix) {
  PlanningJob job;
  job.cell = ValidateCell(request.has_cell() ? &request.cell() : nullptr, defaults, prefix + "cell");
  job.unit = ToUnit(static_cast<int>(request.cloud().unit()), job.cell.sensor.unit, prefix + "cloud.unit");
  const v1::PlanningOptions& options = request.options();
  job.profile = options.profile().empty() ? defaults.profile : options.profile();
  job.params = ProfileOf(defaults, job.profile,
                         options.profile().empty() ? "planning.profile" : prefix + "options.profile");
  job.seed = options.has_seed() ? options.seed() : defaults.seed;
  job.disable_simulation = options.disable_simulation();
  job.max_plans = options.max_plans();
  return job;
}

// PlanPick only: the tube must fit between the open fingers (PlanPick checks it again, naming the
// parameter; here the message names the request's field).
void RequireTubeFitsGripper(const PlanningJob& job, bool cell_in_request, const std::string& prefix) {
  const double opening = job.params.planning.grasps.opening_width;
  if (!(opening > 2.0 * job.cell.tube.radius)) {
    throw InvalidArgument(
        (cell_in_request ? prefix + "cell.tube_radius: " : "cell.tube_radius (the server's cell): ") +
        FormatNumber(job.cell.tube.radius) + " m: a tube of diameter " +
        FormatNumber(2.0 * job.cell.tube.radius) + " m does not fit the gripper opening " +
        FormatNumber(opening) + " m (profile '" + job.profile + "', planning.grasps.opening_width)");
  }
}

// ModelTubesRequest and PlanPickRequest have the same fields (1 cloud, 2 cell, 3 options).
v1::PlanPickRequest AsPlanPick(const v1::ModelTubesRequest& request) {
  v1::PlanPickRequest out;
  if (request.has_cell()) *out.mutable_cell() = request.cell();
  if (request.has_options()) *out.mutable_options() = request.options();
  out.mutable_cloud()->set_unit(request.cloud().unit());
  return out;
}

TubeTopology TopologyOf(v1::TubeTopology topology, TubeTopology configured, const std::string& field) {
  if (topology == v1::TUBE_TOPOLOGY_UNSPECIFIED) return configured;
  if (const std::optional<TubeTopology> known = FromProto(topology)) return *known;
  throw InvalidArgument(field + ": unknown value " + std::to_string(static_cast<int>(topology)) +
                        " (expected TUBE_TOPOLOGY_LINEAR, _BRANCHED or _AUTO)");
}

JunctionShape JunctionShapeOf(v1::JunctionShape shape, JunctionShape configured, const std::string& field) {
  if (shape == v1::JUNCTION_SHAPE_UNSPECIFIED) return configured;
  if (const std::optional<JunctionShape> known = FromProto(shape)) return *known;
  throw InvalidArgument(field + ": unknown value " + std::to_string(static_cast<int>(shape)) +
                        " (expected JUNCTION_SHAPE_ANY, _WYE or _TEE)");
}

}  // namespace

std::string_view CheckCloudBytes(std::string_view xyz, std::uint64_t max_points, const std::string& field) {
  if (xyz.empty()) throw InvalidArgument(field + ": empty cloud (0 bytes); at least one point is needed");
  if (xyz.size() % 12 != 0) {
    throw InvalidArgument(field + ": " + std::to_string(xyz.size()) +
                          " bytes is not a multiple of 12 (packed float32 x, y, z per point)");
  }
  const std::uint64_t count = xyz.size() / 12;
  if (count > max_points) {
    throw TooLarge(field + ": " + std::to_string(count) + " points exceed the limit of " +
                   std::to_string(max_points) + " (planning.max_cloud_points)");
  }
  return xyz;
}

CellConfig ValidateCell(const v1::CellDescription* cell, const PlanningDefaults& defaults,
                        const std::string& field) {
  if (cell == nullptr) return defaults.cell;
  const std::string f = field + ".";
  CellConfig out;
  // The request describes no sensor unit: clouds in LENGTH_UNIT_UNSPECIFIED use the server's.
  out.sensor.unit = defaults.cell.sensor.unit;

  if (!cell->has_bin_inner_size())
    throw InvalidArgument(f + "bin_inner_size: required when the cell is given");
  const Eigen::Vector3d size = FromProto(cell->bin_inner_size(), f + "bin_inner_size");
  static const char* const kAxes[] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i) {
    RequireRange(size[i], kMinBinSize, kMaxBinSize, false, f + "bin_inner_size." + kAxes[i], "m");
  }
  out.bin.inner_size = size;

  if (!cell->has_sensor_pose()) throw InvalidArgument(f + "sensor_pose: required when the cell is given");
  out.sensor.X_BinSensor = FromProto(cell->sensor_pose(), f + "sensor_pose");
  if (!(out.sensor.X_BinSensor.translation().z() > 0.0)) {
    throw InvalidArgument(f + "sensor_pose.position.z: the sensor must be above the bin floor (z > 0), got " +
                          FormatNumber(out.sensor.X_BinSensor.translation().z()) + " m");
  }

  RequireRange(cell->tube_radius(), kMinTubeRadius, kMaxTubeRadius, false, f + "tube_radius", "m");
  out.tube.radius = cell->tube_radius();
  RequireRange(cell->tube_length(), 0.0, kMaxTubeLength, false, f + "tube_length", "m");
  out.tube.length = cell->tube_length();
  RequireRange(cell->tube_mass(), kMinTubeMass, kMaxTubeMass, false, f + "tube_mass", "kg");
  out.tube.mass = cell->tube_mass();
  out.tube.topology = TopologyOf(cell->tube_topology(), defaults.cell.tube.topology, f + "tube_topology");
  out.tube.junction_shape = JunctionShapeOf(cell->tube_junction_shape(), defaults.cell.tube.junction_shape,
                                            f + "tube_junction_shape");
  if (cell->tube_junctions() > JunctionLayout::kMaxJunctions) {
    throw InvalidArgument(f + "tube_junctions: " + std::to_string(cell->tube_junctions()) + " is above " +
                          std::to_string(JunctionLayout::kMaxJunctions) + " (junctions of one part)");
  }
  out.tube.layout.junctions = cell->tube_junctions();
  RequireRange(cell->tube_junction_spacing(), 0.0, kMaxTubeLength, false, f + "tube_junction_spacing", "m");
  out.tube.layout.junction_spacing = cell->tube_junction_spacing();
  RequireRange(cell->tube_branch_length(), 0.0, kMaxTubeLength, false, f + "tube_branch_length", "m");
  out.tube.layout.branch_length = cell->tube_branch_length();

  if (!cell->has_place_pose()) throw InvalidArgument(f + "place_pose: required when the cell is given");
  out.place.X_BinPlace = FromProto(cell->place_pose(), f + "place_pose");

  try {
    out.Validate();  // the same limits; a safety net should they ever drift apart
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(field + ": " + e.what());
  }
  return out;
}

PlanningJob ValidateModelTubes(const v1::ModelTubesRequest& request, const PlanningDefaults& defaults) {
  PlanningJob job = ValidateContext(AsPlanPick(request), defaults, "");
  job.xyz_Sensor = CheckCloudBytes(request.cloud().xyz(), defaults.max_cloud_points, "cloud.xyz");
  return job;
}

PlanningJob ValidatePlanPick(const v1::PlanPickRequest& request, const PlanningDefaults& defaults) {
  PlanningJob job = ValidateContext(request, defaults, "");
  RequireTubeFitsGripper(job, request.has_cell(), "");
  job.xyz_Sensor = CheckCloudBytes(request.cloud().xyz(), defaults.max_cloud_points, "cloud.xyz");
  return job;
}

PlanningJob ValidatePlanPick(const v1::PlanPickRequest& request, std::string_view cloud_xyz,
                             const PlanningDefaults& defaults) {
  if (!request.cloud().xyz().empty()) {
    throw InvalidArgument(
        "header.request.cloud.xyz: must be empty in a stream header (the bytes follow in chunks), got " +
        std::to_string(request.cloud().xyz().size()) + " bytes");
  }
  PlanningJob job = ValidateContext(request, defaults, "header.request.");
  RequireTubeFitsGripper(job, request.has_cell(), "header.request.");
  job.xyz_Sensor = CheckCloudBytes(cloud_xyz, defaults.max_cloud_points, "chunks (the streamed cloud)");
  return job;
}

WrenchJob ValidateAnalyzeWrench(const v1::AnalyzeWrenchRequest& request, const PlanningDefaults& defaults) {
  WrenchJob job;
  if (!request.has_reference()) {
    throw InvalidArgument("reference: required (the F/T reading with the gripper empty, before the pick)");
  }
  if (!request.has_current()) throw InvalidArgument("current: required (the F/T reading after the lift)");
  job.reference.force = FromProto(request.reference().force(), "reference.force");
  job.reference.torque = FromProto(request.reference().torque(), "reference.torque");
  job.current.force = FromProto(request.current().force(), "current.force");
  job.current.torque = FromProto(request.current().torque(), "current.torque");

  job.tube_mass = request.has_tube_mass() ? request.tube_mass() : defaults.cell.tube.mass;
  RequireRange(job.tube_mass, kMinTubeMass, kMaxTubeMass, false, "tube_mass", "kg");

  if (!request.has_tcp_pose()) throw InvalidArgument("tcp_pose: required (X_BinTcp at lift time)");
  job.X_BinTcp = FromProto(request.tcp_pose(), "tcp_pose");

  job.params = ProfileOf(defaults, defaults.profile, "planning.profile").wrench;
  if (request.variant() != v1::RESOLUTION_VARIANT_UNSPECIFIED) {  // else the profile's
    const std::optional<ResolutionVariant> variant = FromProto(request.variant());
    if (!variant) {
      throw InvalidArgument("variant: unknown ResolutionVariant value " +
                            std::to_string(static_cast<int>(request.variant())) +
                            " (expected 0 = UNSPECIFIED .. 4 = JOINT_SAFE)");
    }
    job.params.variant = *variant;
  }

  // The vertical comes from the request's pose, not from the configured wrench.up_Tcp.
  job.params = WrenchParamsAtPose(job.params, job.X_BinTcp);

  const double weight = job.tube_mass * job.params.gravity;
  if (!(job.params.force_tolerance < weight)) {
    throw InvalidArgument("tube_mass: " + FormatNumber(job.tube_mass) + " kg weighs " + FormatNumber(weight) +
                          " N, not more than wrench.force_tolerance " +
                          FormatNumber(job.params.force_tolerance) +
                          " N: one tube could not be told from none" +
                          (request.has_tube_mass() ? "" : " (the server's cell tube mass)"));
  }
  job.params.Validate();
  return job;
}

}  // namespace tubepick::server

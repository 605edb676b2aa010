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

namespace tubepick::server {

/// A validated ModelTubes / PlanPick request, ready to run. Every check happens while building it;
/// caller mistakes throw InvalidArgument whose message names the field ("cloud.xyz",
/// "cell.tube_radius", "options.profile", ...), the reason and the offending value. The server maps
/// that to INVALID_ARGUMENT.
struct PlanningJob {
  /// Decoded points in the sensor frame, in `unit` (non-finite points kept: modeling drops them).
  Points points_Sensor;
  LengthUnit unit = LengthUnit::kMetre;
  CellConfig cell;
  std::string profile;
  Params params;
  std::uint64_t seed = 0;
  bool disable_simulation = false;
  std::uint32_t max_plans = 0;
};

/// Checks a packed float32 xyz byte string (non-empty, a multiple of 12, at most max_points) and
/// decodes it (little-endian). @throws InvalidArgument naming `field`.
Points DecodeCloud(std::string_view xyz, std::uint64_t max_points, const std::string& field);

/// The cell of a request: `defaults.cell` when absent, else every field checked (finite, poses with
/// unit quaternions within 1e-3 — normalised —, radius in (0, 0.5] m, mass in (0, 100] kg, ...).
CellConfig ValidateCell(const v1::CellDescription* cell, const PlanningDefaults& defaults,
                        const std::string& field);

PlanningJob ValidateModelTubes(const v1::ModelTubesRequest& request, const PlanningDefaults& defaults);
PlanningJob ValidatePlanPick(const v1::PlanPickRequest& request, const PlanningDefaults& defaults);
/// PlanPickStream: the header's request (whose cloud.xyz must be empty) and the joined bytes.
PlanningJob ValidatePlanPick(const v1::PlanPickRequest& request, std::string_view cloud_xyz,
                             const PlanningDefaults& defaults);

/// A validated AnalyzeWrench request.
struct WrenchJob {
  Wrench reference;
  Wrench current;
  double tube_mass = 0.0;
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
  WrenchParams params;
};
WrenchJob ValidateAnalyzeWrench(const v1::AnalyzeWrenchRequest& request, const PlanningDefaults& defaults);

}  // namespace tubepick::server

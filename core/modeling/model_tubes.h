#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/common/cell_config.h"
#include "core/common/stop_token.h"
#include "core/common/types.h"
#include "core/modeling/cloud_plausibility.h"
#include "core/modeling/cloud_prepare.h"
#include "core/modeling/junction_joining.h"
#include "core/modeling/modeling_params.h"

namespace tubepick {

struct ModelingInput {
  /// The cloud as the scanner gives it: sensor optical frame, in `unit`. Exactly one of
  /// points_Sensor and xyz_Sensor (the wire form, read in place) is set.
  const Points* points_Sensor = nullptr;
  PackedXyz xyz_Sensor;
  LengthUnit unit = LengthUnit::kMetre;
  Eigen::Isometry3d X_BinSensor = SensorConfig::DefaultX_BinSensor();
  BinConfig bin;
  /// Drives every random choice: same cloud + seed ⇒ same tubes.
  std::uint64_t seed = 0;
  /// ModelingResult::raw_Bin keeps the finite points in this region (default: all). PlanPick needs
  /// those a finger box can reach (RawRegionForPlanning); modeling alone needs none
  /// (RawRegion::None()), and every point kept is memory the call touches.
  RawRegion raw_region_Bin;
  /// The shape of the cell's tubes (CellConfig tube.topology): whether joining looks for
  /// junctions.
  TubeTopology topology = TubeTopology::kLinear;
  /// The fitting at their junctions (CellConfig tube.junction_shape).
  JunctionShape junction_shape = JunctionShape::kAny;
  /// The length of one tube (CellConfig tube.length), metres; 0 = unknown. Bounds joining
  /// (JoinTubesOfLength, and the junction joining's trees and completion).
  double tube_length = 0.0;
  /// Where the junctions of the cell's branched parts are (CellConfig tube.junctions,
  /// junction_spacing, branch_length); unknown fields check nothing (FitsJunctionLayout).
  JunctionLayout layout;
  /// The radius of the cell's tubes (CellConfig tube.radius), metres; 0 = unknown. Must lie within
  /// the cylinder fit's radii (modeling.cylinders.min_radius, max_radius); the fitted radii are
  /// compared with it (ModelingResult::warnings).
  double tube_radius = 0.0;
};

/// The cell's part of a modeling input: bin, X_BinSensor, tube topology, junction shape, length
/// and radius (the cloud, unit, seed and raw region are the caller's).
ModelingInput ModelingInputFor(const CellConfig& cell);

struct StageTiming {
  std::string stage;  ///< "prepare", "filter", "normals", "segmentation", "cylinders", "joining"
  double seconds = 0.0;
};

/// Something the modeling noticed that the caller should act on: the answer is given, but an input
/// probably does not fit the parts in the bin.
struct ModelingWarning {
  /// Stable identifier for programs: "tube_length_shorter_than_scan",
  /// "tube_radius_differs_from_scan".
  std::string code;
  /// What was seen, the values, and the likely cause, for a person.
  std::string message;
  /// The input's value and what the scan shows instead (same unit; metres for lengths).
  double stated = 0.0;
  double observed = 0.0;
};

struct StepCount {
  std::string step;  ///< "input", "finite", each filter step by name, "normals", "segmented", ...
  std::uint64_t points = 0;
};

struct ModelingResult {
  std::vector<Tube> tubes;
  /// Highest z of the filtered cloud (max_z of Equation 5.4), metres; 0 when it is empty.
  double max_height = 0.0;
  std::uint64_t input_points = 0;
  std::uint64_t dropped_non_finite = 0;
  /// How the finite input fits the bin (points inside, floor seen, extent).
  CloudPlausibility plausibility;
  /// What the caller should know about its inputs (also logged): e.g. the scene's whole tubes were
  /// longer than the cell's tube.length allows, and were joined within their own length instead.
  std::vector<ModelingWarning> warnings;
  std::uint32_t segment_count = 0;
  std::uint32_t cylinder_count = 0;
  std::vector<StepCount> counts;
  std::vector<StageTiming> timings;
  double total_seconds = 0.0;

  /// The finite input in the bin frame inside raw_region_Bin (for the grasp collision check; all of
  /// it when the normals search the raw cloud).
  Points raw_Bin;
  RawRegion raw_region_Bin;
  /// The filtered cloud (with normals) that was segmented.
  OrientedPoints filtered;
  /// Per filtered point: its index in the input cloud (ModelingInput::points_Sensor), so per-point
  /// ground truth can be looked up.
  std::vector<std::uint32_t> filtered_source_index;
  /// Per filtered point: its segment, or −1.
  std::vector<std::int32_t> segment_of_point;
  /// Per filtered point: the tube whose cylinder took it as an inlier, or −1.
  std::vector<std::int32_t> tube_of_point;
  /// When the tubes were joined as trees: the linear chains junction joining started from and its
  /// decisions (JunctionJoining::decisions, naming those chains); empty otherwise.
  std::vector<Tube> chains;
  std::vector<JoinDecision> join_decisions;
};

/// Runs Algorithm 1: prepare → filters (+ normals) → region growing → cylinders → joining.
/// @throws InvalidArgument for an empty / all-non-finite cloud or invalid parameters.
/// @throws FailedPrecondition when the cloud in the bin frame does not look like the cell (wrong
///         unit or sensor pose; see RequirePlausible and params.plausibility).
/// @throws Cancelled when `stop` fires (polled inside every stage).
ModelingResult ModelTubes(const ModelingInput& input, const ModelingParams& params,
                          const StopToken* stop = nullptr);

/// Writes the stage clouds as PLY into `directory` (created if missing): 1_filtered.ply,
/// 2_segments.ply (coloured by segment), 3_tubes.ply (cylinder inliers coloured by tube).
void DumpStages(const ModelingResult& result, const std::string& directory);

}  // namespace tubepick

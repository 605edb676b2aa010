#pragma once

#include <string>
#include <vector>

#include "core/modeling/cloud_plausibility.h"
#include "core/modeling/cylinder_fit.h"
#include "core/modeling/filters.h"
#include "core/modeling/junction_joining.h"
#include "core/modeling/normals.h"
#include "core/modeling/segmentation.h"
#include "core/modeling/tube_joining.h"

namespace tubepick {

/// Every parameter of the tube-modeling pipeline (thesis Algorithm 1, Tables 4.2 and 4.3).
struct ModelingParams {
  /// Ordered filter pipeline, applied to the cloud in the bin frame.
  std::vector<FilterStep> filters;
  /// Normals are estimated just before the first step that needs them (plane_removal), or after
  /// the last filter when none does.
  NormalParams normals;
  SegmentationParams segmentation;
  CylinderFitParams cylinders;
  JoiningParams joining;
  /// Junctions (branched tubes), when the cell's topology asks for them.
  JunctionParams junctions;
  /// The check, right after the cloud enters the bin frame, that it looks like the cell.
  PlausibilityParams plausibility;
  /// Worker threads for normals and per-segment fitting; 0 = all cores. Results do not depend
  /// on it.
  std::uint32_t threads = 0;

  /// @throws InvalidArgument naming the first bad key ("modeling.cylinders.min_radius", ...).
  void Validate() const;
};

/// Designed for speed on a 2 M-point cloud: crop box, one random sample, normals on the
/// filtered cloud, tuned thresholds.
ModelingParams FastModelingProfile();
/// The seed's values (Tables 4.2 and 4.3); the depth pass-through is replaced by the bin crop
/// box of §5.2.1 since the depth range depends on the scanner's mount.
ModelingParams ThesisModelingProfile();

}  // namespace tubepick

#pragma once

#include <string>
#include <vector>

#include "core/modeling/modeling_params.h"
#include "core/placement/placement.h"
#include "core/planning/pick_planner.h"
#include "core/wrench/wrench_params.h"

namespace tubepick {

/// All algorithm parameters, one YAML document (`tubepick params --dump`). Every key has a
/// compiled-in default from the chosen profile.
struct Params {
  ModelingParams modeling;
  PlanningParams planning;
  WrenchParams wrench;
  PlacementParams placement;

  /// @throws InvalidArgument naming the first bad key.
  void Validate() const;
};

/// Names of the shipped profiles: "fast" (default) and "thesis".
std::vector<std::string> ProfileNames();
/// @throws InvalidArgument for an unknown profile name.
Params ProfileParams(const std::string& name);

/// Overrides `base` with the keys of a params YAML. Unknown keys, wrong types and out-of-range
/// values are errors naming the key path.
/// @throws InvalidArgument
Params ParseParams(const std::string& yaml_text, const Params& base);
Params LoadParams(const std::string& path, const Params& base);

/// Full YAML of `params` (every key), loadable by ParseParams.
std::string DumpParams(const Params& params);

}  // namespace tubepick

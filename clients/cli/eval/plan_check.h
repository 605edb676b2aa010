#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/common/cell_config.h"
#include "core/planning/pick_planner.h"
#include "physics/tube_geometry.h"

namespace tubepick::cli {

/// The best plan of a scene checked against its ground truth (`tubepick eval --plans`): which
/// real tube it grasps, whether that tube is free (no real tube lies on it), and what lifting it
/// along the plan's trajectory does in a Bullet world of the real tubes — independent of the
/// modeling, which built the plan from its own tubes.
struct PlanCheck {
  /// PlanPick gave a plan.
  bool planned = false;
  /// The best plan: its certainty and trajectory ("sure", "upward", ...), and the modeled tube's
  /// occlusion class ("none", "weak", "strong").
  std::string certainty;
  std::string trajectory;
  std::string modeled_class;
  /// The real tube nearest the grasp point, and that distance from its axis, metres.
  std::int32_t real_tube = -1;
  double grasp_offset = 0.0;
  /// No real tube lies on the grasped one (TubesLyingOn on the real tubes).
  bool real_tube_free = false;
  /// Real tubes nothing lies on.
  std::uint32_t free_real_tubes = 0;
  /// Real tubes raised by more than half the trajectory's lift in the check, the grasped one
  /// included: 1 = lifted alone.
  std::uint32_t lifted = 0;
  /// The other real tubes' summed centre-of-mass displacement in the check, metres.
  double displacement = 0.0;
};

/// Checks `plan.plans.front()` (if any) against the real tubes `tubes_Bin` of the cell.
/// A real tube farther than 2 tube radii from the grasp point is no grasp of a real tube: the
/// check then has real_tube = −1 and lifts nothing.
PlanCheck CheckBestPlan(const PickPlanResult& plan, const std::vector<physics::TubeGeometry>& tubes_Bin,
                        const CellConfig& cell, const PlanningParams& params);

/// Best plans over scenes.
struct PlanCheckSummary {
  std::uint32_t scenes = 0;
  /// Scenes with a plan, and its certainty.
  std::uint32_t planned = 0;
  std::uint32_t sure = 0;
  std::uint32_t simulated = 0;
  std::uint32_t unsure = 0;
  /// Best plans whose grasp point is on no real tube.
  std::uint32_t off_tube = 0;
  /// Best plans on a free real tube; on a real tube something lies on while a free one exists.
  std::uint32_t grasped_free = 0;
  std::uint32_t grasped_lain_on_while_free = 0;
  /// The check lifted the grasped tube alone, with others, or not at all.
  std::uint32_t lifted_alone = 0;
  std::uint32_t lifted_several = 0;
  std::uint32_t lifted_none = 0;
};
PlanCheckSummary SummarizePlanChecks(const std::vector<const PlanCheck*>& checks);

}  // namespace tubepick::cli

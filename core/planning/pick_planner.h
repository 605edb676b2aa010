#pragma once

#include <cstdint>
#include <vector>

#include "core/common/cell_config.h"
#include "core/common/stop_token.h"
#include "core/common/types.h"
#include "core/modeling/model_tubes.h"
#include "core/planning/classification.h"
#include "core/planning/grasp_filters.h"
#include "core/planning/grasp_ranking.h"
#include "core/planning/grasp_synthesis.h"
#include "core/planning/plan_certainty.h"
#include "core/planning/tool_clearance.h"
#include "core/planning/trajectory.h"
#include "core/planning/trajectory_synthesis.h"

namespace tubepick {

/// Every parameter of pick planning (thesis §5.2.2–§5.2.4); defaults are Table 5.3 (set A)
/// where the thesis gives a value.
struct PlanningParams {
  ClassificationParams classification;
  TrajectoryParams trajectories;
  GraspParams grasps;
  GraspFilterParams filters;
  /// The gripper's pads and housing for the tool-clearance filter (ToolClears): a grasp whose
  /// tool would touch a bin wall or the floor at the grasp pose or at a trajectory waypoint is
  /// not executable and is rejected, so the stages fall through to other tubes. Beyond the thesis.
  ToolParams tool;
  CostParams cost;
  /// The certainty rule: a plan that needs luck does not outrank a sure one unless its simulated
  /// displacement says it is as safe (issue 14 item 6). Beyond the thesis.
  CertaintyParams certainty;
  /// Bin-empty test: the bin is empty when no tube was modeled and at most this many filtered
  /// points lie higher than empty_min_height.
  std::uint32_t empty_max_points = 50;
  /// Filtered points at or below this height count as floor, metres.
  double empty_min_height = 0.005;
  /// Beyond the thesis: when neither non-occluded nor weakly occluded tubes give a viable grasp,
  /// consider the strongly occluded ones (upward + occlusion escapes).
  bool strongly_occluded_candidates = true;
  /// Keep at most this many plans (best first); 0 = all.
  std::uint32_t max_plans = 0;

  /// @throws InvalidArgument naming the first bad key ("planning.grasps.spacing: must be > 0,
  ///         got 0.000000").
  void Validate() const;
};

struct PlanningCounts {
  std::uint32_t tubes = 0;
  /// Rejected by the minimum-length filter.
  std::uint32_t too_short = 0;
  /// Every modeled tube was too short and planning.classification.short_tubes_last_resort planned
  /// them anyway: every plan needs luck (kUnsure, or kSimulated with an evaluator).
  bool short_tubes_planned = false;
  /// Occlusion classes among the tubes that passed the length filter.
  std::uint32_t non_occluded = 0;
  std::uint32_t weakly_occluded = 0;
  std::uint32_t strongly_occluded = 0;
  /// Non-occluded tubes another modeled tube lies on (TubeClass::lying_on).
  std::uint32_t non_occluded_lain_on = 0;
  /// Trajectories synthesized, and those sent to the evaluator.
  std::uint32_t trajectories = 0;
  std::uint32_t simulated_trajectories = 0;
  /// (grasp, trajectory) pairs tested, and how many each filter rejected (the first failing one,
  /// tested in the order section, workspace, tool clearance, fingers, approach).
  std::uint64_t grasp_candidates = 0;
  std::uint64_t rejected_section = 0;
  std::uint64_t rejected_workspace = 0;
  std::uint64_t rejected_tool = 0;
  std::uint64_t rejected_fingers = 0;
  std::uint64_t rejected_approach = 0;
  /// Viable pairs whose grasp is tilted (GraspParams::max_tilt): the vertical tool touched a wall.
  std::uint64_t tilted_grasps = 0;
  std::uint32_t plans = 0;
};

struct PickPlanResult {
  /// Best first (RankPlans).
  std::vector<PickPlan> plans;
  /// The modeled tubes, same order, classified (Tube::occlusion, occluded_joint_count).
  std::vector<Tube> tubes;
  /// Parallel to `tubes`.
  std::vector<TubeClass> classes;
  /// Nothing left to pick: see PlanningParams::empty_max_points.
  bool bin_empty = false;
  /// The evaluator was called.
  bool used_simulation = false;
  /// Occlusion class of the best plan's tube; kUnspecified when there is no plan.
  Occlusion planned_class = Occlusion::kUnspecified;
  PlanningCounts counts;
  /// "classification", "cloud_index", "trajectories", "grasps", "simulation", "ranking".
  std::vector<StageTiming> timings;
  double total_seconds = 0.0;
};

/// The bin-empty rule: the bin floor seen (modeling.plausibility.floor_seen), no tube modeled and
/// at most `empty_max_points` filtered points above
/// `empty_min_height` (the filtered cloud holds only bin content: floor, walls and outside were
/// cropped by modeling; the height threshold absorbs floor points a loose crop kept).
bool IsBinEmpty(const ModelingResult& modeling, const PlanningParams& params);

/// The raw points PlanPick's finger test can meet (bin frame). A grasp reaches that test only after
/// the tool-clearance test has kept its pads tool.margin above the floor and, below the wall top,
/// tool.margin inside the walls; the finger boxes (grasp_filters.h) may reach past the pads by the
/// difference of their sizes. So: z >= tool.margin + tool.finger_tip_depth −
/// filters.finger_tip_depth, |x|, |y| within the inner half size − tool.margin + that difference,
/// any x, y from the wall top up; 1 mm of slack on each bound. Everything when tool.check is off.
/// Pass it as ModelingInput::raw_region_Bin: the floor and the walls (most of a scan) then never
/// enter the finger test's index, and the plans are the same.
RawRegion RawRegionForPlanning(const PlanningParams& params, const BinConfig& bin);

/// Plans a pick (ARCHITECTURE.md "How a plan request flows", thesis §5.2.2–§5.2.4):
/// 1. classify the modeled tubes (length filter, occlusion); when every tube is too short and
///    classification.short_tubes_last_resort, they are planned anyway, never as sure plans;
/// 2. candidates in stages, stopping at the first stage that yields a viable grasp:
///    non-occluded tubes (upward trajectory, T_cost 0, no simulation); then weakly occluded
///    tubes (upward + two escapes); then, if strongly_occluded_candidates, strongly occluded
///    ones (upward + one occlusion escape per occluded joint);
/// 3. per trajectory, the tube's grasps are filtered (section, workspace, tool clearance against
///    the bin's walls and floor at the grasp and every waypoint when params.tool.check, finger
///    boxes on the raw cloud, binned once per call); in stages 2 and 3 the trajectories that keep at least
///    one viable grasp (only those: a trajectory without a grasp cannot be executed) are sent to `evaluator`
///    in one Evaluate call, with all modeled tubes (Trajectory::tube_index = position in modeling.tubes) —
///    when `evaluator` is null nothing is simulated and T_cost is 0;
/// 4. every viable (grasp, trajectory) becomes a plan with its cost (Eq. 5.3); plans best first.
/// max_z of Eq. 5.4 is modeling.max_height, or, when that is ≤ 0 (a hand-built model), the
/// highest cylinder endpoint plus its radius. Deterministic for a deterministic evaluator.
/// @throws InvalidArgument for invalid params / cell (naming the key), a tube without cylinders
///         or non-finite geometry, or an opening width not larger than the tube diameter.
/// @throws Cancelled when `stop` fires (also from the evaluator).
/// @throws std::logic_error when the evaluator returns the wrong number of outcomes, or when
///         modeling kept fewer raw points than the finger test needs (modeling.raw_region_Bin does
///         not cover RawRegionForPlanning).
PickPlanResult PlanPick(const ModelingResult& modeling, const CellConfig& cell, const PlanningParams& params,
                        TrajectoryEvaluator* evaluator, std::uint64_t seed, const StopToken* stop = nullptr);

}  // namespace tubepick

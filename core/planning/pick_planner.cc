#include "core/planning/pick_planner.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

#include "core/common/errors.h"
#include "core/common/require.h"

namespace tubepick {
namespace {

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// max_z of Eq. 5.4.
double MaxHeight(const ModelingResult& modeling, const std::vector<Tube>& tubes) {
  if (modeling.max_height > 0.0) return modeling.max_height;
  double top = 0.0;
  for (const Tube& tube : tubes) {
    for (const Cylinder& c : tube.cylinders)
      top = std::max({top, c.start.z() + c.radius, c.end.z() + c.radius});
  }
  return top;
}

// Grasps of one tube, synthesized once, with the cloud tests cached (they do not depend on the
// trajectory): -1 unknown, 0 clear, 1 fingers collide, 2 approach blocked. A vertical grasp's
// tilted variants (GraspTilts order) are made the first time its tool touches a wall.
struct TubeGrasps {
  bool synthesized = false;
  std::vector<Grasp> grasps;
  std::vector<std::int8_t> collides;
  std::vector<std::vector<Grasp>> tilted;
  std::vector<std::vector<std::int8_t>> tilted_collides;
};

// The cloud tests of a grasp: 1 when the fingers collide at the grasp pose (thesis filter (a)),
// 2 when the tool's way down is blocked (filters.approach_check), else 0.
std::int8_t CloudCollision(const Grasp& grasp, const RawCloudIndex& raw, const PlanningParams& params) {
  if (FingersCollide(grasp, raw, params.filters)) return 1;
  if (params.filters.approach_check && ApproachBlocked(grasp, raw, params.filters, params.tool)) return 2;
  return 0;
}

// A non-occluded tube's upward lift is sure when no modeled tube lies on it and the tube is not
// too short (a short one is planned only as a last resort: a part of it is hidden).
bool IsSure(const TubeClass& cls) { return cls.lying_on.empty() && !cls.too_short; }

struct Candidate {
  std::uint32_t trajectory = 0;  // index into the stage's trajectories
  std::uint32_t grasp = 0;       // index into TubeGrasps::grasps of the trajectory's tube
  std::int32_t tilt = -1;        // index into TubeGrasps::tilted[grasp], -1: the vertical grasp
};

const Grasp& GraspOf(const TubeGrasps& tg, const Candidate& c) {
  return c.tilt < 0 ? tg.grasps[c.grasp] : tg.tilted[c.grasp][c.tilt];
}

class StageTimer {
 public:
  explicit StageTimer(std::vector<StageTiming>* timings) : timings_(timings) {}
  void Add(const std::string& stage, Clock::time_point start) {
    const double seconds = SecondsSince(start);
    for (StageTiming& t : *timings_) {
      if (t.stage == stage) {
        t.seconds += seconds;
        return;
      }
    }
    timings_->push_back(StageTiming{stage, seconds});
  }

 private:
  std::vector<StageTiming>* timings_;
};

// What the stages of one PlanPick call share.
struct PlanningContext {
  PlanningContext(const ModelingResult& m, const CellConfig& c, const PlanningParams& p,
                  TrajectoryEvaluator* e, std::uint64_t s, const StopToken* st)
      : modeling(m), cell(c), params(p), evaluator(e), seed(s), stop(st) {}

  const ModelingResult& modeling;
  const CellConfig& cell;
  const PlanningParams& params;
  TrajectoryEvaluator* evaluator;
  std::uint64_t seed;
  const StopToken* stop;
  double max_z = 0.0;
  SafetyZone zone;
  std::unique_ptr<RawCloudIndex> raw;  // built on first use
  std::vector<TubeGrasps> tube_grasps;
  // Trajectories of the stages before, so that trajectory indices stay unique in one answer.
  std::uint32_t trajectories_before = 0;
  // Every tube is too short and classification.short_tubes_last_resort: plan them anyway.
  bool short_tubes = false;
};

// Trajectories of the stage's candidate tubes (thesis §5.2.3.1).
std::vector<Trajectory> StageTrajectories(const PlanningContext& ctx, Occlusion stage,
                                          const PickPlanResult& result) {
  std::vector<Trajectory> trajectories;
  for (std::size_t t = 0; t < result.tubes.size(); ++t) {
    const TubeClass& cls = result.classes[t];
    if ((cls.too_short && !ctx.short_tubes) || cls.occlusion != stage) continue;
    std::vector<Trajectory> own =
        SynthesizeTrajectories(static_cast<std::uint32_t>(t), result.tubes[t], cls, ctx.cell.tube.radius,
                               ctx.zone, ctx.params.trajectories);
    trajectories.insert(trajectories.end(), own.begin(), own.end());
  }
  return trajectories;
}

// The tilt (index into tg.tilted[gi]) of the smallest turn of grasp gi whose tool clears the bin
// along `trajectory`, or -1.
std::int32_t FirstClearTilt(const PlanningContext& ctx, TubeGrasps& tg, std::size_t gi,
                            const Trajectory& trajectory) {
  const PlanningParams& params = ctx.params;
  if (tg.tilted[gi].empty()) {
    for (const double tilt : GraspTilts(params.grasps))
      tg.tilted[gi].push_back(TiltedGrasp(tg.grasps[gi], tilt));
    tg.tilted_collides[gi].assign(tg.tilted[gi].size(), -1);
  }
  for (std::size_t k = 0; k < tg.tilted[gi].size(); ++k) {
    const Grasp& g = tg.tilted[gi][k];
    if (ToolClears(ctx.cell.bin, params.tool, g.X_BinTcp, g.opening_width, trajectory.waypoints))
      return static_cast<std::int32_t>(k);
  }
  return -1;
}

// The (trajectory, grasp) pairs that pass every filter (§5.2.4.1, the tool, the fingers). Where
// the vertical tool would touch a wall, the grasp's smallest tilt that clears it stands in.
std::vector<Candidate> ViableCandidates(PlanningContext& ctx, const std::vector<Trajectory>& trajectories,
                                        const PickPlanResult& result, PlanningCounts& counts) {
  const PlanningParams& params = ctx.params;
  std::vector<Candidate> viable;
  for (std::size_t ti = 0; ti < trajectories.size(); ++ti) {
    ThrowIfStopped(ctx.stop, "grasp planning");
    const Trajectory& trajectory = trajectories[ti];
    TubeGrasps& tg = ctx.tube_grasps[trajectory.tube_index];
    if (!tg.synthesized) {
      tg.grasps = SynthesizeGrasps(result.tubes[trajectory.tube_index], params.grasps);
      tg.collides.assign(tg.grasps.size(), -1);
      tg.tilted.resize(tg.grasps.size());
      tg.tilted_collides.resize(tg.grasps.size());
      tg.synthesized = true;
    }
    for (std::size_t gi = 0; gi < tg.grasps.size(); ++gi) {
      Candidate candidate{static_cast<std::uint32_t>(ti), static_cast<std::uint32_t>(gi), -1};
      const Grasp& grasp = tg.grasps[gi];
      ++counts.grasp_candidates;
      if (!InAllowedSection(grasp, trajectory)) {
        ++counts.rejected_section;
        continue;
      }
      if (!InsideWorkspace(grasp, trajectory, params.filters)) {
        ++counts.rejected_workspace;
        continue;
      }
      if (params.tool.check &&
          !ToolClears(ctx.cell.bin, params.tool, grasp.X_BinTcp, grasp.opening_width, trajectory.waypoints)) {
        candidate.tilt = FirstClearTilt(ctx, tg, gi, trajectory);
        if (candidate.tilt < 0) {
          ++counts.rejected_tool;
          continue;
        }
      }
      std::int8_t& collides = candidate.tilt < 0 ? tg.collides[gi] : tg.tilted_collides[gi][candidate.tilt];
      if (collides < 0) collides = CloudCollision(GraspOf(tg, candidate), *ctx.raw, params);
      if (collides == 1) {
        ++counts.rejected_fingers;
        continue;
      }
      if (collides == 2) {
        ++counts.rejected_approach;
        continue;
      }
      if (candidate.tilt >= 0) ++counts.tilted_grasps;
      viable.push_back(candidate);
    }
  }
  return viable;
}

// Which of the stage's trajectories to simulate: in the occluded stages every one with a viable
// grasp (§5.2.3.2); among non-occluded tubes, with the certainty rule, those of tubes another tube
// lies on, and only when no tube of the stage has a sure plan.
std::vector<bool> TrajectoriesToSimulate(const PlanningContext& ctx, Occlusion stage,
                                         const std::vector<Trajectory>& trajectories,
                                         const std::vector<Candidate>& viable, const PickPlanResult& result) {
  std::vector<bool> simulate(trajectories.size(), false);
  if (ctx.evaluator == nullptr) return simulate;
  if (stage == Occlusion::kNone) {
    if (!ctx.params.certainty.safe_first) return simulate;
    for (const Candidate& c : viable) {
      if (IsSure(result.classes[trajectories[c.trajectory].tube_index])) return simulate;
    }
  }
  for (const Candidate& c : viable) simulate[c.trajectory] = true;
  return simulate;
}

// Simulates the marked trajectories in one Evaluate call; displacement per trajectory.
std::vector<std::optional<double>> Simulate(PlanningContext& ctx, const std::vector<Trajectory>& trajectories,
                                            const std::vector<bool>& simulate, PickPlanResult* result,
                                            StageTimer* timer) {
  std::vector<std::optional<double>> displacement(trajectories.size());
  std::vector<Trajectory> to_simulate;
  std::vector<std::size_t> simulated_index;
  for (std::size_t ti = 0; ti < trajectories.size(); ++ti) {
    if (!simulate[ti]) continue;
    to_simulate.push_back(trajectories[ti]);
    simulated_index.push_back(ti);
  }
  if (to_simulate.empty()) return displacement;
  const Clock::time_point t0 = Clock::now();
  const std::vector<TrajectoryOutcome> outcomes =
      ctx.evaluator->Evaluate(result->tubes, to_simulate, ctx.seed, ctx.stop);
  if (outcomes.size() != to_simulate.size()) {
    throw std::logic_error("TrajectoryEvaluator returned " + std::to_string(outcomes.size()) +
                           " outcomes for " + std::to_string(to_simulate.size()) + " trajectories");
  }
  for (std::size_t k = 0; k < outcomes.size(); ++k)
    displacement[simulated_index[k]] = outcomes[k].displacement;
  result->used_simulation = true;
  result->counts.simulated_trajectories += static_cast<std::uint32_t>(to_simulate.size());
  timer->Add("simulation", t0);
  return displacement;
}

// One candidate stage (thesis §5.2.3–§5.2.4): its trajectories, viable grasps, simulation and
// plans, appended to result->plans (unranked).
void PlanStage(PlanningContext& ctx, Occlusion stage, PickPlanResult* result, StageTimer* timer) {
  ThrowIfStopped(ctx.stop, "planning");
  Clock::time_point t0 = Clock::now();
  const std::vector<Trajectory> trajectories = StageTrajectories(ctx, stage, *result);
  const std::uint32_t first_index = ctx.trajectories_before;
  ctx.trajectories_before += static_cast<std::uint32_t>(trajectories.size());
  result->counts.trajectories += static_cast<std::uint32_t>(trajectories.size());
  timer->Add("trajectories", t0);
  if (trajectories.empty()) return;

  if (!ctx.raw) {
    t0 = Clock::now();
    const auto [z_lo, z_hi] = FingerBandZ(result->tubes, ctx.params.filters, ctx.params.grasps);
    ctx.raw =
        std::make_unique<RawCloudIndex>(ctx.modeling.raw_Bin, ctx.params.filters.grid_cell_size, z_lo, z_hi);
    timer->Add("cloud_index", t0);
  }
  t0 = Clock::now();
  const std::vector<Candidate> viable = ViableCandidates(ctx, trajectories, *result, result->counts);
  timer->Add("grasps", t0);
  if (viable.empty()) return;

  const std::vector<std::optional<double>> displacement = Simulate(
      ctx, trajectories, TrajectoriesToSimulate(ctx, stage, trajectories, viable, *result), result, timer);

  t0 = Clock::now();
  result->plans.reserve(result->plans.size() + viable.size());
  for (const Candidate& c : viable) {
    const Trajectory& trajectory = trajectories[c.trajectory];
    const Tube& tube = result->tubes[trajectory.tube_index];
    const TubeClass& cls = result->classes[trajectory.tube_index];
    PickPlan plan;
    plan.tube_id = tube.id;
    plan.grasp = GraspOf(ctx.tube_grasps[trajectory.tube_index], c);
    plan.waypoints = trajectory.waypoints;
    plan.kind = trajectory.kind;
    plan.escape_direction = trajectory.escape_direction;
    plan.trajectory_index = first_index + c.trajectory;
    plan.displacement = displacement[c.trajectory];
    plan.certainty = plan.displacement                          ? PlanCertainty::kSimulated
                     : stage == Occlusion::kNone && IsSure(cls) ? PlanCertainty::kSure
                                                                : PlanCertainty::kUnsure;
    plan.costs = PlanCost(plan.grasp, tube, ctx.max_z, plan.displacement, ctx.params.cost);
    result->plans.push_back(std::move(plan));
  }
  timer->Add("ranking", t0);
}

}  // namespace

void PlanningParams::Validate() const {
  RequireNonNegative(classification.length_tolerance, "planning.classification.length_tolerance");
  RequireNonNegative(classification.junction_gap, "planning.classification.junction_gap");

  const TrajectoryParams& t = trajectories;
  RequirePositive(t.upward_distance, "planning.trajectories.upward_distance");
  RequireNonNegative(t.escape_first_lift, "planning.trajectories.escape_first_lift");
  RequirePositive(t.escape_second_lift, "planning.trajectories.escape_second_lift");
  RequireNonNegative(t.escape_constant, "planning.trajectories.escape_constant");
  RequireNonNegative(t.safety_margin, "planning.trajectories.safety_margin");
  RequireNonNegative(t.min_escape_distance, "planning.trajectories.min_escape_distance");

  const GraspParams& g = grasps;
  RequirePositive(g.spacing, "planning.grasps.spacing");
  RequireNonNegative(g.min_base_distance, "planning.grasps.min_base_distance");
  RequirePositive(g.opening_width, "planning.grasps.opening_width");
  RequireInRange(g.max_axis_inclination, 0.0, M_PI / 2.0, "planning.grasps.max_axis_inclination");
  RequireInRange(g.max_tilt, 0.0, M_PI / 3.0, "planning.grasps.max_tilt");
  if (g.max_tilt > 0.0) RequireInRange(g.tilt_step, 1e-3, g.max_tilt, "planning.grasps.tilt_step");

  const GraspFilterParams& f = filters;
  RequirePositive(f.finger_thickness, "planning.filters.finger_thickness");
  RequirePositive(f.finger_width, "planning.filters.finger_width");
  RequirePositive(f.finger_length, "planning.filters.finger_length");
  RequireFinite(f.finger_tip_depth, "planning.filters.finger_tip_depth");
  RequirePositive(f.grid_cell_size, "planning.filters.grid_cell_size");
  RequireInRange(f.approach_column_height, 0.0, 2.0, "planning.filters.approach_column_height");
  RequireFiniteComponents(f.workspace_min, "planning.filters.workspace_min");
  RequireFiniteComponents(f.workspace_max, "planning.filters.workspace_max");
  for (int k = 0; k < 3; ++k) {
    if (f.workspace_min[k] > f.workspace_max[k]) {
      std::ostringstream s;
      s << "planning.filters.workspace_min[" << k << "]: " << f.workspace_min[k] << " exceeds workspace_max["
        << k << "] " << f.workspace_max[k];
      throw InvalidArgument(s.str());
    }
  }

  const ToolParams& tool_params = tool;
  for (int k = 0; k < 3; ++k) {
    RequirePositive(tool_params.finger_size[k], "planning.tool.finger_size[" + std::to_string(k) + "]");
    RequireNonNegative(tool_params.housing_size[k], "planning.tool.housing_size[" + std::to_string(k) + "]");
  }
  RequireFinite(tool_params.finger_tip_depth, "planning.tool.finger_tip_depth");
  RequireNonNegative(tool_params.housing_gap, "planning.tool.housing_gap");
  RequireNonNegative(tool_params.margin, "planning.tool.margin");

  RequireNonNegative(cost.height_weight, "planning.cost.height_weight");
  RequireNonNegative(cost.centre_weight, "planning.cost.centre_weight");
  RequireNonNegative(cost.trajectory_weight, "planning.cost.trajectory_weight");
  const double sum = cost.height_weight + cost.centre_weight + cost.trajectory_weight;
  if (std::abs(sum - 1.0) > 1e-6) {
    std::ostringstream s;
    s << "planning.cost: height_weight + centre_weight + trajectory_weight must be 1, got "
      << cost.height_weight << " + " << cost.centre_weight << " + " << cost.trajectory_weight << " = " << sum;
    throw InvalidArgument(s.str());
  }
  RequirePositive(cost.max_displacement, "planning.cost.max_displacement");
  RequireNonNegative(certainty.safe_displacement, "planning.certainty.safe_displacement");
  RequireNonNegative(certainty.contact_margin, "planning.certainty.contact_margin");
  RequireFinite(empty_min_height, "planning.empty_min_height");
}

bool IsBinEmpty(const ModelingResult& modeling, const PlanningParams& params) {
  if (!modeling.tubes.empty()) return false;
  // Nothing standing on a floor that is not seen is no evidence of an empty bin.
  if (!modeling.plausibility.floor_seen) return false;
  std::uint32_t above = 0;
  for (const Eigen::Vector3f& p : modeling.filtered.points) {
    if (p.z() > params.empty_min_height && ++above > params.empty_max_points) return false;
  }
  return true;
}

RawRegion RawRegionForPlanning(const PlanningParams& params, const BinConfig& bin) {
  if (!params.tool.check) return RawRegion::All();
  constexpr double kSlack = 1e-3;
  const ToolParams& tool = params.tool;
  const GraspFilterParams& fingers = params.filters;
  // How far a finger box may reach past the tool's pad, in x_Tcp and y_Tcp together (any yaw).
  const double past_pad = std::max(0.0, 0.5 * (fingers.finger_width - tool.finger_size.x())) +
                          std::max(0.0, fingers.finger_thickness - tool.finger_size.y());
  RawRegion region;
  region.min_z = tool.margin + tool.finger_tip_depth - fingers.finger_tip_depth - kSlack;
  region.half_xy =
      0.5 * bin.inner_size.head<2>() - Eigen::Vector2d::Constant(tool.margin - past_pad - kSlack);
  region.any_xy_above_z = bin.inner_size.z() - kSlack;
  return region;
}

namespace {

// 1. Classification: each tube's class (too short, occlusion) and, for the free ones, the tubes
// lying on them (their plans are not sure). Returns whether every tube is too short and planning
// takes them anyway as a last resort (classification.short_tubes_last_resort).
bool ClassificationStage(const ModelingResult& modeling, const CellConfig& cell, const PlanningParams& params,
                         PickPlanResult* result, StageTimer* timer) {
  const Clock::time_point t0 = Clock::now();
  ClassificationResult classified = ClassifyTubes(modeling.tubes, cell.tube.length, params.classification);
  result->tubes = std::move(classified.tubes);
  result->classes = std::move(classified.classes);
  result->bin_empty = IsBinEmpty(modeling, params);
  PlanningCounts& counts = result->counts;
  counts.tubes = static_cast<std::uint32_t>(result->tubes.size());
  for (const TubeClass& cls : result->classes) {
    if (cls.too_short) {
      ++counts.too_short;
    } else if (cls.occlusion == Occlusion::kNone) {
      ++counts.non_occluded;
    } else if (cls.occlusion == Occlusion::kWeak) {
      ++counts.weakly_occluded;
    } else {
      ++counts.strongly_occluded;
    }
  }
  const bool short_tubes =
      counts.tubes > 0 && counts.too_short == counts.tubes && params.classification.short_tubes_last_resort;
  for (std::size_t t = 0; t < result->tubes.size(); ++t) {
    TubeClass& cls = result->classes[t];
    if ((cls.too_short && !short_tubes) || cls.occlusion != Occlusion::kNone) continue;
    cls.lying_on = TubesLyingOn(result->tubes, t, params.certainty);
    if (!cls.lying_on.empty()) ++counts.non_occluded_lain_on;
  }
  timer->Add("classification", t0);
  return short_tubes;
}

// The plans ranked (the certainty rule), cut to max_plans; the best plan's occlusion class.
void RankingStage(const PlanningParams& params, PickPlanResult* result, StageTimer* timer) {
  const Clock::time_point t0 = Clock::now();
  RankPlans(&result->plans, params.certainty);
  if (params.max_plans > 0 && result->plans.size() > params.max_plans) result->plans.resize(params.max_plans);
  if (!result->plans.empty()) {
    for (std::size_t t = 0; t < result->tubes.size(); ++t) {
      if (result->tubes[t].id == result->plans.front().tube_id)
        result->planned_class = result->classes[t].occlusion;
    }
  }
  timer->Add("ranking", t0);
  result->counts.plans = static_cast<std::uint32_t>(result->plans.size());
}

}  // namespace

PickPlanResult PlanPick(const ModelingResult& modeling, const CellConfig& cell, const PlanningParams& params,
                        TrajectoryEvaluator* evaluator, std::uint64_t seed, const StopToken* stop) {
  const Clock::time_point start = Clock::now();
  params.Validate();
  cell.Validate();
  if (!modeling.raw_region_Bin.Covers(RawRegionForPlanning(params, cell.bin))) {
    throw std::logic_error(
        "PlanPick: modeling kept fewer raw points than the finger test needs (set "
        "ModelingInput::raw_region_Bin to RawRegionForPlanning)");
  }
  if (!(params.grasps.opening_width > 2.0 * cell.tube.radius)) {
    std::ostringstream s;
    s << "planning.grasps.opening_width: " << params.grasps.opening_width
      << " must exceed the tube diameter 2 * tube.radius = " << 2.0 * cell.tube.radius;
    throw InvalidArgument(s.str());
  }

  PickPlanResult result;
  StageTimer timer(&result.timings);
  ThrowIfStopped(stop, "planning");

  const bool short_tubes = ClassificationStage(modeling, cell, params, &result, &timer);
  if (result.counts.too_short == result.counts.tubes && !short_tubes) {
    result.total_seconds = SecondsSince(start);
    return result;
  }

  PlanningContext ctx(modeling, cell, params, evaluator, seed, stop);
  ctx.short_tubes = short_tubes;
  result.counts.short_tubes_planned = short_tubes;
  ctx.max_z = MaxHeight(modeling, result.tubes);
  ctx.zone = MakeSafetyZone(cell.bin, params.trajectories.safety_margin);
  ctx.tube_grasps.resize(result.tubes.size());

  std::vector<Occlusion> stages = {Occlusion::kNone, Occlusion::kWeak};
  if (params.strongly_occluded_candidates) stages.push_back(Occlusion::kStrong);
  for (const Occlusion stage : stages) {
    PlanStage(ctx, stage, &result, &timer);
    if (result.plans.empty()) continue;
    // The thesis stops at the first stage with a plan; the certainty rule goes on until one is safe.
    if (!params.certainty.safe_first) break;
    const auto safe = [&](const PickPlan& p) { return PlanIsSafe(p, params.certainty); };
    if (std::any_of(result.plans.begin(), result.plans.end(), safe)) break;
  }

  RankingStage(params, &result, &timer);
  result.total_seconds = SecondsSince(start);
  return result;
}

}  // namespace tubepick

#include "core/planning/pick_planner.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <set>
#include <stdexcept>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/planning/test/planning_test_util.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;
using namespace testing_planning;  // NOLINT
constexpr double kTol = 1e-12;

// A scripted physics backend: displacement per trajectory from a function; records its calls.
class FakeEvaluator final : public TrajectoryEvaluator {
 public:
  explicit FakeEvaluator(std::function<double(const Trajectory&)> displacement)
      : displacement_(std::move(displacement)) {}

  std::vector<TrajectoryOutcome> Evaluate(const std::vector<Tube>& tubes,
                                          const std::vector<Trajectory>& trajectories, std::uint64_t seed,
                                          const StopToken* stop) override {
    ThrowIfStopped(stop, "fake evaluation");
    ++calls;
    tubes_seen = tubes;
    trajectories_seen = trajectories;
    seed_seen = seed;
    std::vector<TrajectoryOutcome> out;
    for (const Trajectory& t : trajectories)
      out.push_back(TrajectoryOutcome{displacement_(t), false, 0.0, 1.0});
    if (drop_one && !out.empty()) out.pop_back();
    return out;
  }

  int calls = 0;
  bool drop_one = false;
  std::vector<Tube> tubes_seen;
  std::vector<Trajectory> trajectories_seen;
  std::uint64_t seed_seen = 0;

 private:
  std::function<double(const Trajectory&)> displacement_;
};

// Upward 0.5, escape towards +x 0.05, any other escape 0.2.
double ScriptedDisplacement(const Trajectory& t) {
  if (t.kind == TrajectoryKind::kUpward) return 0.5;
  return t.escape_direction.x() > 0.5 ? 0.05 : 0.2;
}

ModelingResult Model(std::vector<Tube> tubes, Points raw = {}) {
  ModelingResult m;
  m.tubes = std::move(tubes);
  m.max_height = 0.05;
  m.raw_Bin = std::move(raw);
  return m;
}

// Point lines along both fingers of every grasp on the upper crossing tube (x = ±0.0275,
// z = 0.07, |y| ≤ 0.25): ~44 points per finger box, none in the lower tube's finger boxes
// (z ≤ 0.0575).
Points BlockUpperTube() {
  Points pts;
  for (double y = -0.25; y <= 0.25; y += 0.0005) {
    pts.emplace_back(0.0275, y, 0.07);
    pts.emplace_back(-0.0275, y, 0.07);
  }
  return pts;
}

TEST(PickPlanner, NonOccludedTubeWinsWithoutSimulation) {
  FakeEvaluator evaluator(ScriptedDisplacement);
  const PickPlanResult r = PlanPick(Model(CrossingTubes()), CellConfig{}, PlanningParams{}, &evaluator, 1);
  EXPECT_EQ(evaluator.calls, 0);
  EXPECT_FALSE(r.used_simulation);
  EXPECT_FALSE(r.bin_empty);
  EXPECT_EQ(r.planned_class, Occlusion::kNone);
  ASSERT_EQ(r.tubes.size(), 2u);
  EXPECT_EQ(r.tubes[0].occlusion, Occlusion::kNone);
  EXPECT_EQ(r.tubes[1].occlusion, Occlusion::kWeak);
  EXPECT_EQ(r.counts.non_occluded, 1u);
  EXPECT_EQ(r.counts.weakly_occluded, 1u);
  ASSERT_EQ(r.plans.size(), 19u);  // 0.4 m cylinder, grasps 2 cm apart from 2 cm to 38 cm
  EXPECT_EQ(r.counts.plans, 19u);
  EXPECT_EQ(r.counts.grasp_candidates, 19u);
  for (const PickPlan& p : r.plans) {
    EXPECT_EQ(p.tube_id, 0u);
    EXPECT_EQ(p.kind, TrajectoryKind::kUpward);
    EXPECT_EQ(p.costs.trajectory, 0.0);
    EXPECT_FALSE(p.displacement.has_value());
    EXPECT_FALSE(p.X_BinTcp_place.has_value());
    ASSERT_EQ(p.waypoints.size(), 2u);
  }
  // Best: the middle grasp (C = 0); H = 0.0375 / 0.05 = 0.75 ⇒ total 0.2 · 0.75 = 0.15.
  const PickPlan& best = r.plans.front();
  EXPECT_NEAR(best.grasp.p_Bin_grasp.y(), 0.0, 1e-9);
  EXPECT_NEAR(best.costs.height, 0.75, kTol);
  EXPECT_NEAR(best.costs.centre, 0.0, 1e-9);
  EXPECT_NEAR(best.costs.total, 0.15, 1e-9);
  for (std::size_t i = 1; i < r.plans.size(); ++i) {
    EXPECT_LE(r.plans[i - 1].costs.total, r.plans[i].costs.total);
  }
}

TEST(PickPlanner, SimulatesWeakTubeWhenNonOccludedHasNoViableGrasp) {
  FakeEvaluator evaluator(ScriptedDisplacement);
  const PickPlanResult r =
      PlanPick(Model(CrossingTubes(), BlockUpperTube()), CellConfig{}, PlanningParams{}, &evaluator, 42);
  EXPECT_EQ(evaluator.calls, 1);
  EXPECT_TRUE(r.used_simulation);
  EXPECT_EQ(evaluator.seed_seen, 42u);
  EXPECT_EQ(r.planned_class, Occlusion::kWeak);
  EXPECT_EQ(r.counts.rejected_fingers, 19u);  // every grasp of the upper tube
  // All of the weak tube's trajectories in one call, with every modeled tube.
  ASSERT_EQ(evaluator.tubes_seen.size(), 2u);
  ASSERT_EQ(evaluator.trajectories_seen.size(), 3u);
  EXPECT_EQ(r.counts.simulated_trajectories, 3u);
  for (const Trajectory& t : evaluator.trajectories_seen) EXPECT_EQ(t.tube_index, 1u);
  EXPECT_EQ(evaluator.trajectories_seen[0].kind, TrajectoryKind::kUpward);
  EXPECT_EQ(evaluator.trajectories_seen[1].kind, TrajectoryKind::kEscape);
  EXPECT_EQ(evaluator.trajectories_seen[2].kind, TrajectoryKind::kEscape);

  // The lowest-displacement trajectory (escape towards +x) wins, gripped on the leading section.
  ASSERT_FALSE(r.plans.empty());
  const PickPlan& best = r.plans.front();
  EXPECT_EQ(best.tube_id, 1u);
  EXPECT_EQ(best.kind, TrajectoryKind::kEscape);
  EXPECT_GT(best.escape_direction.x(), 0.99);
  ASSERT_TRUE(best.displacement.has_value());
  EXPECT_DOUBLE_EQ(*best.displacement, 0.05);
  EXPECT_NEAR(best.costs.trajectory, 0.05, kTol);
  EXPECT_EQ(best.grasp.cylinder_index, 1u);
  // Nearest the middle on that section: x = 0.04 (curve 0.24 of 0.40 ⇒ C = 0.2).
  EXPECT_NEAR(best.grasp.p_Bin_grasp.x(), 0.04, 1e-9);
  EXPECT_NEAR(best.costs.centre, 0.2, 1e-9);
  EXPECT_NEAR(best.costs.total, 0.2 * kR / 0.05 + 0.5 * 0.2 + 0.3 * 0.05, 1e-9);
  // Every plan carries its measured displacement.
  for (const PickPlan& p : r.plans) {
    ASSERT_TRUE(p.displacement.has_value());
    EXPECT_NEAR(p.costs.trajectory, *p.displacement, kTol);
    if (p.kind == TrajectoryKind::kEscape) {
      EXPECT_EQ(p.grasp.cylinder_index, p.escape_direction.x() > 0 ? 1u : 0u);
    }
  }
}

TEST(PickPlanner, NoEvaluatorMeansNoSimulation) {
  const PickPlanResult r =
      PlanPick(Model(CrossingTubes(), BlockUpperTube()), CellConfig{}, PlanningParams{}, nullptr, 0);
  EXPECT_FALSE(r.used_simulation);
  EXPECT_EQ(r.planned_class, Occlusion::kWeak);
  ASSERT_FALSE(r.plans.empty());
  for (const PickPlan& p : r.plans) {
    EXPECT_FALSE(p.displacement.has_value());
    EXPECT_EQ(p.costs.trajectory, 0.0);
  }
  // Equal costs: the upward trajectory (synthesized first) ranks before the escapes.
  EXPECT_EQ(r.plans.front().kind, TrajectoryKind::kUpward);
}

TEST(PickPlanner, OnlyTrajectoriesWithViableGraspsAreSimulated) {
  // Workspace x ≤ 0.15: after the +x escape (shortened to 0.1375 by the safety zone), every
  // grasp on its leading section (x ≥ 0.04) ends beyond 0.15.
  PlanningParams params;
  params.filters.workspace_max.x() = 0.15;
  FakeEvaluator evaluator(ScriptedDisplacement);
  const PickPlanResult r =
      PlanPick(Model(CrossingTubes(), BlockUpperTube()), CellConfig{}, params, &evaluator, 0);
  ASSERT_EQ(evaluator.trajectories_seen.size(), 2u);
  for (const Trajectory& t : evaluator.trajectories_seen) EXPECT_LE(t.escape_direction.x(), 0.0);
  EXPECT_EQ(r.counts.trajectories, 4u);  // upper upward + lower upward and two escapes
  EXPECT_EQ(r.counts.simulated_trajectories, 2u);
  EXPECT_GT(r.counts.rejected_workspace, 0u);
  EXPECT_GT(r.counts.rejected_section, 0u);
}

Tube StrongTube(std::uint32_t id) {
  return MakeTube(id, {FlatCylinder(-0.25, 0.1, -0.15, 0.1, 1), FlatCylinder(-0.11, 0.1, 0.05, 0.1, 2),
                       FlatCylinder(0.09, 0.1, 0.25, 0.1, 3)});
}

TEST(PickPlanner, StronglyOccludedTubesAsLastResort) {
  FakeEvaluator evaluator([](const Trajectory& t) { return t.kind == TrajectoryKind::kUpward ? 0.8 : 0.1; });
  const PickPlanResult r = PlanPick(Model({StrongTube(0)}), CellConfig{}, PlanningParams{}, &evaluator, 0);
  EXPECT_EQ(r.planned_class, Occlusion::kStrong);
  EXPECT_TRUE(r.used_simulation);
  ASSERT_EQ(evaluator.trajectories_seen.size(), 3u);
  ASSERT_FALSE(r.plans.empty());
  EXPECT_EQ(r.plans.front().kind, TrajectoryKind::kOcclusionEscape);

  PlanningParams thesis_only;
  thesis_only.strongly_occluded_candidates = false;
  FakeEvaluator unused(ScriptedDisplacement);
  const PickPlanResult none = PlanPick(Model({StrongTube(0)}), CellConfig{}, thesis_only, &unused, 0);
  EXPECT_TRUE(none.plans.empty());
  EXPECT_EQ(unused.calls, 0);
  EXPECT_FALSE(none.bin_empty);
  EXPECT_EQ(none.planned_class, Occlusion::kUnspecified);
}

TEST(PickPlanner, TooShortTubesAreObstaclesOnly) {
  // Expected length 0.5, tolerance 0.15: the 0.3 m non-occluded tube is discarded; the weak tube
  // (index 1) is planned and the evaluator still sees both tubes.
  const std::vector<Tube> tubes = {
      MakeTube(0, {FlatCylinder(-0.15, 0.2, 0.15, 0.2, 5)}),
      MakeTube(1, {FlatCylinder(-0.2, 0.0, -0.02, 0.0, 1), FlatCylinder(0.02, 0.0, 0.2, 0.0, 2)})};
  FakeEvaluator evaluator(ScriptedDisplacement);
  const PickPlanResult r = PlanPick(Model(tubes), CellConfig{}, PlanningParams{}, &evaluator, 0);
  EXPECT_EQ(r.counts.too_short, 1u);
  EXPECT_TRUE(r.classes[0].too_short);
  EXPECT_EQ(r.counts.non_occluded, 0u);
  EXPECT_EQ(evaluator.calls, 1);
  EXPECT_EQ(evaluator.tubes_seen.size(), 2u);
  for (const PickPlan& p : r.plans) EXPECT_EQ(p.tube_id, 1u);
}

TEST(PickPlanner, WhenEveryTubeIsTooShortTheyArePlannedAsALastResortThatNeedsLuck) {
  // Expected length 0.5, tolerance 0.15: both tubes (0.30 m, free; 0.25 m, free) are too short.
  // The thesis plans nothing, and a bin whose last tube is partly hidden is never emptied.
  const std::vector<Tube> tubes = {MakeTube(0, {FlatCylinder(-0.15, 0.2, 0.15, 0.2, 5)}),
                                   MakeTube(1, {FlatCylinder(-0.15, -0.1, 0.10, -0.1, 6)})};
  PlanningParams thesis;
  thesis.classification.short_tubes_last_resort = false;
  const PickPlanResult none = PlanPick(Model(tubes), CellConfig{}, thesis, nullptr, 0);
  EXPECT_TRUE(none.plans.empty());
  EXPECT_FALSE(none.counts.short_tubes_planned);
  EXPECT_FALSE(none.bin_empty);

  // Without an evaluator: plans of both tubes, every one unsure (never "sure": a part is hidden).
  const PickPlanResult unsure = PlanPick(Model(tubes), CellConfig{}, PlanningParams{}, nullptr, 0);
  EXPECT_TRUE(unsure.counts.short_tubes_planned);
  EXPECT_EQ(unsure.counts.too_short, 2u);
  ASSERT_FALSE(unsure.plans.empty());
  std::set<std::uint32_t> planned;
  for (const PickPlan& p : unsure.plans) {
    EXPECT_EQ(p.certainty, PlanCertainty::kUnsure);
    planned.insert(p.tube_id);
  }
  EXPECT_EQ(planned, (std::set<std::uint32_t>{0u, 1u}));
  EXPECT_EQ(unsure.planned_class, Occlusion::kNone);

  // With an evaluator: their upward lifts are simulated, as a lain-on free tube's are.
  FakeEvaluator evaluator(ScriptedDisplacement);
  const PickPlanResult simulated = PlanPick(Model(tubes), CellConfig{}, PlanningParams{}, &evaluator, 0);
  EXPECT_EQ(evaluator.calls, 1);
  ASSERT_FALSE(simulated.plans.empty());
  for (const PickPlan& p : simulated.plans) EXPECT_EQ(p.certainty, PlanCertainty::kSimulated);

  // One tube long enough: the short one stays an obstacle only.
  const std::vector<Tube> one_whole = {tubes[0], MakeTube(1, {FlatCylinder(-0.2, -0.1, 0.2, -0.1, 6)})};
  const PickPlanResult whole = PlanPick(Model(one_whole), CellConfig{}, PlanningParams{}, nullptr, 0);
  EXPECT_FALSE(whole.counts.short_tubes_planned);
  ASSERT_FALSE(whole.plans.empty());
  for (const PickPlan& p : whole.plans) EXPECT_EQ(p.tube_id, 1u);
}

TEST(PickPlanner, BinEmpty) {
  PlanningParams params;  // empty: ≤ 50 filtered points above 5 mm
  ModelingResult empty = Model({});
  empty.plausibility.floor_seen = true;
  for (int i = 0; i < 40; ++i) empty.filtered.points.emplace_back(0.0f, 0.0f, 0.03f);    // stray points
  for (int i = 0; i < 500; ++i) empty.filtered.points.emplace_back(0.0f, 0.0f, 0.002f);  // floor
  const PickPlanResult r = PlanPick(empty, CellConfig{}, params, nullptr, 0);
  EXPECT_TRUE(r.bin_empty);
  EXPECT_TRUE(r.plans.empty());
  EXPECT_EQ(r.planned_class, Occlusion::kUnspecified);

  ModelingResult clutter = empty;
  for (int i = 0; i < 20; ++i) clutter.filtered.points.emplace_back(0.0f, 0.0f, 0.03f);  // 60 > 50
  EXPECT_FALSE(IsBinEmpty(clutter, params));
  EXPECT_FALSE(PlanPick(Model(CrossingTubes()), CellConfig{}, params, nullptr, 0).bin_empty);
  EXPECT_FALSE(IsBinEmpty(Model({MakeTube(0, {FlatCylinder(0, 0, 0.05, 0, 1)})}), params));

  ModelingResult no_floor = empty;  // nothing stands on a floor that was not seen: not empty
  no_floor.plausibility.floor_seen = false;
  EXPECT_FALSE(IsBinEmpty(no_floor, params));
}

TEST(PickPlanner, MaxPlans) {
  PlanningParams params;
  params.max_plans = 3;
  const PickPlanResult r = PlanPick(Model(CrossingTubes()), CellConfig{}, params, nullptr, 0);
  ASSERT_EQ(r.plans.size(), 3u);
  EXPECT_NEAR(r.plans.front().grasp.p_Bin_grasp.y(), 0.0, 1e-9);
}

TEST(PickPlanner, Deterministic) {
  FakeEvaluator e1(ScriptedDisplacement), e2(ScriptedDisplacement);
  const PickPlanResult a =
      PlanPick(Model(CrossingTubes(), BlockUpperTube()), CellConfig{}, PlanningParams{}, &e1, 3);
  const PickPlanResult b =
      PlanPick(Model(CrossingTubes(), BlockUpperTube()), CellConfig{}, PlanningParams{}, &e2, 3);
  ASSERT_EQ(a.plans.size(), b.plans.size());
  for (std::size_t i = 0; i < a.plans.size(); ++i) {
    EXPECT_EQ(a.plans[i].tube_id, b.plans[i].tube_id);
    EXPECT_EQ(a.plans[i].trajectory_index, b.plans[i].trajectory_index);
    EXPECT_EQ(a.plans[i].grasp.p_Bin_grasp, b.plans[i].grasp.p_Bin_grasp);
    EXPECT_EQ(a.plans[i].costs.total, b.plans[i].costs.total);
  }
}

TEST(PickPlanner, WrongOutcomeCountIsAnError) {
  FakeEvaluator evaluator(ScriptedDisplacement);
  evaluator.drop_one = true;
  EXPECT_THROW(
      PlanPick(Model(CrossingTubes(), BlockUpperTube()), CellConfig{}, PlanningParams{}, &evaluator, 0),
      std::logic_error);
}

TEST(PickPlanner, StopTokenCancels) {
  StopToken stop;
  stop.RequestStop();
  EXPECT_THROW(PlanPick(Model(CrossingTubes()), CellConfig{}, PlanningParams{}, nullptr, 0, &stop),
               Cancelled);
}

// Expects PlanPick to throw InvalidArgument whose message contains `key`.
void ExpectInvalid(const PlanningParams& params, const std::string& key,
                   const CellConfig& cell = CellConfig{}) {
  try {
    PlanPick(Model(CrossingTubes()), cell, params, nullptr, 0);
    ADD_FAILURE() << "expected InvalidArgument naming " << key;
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr(key));
  }
}

// Tube 0 on the floor (non-occluded: one segment), tube 1 across its end, resting on it (also
// non-occluded, nothing on it). Tube 2, if asked for, weakly occluded on the floor far from both.
std::vector<Tube> LainOnTubes(bool with_weak) {
  std::vector<Tube> tubes = {MakeTube(0, {FlatCylinder(-0.2, 0.05, 0.2, 0.05, 1)}),
                             MakeTube(1, {FlatCylinder(0.17, -0.1, 0.17, 0.2, 2, 3.0 * kR)})};
  if (with_weak) {
    tubes.push_back(
        MakeTube(2, {FlatCylinder(-0.2, -0.2, -0.02, -0.2, 3), FlatCylinder(0.02, -0.2, 0.2, -0.2, 4)}));
  }
  return tubes;
}

// Points along both fingers of every grasp on tube 1 (x = 0.17 ± 0.0275, z = 0.07).
Points BlockTube1() {
  Points pts;
  for (double y = -0.15; y <= 0.25; y += 0.0005) {
    pts.emplace_back(0.17 + 0.0275, y, 0.07);
    pts.emplace_back(0.17 - 0.0275, y, 0.07);
  }
  return pts;
}

CellConfig CellOf40cmTubes() {
  CellConfig cell;
  cell.tube.length = 0.40;  // minimum accepted length 0.25 m
  return cell;
}

TEST(PickPlanner, ATubeLainOnDoesNotOutrankAFreeOne) {
  FakeEvaluator evaluator([](const Trajectory&) { return 0.0; });
  const PickPlanResult r =
      PlanPick(Model(LainOnTubes(false)), CellOf40cmTubes(), PlanningParams{}, &evaluator, 0);
  ASSERT_EQ(r.classes.size(), 2u);
  EXPECT_EQ(r.counts.non_occluded, 2u);
  EXPECT_EQ(r.counts.non_occluded_lain_on, 1u);
  EXPECT_EQ(r.classes[0].lying_on, (std::vector<std::uint32_t>{1}));
  EXPECT_TRUE(r.classes[1].lying_on.empty());
  EXPECT_EQ(evaluator.calls, 0);  // a sure plan exists: nothing to simulate
  ASSERT_FALSE(r.plans.empty());
  // Tube 0 is lower (H 0.25 against 0.75) and has the lower G_cost, but tube 1 lies on it.
  EXPECT_EQ(r.plans.front().tube_id, 1u);
  EXPECT_EQ(r.plans.front().certainty, PlanCertainty::kSure);
  // H 0.75; the grasps nearest the middle (curve 0.15 of 0.30) are 1 cm from it.
  EXPECT_NEAR(r.plans.front().costs.total, 0.2 * 0.75 + 0.5 * 0.01 / 0.15, 1e-9);
  double tube0_best = 1.0;
  for (const PickPlan& p : r.plans) {
    if (p.tube_id != 0) continue;
    tube0_best = std::min(tube0_best, p.costs.total);
    EXPECT_EQ(p.certainty, PlanCertainty::kUnsure);
  }
  EXPECT_NEAR(tube0_best, 0.05, 1e-9);  // H 0.25, the middle grasp

  // The thesis' ranking (G_cost alone) takes the lower tube.
  PlanningParams thesis;
  thesis.certainty.safe_first = false;
  const PickPlanResult t = PlanPick(Model(LainOnTubes(false)), CellOf40cmTubes(), thesis, &evaluator, 0);
  ASSERT_FALSE(t.plans.empty());
  EXPECT_EQ(t.plans.front().tube_id, 0u);
  EXPECT_EQ(evaluator.calls, 0);
}

TEST(PickPlanner, ATubeLainOnIsSimulatedWhenNoSurePlanExists) {
  // Tube 1 cannot be grasped: tube 0's upward lift is simulated, and 1 cm of displacement is safe.
  FakeEvaluator gentle([](const Trajectory&) { return 0.01; });
  const PickPlanResult r =
      PlanPick(Model(LainOnTubes(true), BlockTube1()), CellOf40cmTubes(), PlanningParams{}, &gentle, 0);
  EXPECT_EQ(gentle.calls, 1);
  ASSERT_EQ(gentle.trajectories_seen.size(), 1u);
  EXPECT_EQ(gentle.trajectories_seen[0].tube_index, 0u);
  EXPECT_EQ(gentle.trajectories_seen[0].kind, TrajectoryKind::kUpward);
  ASSERT_FALSE(r.plans.empty());
  EXPECT_EQ(r.plans.front().tube_id, 0u);
  EXPECT_EQ(r.plans.front().certainty, PlanCertainty::kSimulated);
  EXPECT_EQ(r.planned_class, Occlusion::kNone);
  for (const PickPlan& p : r.plans) EXPECT_EQ(p.tube_id, 0u);  // a safe plan: no further stage

  // 10 cm is not safe: the weak stage is planned too, and its 2 cm escape outranks tube 0's lift
  // although that lift's G_cost is lower.
  FakeEvaluator rough([](const Trajectory& t) {
    if (t.tube_index == 0) return 0.10;
    return t.kind == TrajectoryKind::kUpward ? 0.30 : 0.02;
  });
  const PickPlanResult w =
      PlanPick(Model(LainOnTubes(true), BlockTube1()), CellOf40cmTubes(), PlanningParams{}, &rough, 0);
  EXPECT_EQ(rough.calls, 2);
  ASSERT_FALSE(w.plans.empty());
  const PickPlan& best = w.plans.front();
  EXPECT_EQ(best.tube_id, 2u);
  EXPECT_EQ(best.kind, TrajectoryKind::kEscape);
  EXPECT_EQ(best.certainty, PlanCertainty::kSimulated);
  EXPECT_EQ(w.planned_class, Occlusion::kWeak);
  double tube0_best = 1.0;
  for (const PickPlan& p : w.plans) {
    if (p.tube_id == 0) tube0_best = std::min(tube0_best, p.costs.total);
    if (p.tube_id == 2) {
      EXPECT_GE(p.trajectory_index, 2u);  // after the two upward lifts of stage 1
    }
  }
  EXPECT_LT(tube0_best, best.costs.total);
  EXPECT_EQ(w.counts.simulated_trajectories, 4u);  // tube 0 upward; tube 2 upward and two escapes
}

TEST(PickPlanner, InvalidParamsAreNamed) {
  EXPECT_NO_THROW(PlanningParams{}.Validate());
  PlanningParams p;
  p.grasps.spacing = 0.0;
  ExpectInvalid(p, "planning.grasps.spacing: must be > 0, got 0");
  p = PlanningParams{};
  p.trajectories.upward_distance = -0.4;
  ExpectInvalid(p, "planning.trajectories.upward_distance");
  p = PlanningParams{};
  p.cost.trajectory_weight = 0.4;
  ExpectInvalid(
      p, "planning.cost: height_weight + centre_weight + trajectory_weight must be 1, got 0.2 + 0.5 + 0.4");
  p = PlanningParams{};
  p.cost.max_displacement = 0.0;
  ExpectInvalid(p, "planning.cost.max_displacement");
  p = PlanningParams{};
  p.certainty.safe_displacement = -0.01;
  ExpectInvalid(p, "planning.certainty.safe_displacement");
  p = PlanningParams{};
  p.filters.workspace_min.z() = 2.0;
  ExpectInvalid(p, "planning.filters.workspace_min[2]: 2 exceeds workspace_max[2] 1");
  p = PlanningParams{};
  p.filters.finger_width = std::nan("");
  ExpectInvalid(p, "planning.filters.finger_width");
  p = PlanningParams{};
  p.grasps.max_axis_inclination = 2.0;
  ExpectInvalid(p, "planning.grasps.max_axis_inclination");
  p = PlanningParams{};
  p.classification.length_tolerance = -1.0;
  ExpectInvalid(p, "planning.classification.length_tolerance");
  // The opening must exceed the tube's diameter (2 × 0.0125).
  p = PlanningParams{};
  p.grasps.opening_width = 0.02;
  ExpectInvalid(p, "planning.grasps.opening_width: 0.02 must exceed the tube diameter");
  // The cell is validated too.
  CellConfig cell;
  cell.tube.radius = -1.0;
  ExpectInvalid(PlanningParams{}, "tube.radius", cell);
}

}  // namespace
}  // namespace tubepick

// Planning on generated scenes: physics drop -> virtual scan -> modeling -> planning with the
// Bullet trajectory evaluator, as the service will run it.
#include <gtest/gtest.h>

#include "core/modeling/model_tubes.h"
#include "core/params.h"
#include "core/planning/pick_planner.h"
#include "core/planning/plan_placement.h"
#include "physics/scene_generator.h"
#include "physics/trajectory_simulator.h"
#include "physics/virtual_scanner.h"

namespace tubepick {
namespace {

struct Planned {
  ModelingResult modeling;
  PickPlanResult plan;
};

Planned PlanGeneratedScene(int tubes, std::uint64_t seed) {
  const CellConfig cell;
  physics::SceneParams scene;
  scene.tube_count = tubes;
  scene.bin = cell.bin;
  const physics::DropResult drop = physics::GenerateScene(scene, seed);
  const physics::ScanResult scan = physics::ScanScene(drop.tubes, cell, physics::ScannerParams{}, seed);
  const Params params = ProfileParams("fast");
  ModelingInput input;
  input.points_Sensor = &scan.points_Sensor;
  input.X_BinSensor = cell.sensor.X_BinSensor;
  input.bin = cell.bin;
  input.seed = seed;
  Planned out;
  out.modeling = ModelTubes(input, params.modeling);
  physics::TrajectorySimParams sim;
  sim.bin = cell.bin;
  physics::BulletTrajectoryEvaluator evaluator(sim);
  out.plan = PlanPick(out.modeling, cell, params.planning, &evaluator, seed);
  AttachPlacements(out.modeling, cell.place.X_BinPlace, params.placement, &out.plan);
  return out;
}

TEST(PlanPipeline, GeneratedBinGivesRankedPlansWithPlacement) {
  const Planned p = PlanGeneratedScene(5, 11);
  ASSERT_FALSE(p.plan.bin_empty);
  ASSERT_FALSE(p.plan.plans.empty());
  for (std::size_t i = 0; i < p.plan.plans.size(); ++i) {
    const PickPlan& plan = p.plan.plans[i];
    if (i > 0) {
      EXPECT_LE(p.plan.plans[i - 1].costs.total, plan.costs.total);
    }
    EXPECT_GE(plan.costs.total, 0.0);
    EXPECT_LE(plan.costs.total, 1.0);
    ASSERT_FALSE(plan.waypoints.empty());
    EXPECT_EQ(plan.waypoints.front(), Eigen::Vector3d::Zero());
    EXPECT_GT(plan.waypoints.back().z(), 0.3);  // ends lifted
    // The grasp lies inside the bin, on a modeled tube.
    EXPECT_LT(std::abs(plan.grasp.p_Bin_grasp.x()), 0.4);
    EXPECT_LT(std::abs(plan.grasp.p_Bin_grasp.y()), 0.3);
    bool found = false;
    for (const Tube& t : p.plan.tubes) found = found || t.id == plan.tube_id;
    EXPECT_TRUE(found);
  }
  // The best plan picks a tube nothing lies on, without simulation (thesis §5.2.3.1).
  const PickPlan& best = p.plan.plans.front();
  for (const Tube& t : p.plan.tubes) {
    if (t.id == best.tube_id) {
      EXPECT_EQ(t.occlusion, Occlusion::kNone);
    }
  }
  EXPECT_EQ(best.kind, TrajectoryKind::kUpward);
  EXPECT_TRUE(best.X_BinTcp_place.has_value());
}

TEST(PlanPipeline, SameSeedSamePlans) {
  const Planned a = PlanGeneratedScene(4, 5);
  const Planned b = PlanGeneratedScene(4, 5);
  ASSERT_EQ(a.plan.plans.size(), b.plan.plans.size());
  for (std::size_t i = 0; i < a.plan.plans.size(); ++i) {
    EXPECT_EQ(a.plan.plans[i].tube_id, b.plan.plans[i].tube_id);
    EXPECT_EQ(a.plan.plans[i].costs.total, b.plan.plans[i].costs.total);
    EXPECT_TRUE(a.plan.plans[i].grasp.X_BinTcp.isApprox(b.plan.plans[i].grasp.X_BinTcp, 0.0));
  }
}

}  // namespace
}  // namespace tubepick

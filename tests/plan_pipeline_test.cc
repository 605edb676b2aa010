// Planning on generated scenes: physics drop -> virtual scan -> modeling -> planning with the
// Bullet trajectory evaluator, as the service will run it.
#include <cstdint>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

#include "core/modeling/model_tubes.h"
#include "core/params.h"
#include "core/planning/pick_planner.h"
#include "core/planning/plan_placement.h"
#include "physics/scene_generator.h"
#include "physics/trajectory_simulator.h"
#include "physics/virtual_scanner.h"
#include "wire/packed_cloud.h"

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

void ExpectSamePlans(const PickPlanResult& a, const PickPlanResult& b) {
  ASSERT_EQ(a.plans.size(), b.plans.size());
  for (std::size_t i = 0; i < a.plans.size(); ++i) {
    EXPECT_EQ(a.plans[i].tube_id, b.plans[i].tube_id) << "plan " << i;
    EXPECT_EQ(a.plans[i].costs.total, b.plans[i].costs.total) << "plan " << i;
    EXPECT_TRUE(a.plans[i].grasp.X_BinTcp.isApprox(b.plans[i].grasp.X_BinTcp, 0.0)) << "plan " << i;
  }
  EXPECT_EQ(a.counts.grasp_candidates, b.counts.grasp_candidates);
  EXPECT_EQ(a.counts.rejected_tool, b.counts.rejected_tool);
  EXPECT_EQ(a.counts.rejected_fingers, b.counts.rejected_fingers);
}

// The service's path (the packed bytes read in place, only the raw points a finger box can reach
// kept) plans exactly what the reference path (decoded points, every raw point kept) plans.
TEST(PlanPipeline, ServicePathPlansExactlyAsTheReferencePath) {
  const CellConfig cell;
  const Params params = ProfileParams("fast");
  std::uint64_t finger_rejections = 0;
  for (const std::uint64_t seed : {3u, 8u}) {
    physics::SceneParams scene;
    scene.tube_count = 10;
    scene.bin = cell.bin;
    const physics::DropResult drop = physics::GenerateScene(scene, seed);
    const physics::ScanResult scan = physics::ScanScene(drop.tubes, cell, physics::ScannerParams{}, seed);
    ModelingInput reference;
    reference.points_Sensor = &scan.points_Sensor;
    reference.X_BinSensor = cell.sensor.X_BinSensor;
    reference.bin = cell.bin;
    reference.seed = seed;
    const std::string bytes = PackXyz(scan.points_Sensor);  // as PlanPickRequest.cloud.xyz
    ModelingInput service = reference;
    service.points_Sensor = nullptr;
    service.xyz_Sensor = PackedXyz{bytes};
    service.raw_region_Bin = RawRegionForPlanning(params.planning, cell.bin);

    const ModelingResult a = ModelTubes(reference, params.modeling);
    const ModelingResult b = ModelTubes(service, params.modeling);
    EXPECT_EQ(a.filtered.points, b.filtered.points);
    EXPECT_EQ(a.filtered_source_index, b.filtered_source_index);
    ASSERT_EQ(a.tubes.size(), b.tubes.size());
    // The floor and the walls, most of the scan, are left out.
    EXPECT_LT(b.raw_Bin.size(), a.raw_Bin.size() / 4) << b.raw_Bin.size() << " of " << a.raw_Bin.size();

    const PickPlanResult plan_a = PlanPick(a, cell, params.planning, nullptr, seed);
    const PickPlanResult plan_b = PlanPick(b, cell, params.planning, nullptr, seed);
    ExpectSamePlans(plan_a, plan_b);
    finger_rejections += plan_a.counts.rejected_fingers;
  }
  EXPECT_GT(finger_rejections, 0u);  // the finger test was exercised
}

TEST(PlanPipeline, PlanningOnTooFewRawPointsIsAnError) {
  const CellConfig cell;
  const Params params = ProfileParams("fast");
  ModelingResult modeling;
  modeling.raw_region_Bin = RawRegion::None();
  EXPECT_THROW(PlanPick(modeling, cell, params.planning, nullptr, 0), std::logic_error);
  modeling.raw_region_Bin = RawRegionForPlanning(params.planning, cell.bin);
  EXPECT_NO_THROW(PlanPick(modeling, cell, params.planning, nullptr, 0));
}

}  // namespace
}  // namespace tubepick

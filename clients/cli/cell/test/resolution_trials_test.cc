#include "clients/cli/cell/resolution_trials.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <deque>
#include <vector>

#include "clients/cell/local_wrench_analysis.h"
#include "clients/cell/test/scripted_cell.h"
#include "clients/cli/cell/sim_round.h"
#include "core/common/errors.h"
#include "devices/sim/test/sim_test_util.h"

namespace tubepick::cli {
namespace {

using devices::sim::SimCell;
using devices::sim::SimCellParams;
using devices::sim::testing::PolylineTube;
using ::testing::HasSubstr;

/// Tube A (0.4 m, four cylinders) along x on the floor; tube B a bridge across it at x = 0.05, its
/// flat middle resting on A and its legs on the floor on both sides: lifting A carries B.
std::vector<physics::TubeGeometry> BridgedTubes(double r) {
  const double top = 3.0 * r + 0.001;
  return {PolylineTube(1, {{-0.2, 0.0, r}, {-0.1, 0.0, r}, {0.0, 0.0, r}, {0.1, 0.0, r}, {0.2, 0.0, r}}, r),
          PolylineTube(2, {{0.05, -0.22, r}, {0.05, -0.03, top}, {0.05, 0.03, top}, {0.05, 0.22, r}}, r)};
}

WrenchParams Resolution(ResolutionVariant variant) {
  WrenchParams wrench;
  wrench.variant = variant;
  return wrench;
}

TEST(SimShapes, TreesTellThePlannerTheirLengthTopologyAndJunctionLayout) {
  SimCellParams p = SimCellParams::Thesis(devices::sim::Material::kPvc, 20, 1);
  WithShapes("C", &p);
  EXPECT_EQ(p.cell.tube.topology, TubeTopology::kBranched);
  EXPECT_NEAR(p.cell.tube.length, 0.75, 1e-9);
  EXPECT_EQ(p.cell.tube.layout.junctions, 2u);
  EXPECT_NEAR(p.cell.tube.layout.junction_spacing, 0.30, 1e-9);
  EXPECT_NEAR(p.cell.tube.layout.branch_length, 0.15, 1e-9);
  SimCellParams linear = SimCellParams::Thesis(devices::sim::Material::kPvc, 20, 1);
  WithShapes("B", &linear);
  EXPECT_FALSE(linear.cell.tube.layout.known());
}

TEST(ResolutionTrials, ChoosesTheTubeAnotherLiesOnAtItsMiddle) {
  const SimCellParams params;
  SimCell cell(params, BridgedTubes(params.cell.tube.radius));
  const std::optional<TrialGrasp> grasp = ChooseTrialGrasp(cell, {});
  ASSERT_TRUE(grasp.has_value());
  EXPECT_EQ(grasp->tube, 0u);
  EXPECT_EQ(grasp->tubes_on_it, 1u);
  // The middle of a cylinder next to A's centre of mass, on A's axis.
  EXPECT_NEAR(std::abs(grasp->X_BinTcp.translation().x()), 0.05, 0.005);
  EXPECT_NEAR(grasp->X_BinTcp.translation().y(), 0.0, 0.005);
  // Nothing lies on B: once A is tried there is no trial grasp left.
  EXPECT_FALSE(ChooseTrialGrasp(cell, {0}).has_value());
}

/// A trial in the cell of BridgedTubes, with the torque-axis resolution.
class BridgedTrialTest : public ::testing::Test {
 protected:
  ResolutionTrial Run(const TrialParams& tp) {
    return RunResolutionTrial(cell, Resolution(ResolutionVariant::kTorqueAxis), tp);
  }
  const SimCellParams params;
  SimCell cell{params, BridgedTubes(params.cell.tube.radius)};
};

TEST_F(BridgedTrialTest, TheTorqueAxisTiltSlidesABridgedTubeOffIntoTheBin) {
  const ResolutionTrial trial = Run(TrialParams{});
  EXPECT_EQ(trial.fault, "");
  EXPECT_EQ(trial.lifts, 1u);
  EXPECT_TRUE(trial.multiple);
  EXPECT_EQ(trial.others_lifted, 1u);  // B hung from A, clear of the floor
  EXPECT_EQ(trial.motions_used, 1u);
  EXPECT_TRUE(trial.freed);
  EXPECT_TRUE(trial.tube_held);
  EXPECT_EQ(trial.others_outside, 0u);
  EXPECT_EQ(cell.TubesInBin(), 1u);  // B fell back; A is held above the bin
}

TEST_F(BridgedTrialTest, WithoutTheResolutionADoublePickIsPutBackAsTheControllerDoes) {
  TrialParams tp;
  tp.resolve = false;
  const ResolutionTrial trial = Run(tp);
  EXPECT_EQ(trial.fault, "");
  EXPECT_TRUE(trial.multiple);
  EXPECT_EQ(trial.motions_used, 0u);
  EXPECT_FALSE(trial.freed);
  // Their centre of mass near the bin's middle: back where they were lifted, and let go.
  EXPECT_EQ(trial.put_back_shift, 0.0);
  EXPECT_FALSE(trial.caught);
  EXPECT_FALSE(trial.tube_held);
  EXPECT_EQ(trial.others_outside, 0u);
  EXPECT_EQ(cell.TubesInBin(), 2u);
}

TEST_F(BridgedTrialTest, LoweredToRestTheTurnComesNoLowerThanTheGraspPlusReleaseHeight) {
  TrialParams tp;
  tp.controller.resolution_rest_load = 1.5;
  const ResolutionTrial trial = Run(tp);
  EXPECT_EQ(trial.fault, "");
  EXPECT_TRUE(trial.multiple);
  EXPECT_EQ(trial.others_lifted, 1u);
  // Let down in put_back_step steps: B, draped over A's middle, keeps more than half its weight on A
  // even with its legs on the floor, so the descent goes on to its limit, the grasp's height +
  // release_height, and stops there.
  EXPECT_NEAR(trial.lowered, tp.lift - tp.controller.release_height, 1e-6);
  EXPECT_EQ(trial.motions_used, 1u);
  EXPECT_TRUE(trial.freed);
  EXPECT_EQ(trial.others_outside, 0u);
}

TEST_F(BridgedTrialTest, AMotionBeyondTheRobotsWristLimitIsSkippedAndTheDoublePickPutBack) {
  WrenchParams wrench = Resolution(ResolutionVariant::kTorqueAxis);
  wrench.rotation_angle = 75.0 * M_PI / 180.0;  // the simulated arm tilts the tool 60° at most
  const ResolutionTrial trial = RunResolutionTrial(cell, wrench, TrialParams{});
  // Skipped as the controller skips it, not driven into the arm's joint-limit stop (a fault).
  EXPECT_EQ(trial.fault, "");
  EXPECT_TRUE(trial.multiple);
  EXPECT_EQ(trial.beyond_limits, 1u);
  EXPECT_EQ(trial.motions_used, 0u);
  EXPECT_FALSE(trial.freed);
  EXPECT_FALSE(trial.tube_held);  // put back
  EXPECT_EQ(trial.others_outside, 0u);
  EXPECT_EQ(cell.TubesInBin(), 2u);
}

std::string ErrorOf(const ResolutionTrialsOptions& o) {
  try {
    ValidateResolutionTrials(o);
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

TEST(ResolutionTrials, EveryBadOptionIsRefusedByNameBeforeATrialRuns) {
  EXPECT_EQ(ErrorOf(ResolutionTrialsOptions{}), "");
  auto with = [](auto change) {
    ResolutionTrialsOptions o;
    change(o);
    return ErrorOf(o);
  };
  EXPECT_THAT(with([](auto& o) {
                o.materials = {"pvc", "wood"};
              }),
              HasSubstr("--materials: unknown material 'wood'"));
  EXPECT_THAT(with([](auto& o) { o.variants = {"sideways"}; }), HasSubstr("--variants"));
  EXPECT_THAT(with([](auto& o) { o.angles_deg = {45.0, 0.8}; }), HasSubstr("--angles: 0.8"));
  EXPECT_THAT(with([](auto& o) { o.angles_deg = {120.0}; }), HasSubstr("--angles: 120°"));
  EXPECT_THAT(with([](auto& o) { o.shapes = "Q"; }), HasSubstr("--shapes: unknown random tube preset 'Q'"));
  EXPECT_THAT(with([](auto& o) { o.bins = 0; }), HasSubstr("--bins: 0"));
  EXPECT_THAT(with([](auto& o) { o.tubes = 1; }), HasSubstr("--tubes: 1"));
  EXPECT_THAT(with([](auto& o) { o.trial.lift = 0.0; }), HasSubstr("--lift: 0 m"));
  EXPECT_THAT(with([](auto& o) { o.trial.controller.resolution_dwell = -1.0; }), HasSubstr("--dwell: -1 s"));
  EXPECT_THAT(with([](auto& o) { o.trial.controller.resolution_wall_margin = -0.1; }),
              HasSubstr("--wall-margin: -0.1 m"));
  EXPECT_THAT(with([](auto& o) { o.trial.controller.put_back_margin = -0.2; }),
              HasSubstr("--put-back-margin: -0.2 m"));
  EXPECT_THAT(with([](auto& o) { o.trial.controller.put_back_step = -0.01; }),
              HasSubstr("--put-back-step: -0.01 m"));
  EXPECT_THAT(with([](auto& o) { o.trial.controller.resolution_rest_load = 0.5; }),
              HasSubstr("--rest-load: cell controller resolution_rest_load: 0.5 tube weights"));
}

// PlanPick from a queue; AnalyzeWrench is the real analysis (the fast profile's, as the server's).
class QueuePlanner final : public cell::PlannerClient {
 public:
  std::deque<v1::PlanPickResponse> answers;
  std::vector<v1::AnalyzeWrenchRequest> wrench_requests;

  v1::PlanPickResponse PlanPick(const v1::PlanPickRequest&, std::chrono::milliseconds) override {
    if (answers.empty())
      throw cell::PlannerError("PlanPick", grpc::StatusCode::UNAVAILABLE, "no answer left", 1);
    v1::PlanPickResponse a = answers.front();
    answers.pop_front();
    return a;
  }
  v1::AnalyzeWrenchResponse AnalyzeWrench(const v1::AnalyzeWrenchRequest& request,
                                          std::chrono::milliseconds) override {
    wrench_requests.push_back(request);
    return cell::LocalAnalyzeWrench(request, "fast");
  }
};

class MemorySink final : public cell::RecordSink {
 public:
  std::vector<nlohmann::json> records;
  void Write(const nlohmann::json& record) override { records.push_back(record); }
};

TEST(ResolutionInTheCell, TheControllerCarriesADoublePickOverTheBinsMiddleAndFreesItThere) {
  // The bridged pair off-centre: A from x = 0 to 0.3 m, grasped at its middle; B across it 0.1 m
  // further out. Lifted, the payload's centre of mass is about 0.05 m beyond the TCP; the controller
  // carries it over the bin's middle (TCP to x ≈ −0.05) before it turns the gripper.
  SimCellParams params;
  const double r = params.cell.tube.radius, top = 3.0 * r + 0.001;
  const std::vector<physics::TubeGeometry> tubes = {
      PolylineTube(1, {{0.0, 0.0, r}, {0.1, 0.0, r}, {0.2, 0.0, r}, {0.3, 0.0, r}}, r),
      PolylineTube(2, {{0.25, -0.22, r}, {0.25, -0.03, top}, {0.25, 0.03, top}, {0.25, 0.22, r}}, r)};
  SimCell sim(params, tubes);
  QueuePlanner planner;
  v1::PlanPickResponse plan = cell::testing::Plans({cell::testing::MakePlan(0, {0.15, 0.0, r})}, 2).response;
  v1::PlanPickResponse empty;  // the round ends when the planner says so
  empty.set_bin_empty(true);
  planner.answers = {plan, empty};
  MemorySink sink;
  cell::CellControllerParams controller;
  controller.disable_simulation = true;

  const SimRoundResult result = RunSimRound(planner, sim, controller, 0, &sink);
  EXPECT_EQ(result.run.picks, 1u) << result.run.message;
  EXPECT_EQ(result.tubes_in_bin, 1u);  // B fell back into the bin
  EXPECT_EQ(result.tubes_in_place_zone, 1u);
  EXPECT_EQ(result.tubes_elsewhere, 0u);

  nlohmann::json attempt;
  for (const nlohmann::json& record : sink.records)
    if (record.value("type", "") == "attempt") attempt = record;
  ASSERT_FALSE(attempt.is_null());
  EXPECT_EQ(attempt["analysis"]["outcome"], "multiple");
  EXPECT_EQ(attempt["resolution"]["used"], 1);
  EXPECT_EQ(attempt["resolution"]["succeeded"], true);
  EXPECT_NEAR(attempt["resolution"]["payload_offset"][0].get<double>(), 0.05, 0.02);
  EXPECT_NEAR(attempt["resolution"]["hold_shift"][0].get<double>(), -0.2, 0.02);
  // The analysis after the rotation was asked at the hold pose.
  ASSERT_EQ(planner.wrench_requests.size(), 2u);
  EXPECT_LT(planner.wrench_requests[1].tcp_pose().position().x(), 0.0);
}

}  // namespace
}  // namespace tubepick::cli

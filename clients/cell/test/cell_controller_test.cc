#include "clients/cell/cell_controller.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>
#include <thread>

#include "clients/cell/cell_statistics.h"
#include "clients/cell/test/scripted_cell.h"
#include "core/common/errors.h"
#include "core/wrench/resolution_hold.h"
#include "wire/proto_convert.h"

namespace tubepick::cell {
namespace {

using nlohmann::json;
using testing::AddTubeAxis;
using testing::DownPose;
using testing::Failure;
using testing::MakePlan;
using testing::Outcome;
using testing::Plans;

constexpr double kTol = 1e-9;

devices::WrenchReading Reading(double fz, double mx = 0.0, double my = 0.0) {
  devices::WrenchReading r;
  r.force = Eigen::Vector3d(0.0, 0.0, fz);
  r.torque = Eigen::Vector3d(mx, my, 0.0);
  return r;
}

devices::GripperStatus ClosedOnNothing() {
  devices::GripperStatus s;
  s.activated = true;
  s.object = devices::GripperObject::kAtPosition;
  return s;
}

class CellControllerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    params.ft_samples = 1;
    params.ft_settle_samples = 0;
    gripper.tcp = &robot.X_BinTcp;
    ft.holding = &gripper.holding;
  }

  CellRunResult Run() {
    CellController controller({&scanner, &robot, &gripper, &ft}, planner, cell, params, &sink);
    if (observer) controller.set_state_observer(observer);
    running = &controller;
    const CellRunResult result = controller.Run(3);
    running = nullptr;
    return result;
  }

  /// The dry run of plan MakePlan(4, p_Bin_grasp) against a run of the same plan: after the
  /// start's way home, the robot gets exactly the dry run's commands.
  void ExpectTheDryRunIsTheRun();
  DryRunResult DryRun() {
    CellController controller({&scanner, &robot, &gripper, &ft}, planner, cell, params, &sink);
    if (observer) controller.set_state_observer(observer);
    running = &controller;
    const DryRunResult result = controller.DryRun(3);
    running = nullptr;
    return result;
  }

  std::vector<json> Records(const std::string& type) const {
    std::vector<json> out;
    for (const json& r : sink.records())
      if (r.at("type") == type) out.push_back(r);
    return out;
  }

  /// Waypoint `X_BinTcp` added to motion `m` of `response`.
  static void AddWaypoint(v1::AnalyzeWrenchResponse& response, int m, const Eigen::Isometry3d& X_BinTcp) {
    *response.mutable_resolution_motions(m)->add_waypoints()->mutable_tcp_pose() = ToProto(X_BinTcp);
  }

  testing::ScriptedScanner scanner;
  testing::ScriptedRobot robot;
  testing::ScriptedGripper gripper;
  testing::ScriptedForceTorque ft;
  testing::ScriptedPlanner planner;
  MemoryRecordSink sink;
  CellConfig cell;
  CellControllerParams params;
  std::function<void(CellState)> observer;
  /// The controller of the Run / DryRun under way (for an observer that asks it to stop).
  CellController* running = nullptr;
  const Eigen::Vector3d p_Bin_grasp{0.1, -0.05, 0.03};
  /// The heights, in order, of the robot's stops above `p_xy` between z_min and z_max (a put-back's
  /// way down and back up; home's transit lies higher).
  std::vector<double> StopsOver(const Eigen::Vector3d& p_xy, double z_min, double z_max) const {
    std::vector<double> z;
    for (const auto& m : robot.moves) {
      const Eigen::Vector3d q = m.X_BinTcpTarget.translation();
      if ((q.head<2>() - p_xy.head<2>()).norm() < kTol && q.z() > z_min && q.z() < z_max + kTol)
        z.push_back(q.z());
    }
    return z;
  }
  /// The i-th of several grasps 4 cm apart (a 5 x 2 grid from p_Bin_grasp): a failed grasp's spot is
  /// not planned again (failed_grasp_radius), so scripted retries grasp elsewhere.
  Eigen::Vector3d GraspSpot(int i) const {
    return p_Bin_grasp + Eigen::Vector3d(-0.04 * (i % 5), 0.04 * (i / 5), 0.0);
  }
  /// Scan 1 plans one tube, lifted alone and placed; scan 2 sees the bin empty.
  void ScriptOneSinglePick() {
    planner.plan_answers = {Plans({MakePlan(4, p_Bin_grasp)}, 1)};
    ft.readings = {Reading(0.10), Reading(0.64)};
    planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)};
  }
  /// Scan 1 plans grasp A, which closes on nothing; scan 2 plans A again first, then B elsewhere.
  void ScriptGraspFailedThenSameGrasp() {
    params.max_plans_per_scan = 1;
    planner.plan_answers = {Plans({MakePlan(1, p_Bin_grasp)}, 2),
                            Plans({MakePlan(1, p_Bin_grasp), MakePlan(2, GraspSpot(4))}, 2)};
    gripper.close_results = {ClosedOnNothing()};
    planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)};
  }
};

TEST_F(CellControllerTest, EmptyBinAtFirstScanFinishesWithoutAttempts) {
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty);
  EXPECT_EQ(result.attempts, 0u);
  EXPECT_EQ(result.scans, 1u);
  EXPECT_TRUE(robot.servo_on);
  EXPECT_EQ(gripper.activations, 1);
  EXPECT_EQ(ft.biases, 1);
  // The scan was taken from home: above the place frame at transit height (wall 0.2 + 0.3 m).
  EXPECT_TRUE(robot.X_BinTcp.isApprox(HomePose(params, cell), kTol));
  EXPECT_NEAR(robot.X_BinTcp.translation().z(), 0.5, kTol);
  ASSERT_EQ(sink.records().size(), 1u);
  const json& end = sink.records()[0];
  EXPECT_EQ(end["type"], "end");
  EXPECT_EQ(end["reason"], "bin_empty");
  EXPECT_EQ(end["round"], 3);
  EXPECT_EQ(end["picks"], 0);
  // The request carried the cloud (2 points, 24 bytes) and the cell.
  ASSERT_EQ(planner.plan_requests.size(), 1u);
  EXPECT_EQ(planner.plan_requests[0].cloud().xyz().size(), 24u);
  EXPECT_DOUBLE_EQ(planner.plan_requests[0].cell().tube_mass(), cell.tube.mass);
  EXPECT_EQ(planner.plan_requests[0].options().seed(), params.seed);
}

TEST_F(CellControllerTest, ABinThatLooksEmptyShortOfItsTubesSaysHowManyAreUnaccountedFor) {
  // One tube placed, then the planner sees the bin empty: with tubes_per_bin = 3, two are missing.
  params.tubes_per_bin = 3;
  ScriptOneSinglePick();
  const CellRunResult result = Run();
  ASSERT_EQ(result.reason, CellStopReason::kBinEmpty) << result.message;
  EXPECT_EQ(result.picks, 1u);
  EXPECT_EQ(result.tubes_expected, 3u);
  EXPECT_EQ(result.tubes_unaccounted, 2u);
  EXPECT_THAT(DescribeRoundWarnings(result),
              ::testing::HasSubstr(
                  "; 2 of the bin's 3 tubes unaccounted for (tubes_per_bin): not placed and not seen in "
                  "the bin, they may have fallen out of it"));
  const std::vector<json> end = Records("end");
  ASSERT_EQ(end.size(), 1u);
  EXPECT_EQ(end[0]["tubes_expected"], 3);
  EXPECT_EQ(end[0]["tubes_unaccounted"], 2);
}

TEST_F(CellControllerTest, TheTubeCountIsQuietWhenMetOrNotKnownAndOnlyForABinFoundEmpty) {
  const auto run_one_pick = [&](std::uint32_t tubes_per_bin) {
    params.tubes_per_bin = tubes_per_bin;
    ScriptOneSinglePick();
    return Run();
  };
  const CellRunResult met = run_one_pick(1);
  EXPECT_EQ(met.picks, 1u);
  EXPECT_EQ(met.tubes_expected, 1u);
  EXPECT_EQ(met.tubes_unaccounted, 0u);
  EXPECT_EQ(DescribeTubeCount(met), "");
  const CellRunResult unknown = run_one_pick(0);
  EXPECT_EQ(unknown.tubes_expected, 0u);
  EXPECT_EQ(unknown.tubes_unaccounted, 0u);
  // A round stopped at a limit leaves tubes in the bin on purpose: nothing is counted.
  params.tubes_per_bin = 5;
  params.max_attempts_per_bin = 1;
  planner.plan_answers = {Plans({MakePlan(1, p_Bin_grasp)}, 2), Plans({MakePlan(1, GraspSpot(3))}, 2)};
  gripper.close_results = {ClosedOnNothing()};
  const CellRunResult limited = Run();
  ASSERT_EQ(limited.reason, CellStopReason::kLimitReached) << limited.message;
  EXPECT_EQ(limited.tubes_expected, 0u);
  EXPECT_EQ(limited.tubes_unaccounted, 0u);
  // More placed than the count: the count is wrong (said, nothing unaccounted).
  CellRunResult over;
  over.picks = 21;
  over.tubes_expected = 20;
  EXPECT_EQ(DescribeTubeCount(over),
            "; 21 tubes placed from a bin of 20 (tubes_per_bin): the count is wrong");
}

TEST_F(CellControllerTest, SinglePickIsPlacedAndRecorded) {
  ScriptOneSinglePick();

  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty) << result.message;
  EXPECT_EQ(result.picks, 1u);
  EXPECT_EQ(result.attempts, 1u);
  EXPECT_EQ(result.scans, 2u);

  // Pre-grasp 0.1 m above, grasp, lift 0.4 m, place, back home.
  const Eigen::Isometry3d X_BinTcpGrasp = DownPose(p_Bin_grasp);
  EXPECT_TRUE(robot.Visited(DownPose(p_Bin_grasp + Eigen::Vector3d(0, 0, 0.1))));
  EXPECT_TRUE(robot.Visited(X_BinTcpGrasp));
  EXPECT_TRUE(robot.Visited(DownPose(p_Bin_grasp + Eigen::Vector3d(0, 0, 0.4))));
  EXPECT_TRUE(robot.Visited(DownPose(Eigen::Vector3d(0.0, 0.8, 0.12))));
  EXPECT_TRUE(robot.X_BinTcp.isApprox(HomePose(params, cell), kTol));
  EXPECT_EQ(gripper.openings, std::vector<double>{0.045});
  EXPECT_TRUE(gripper.open);

  // AnalyzeWrench got the reference (taken before the grasp), the reading after the lift and the
  // lift pose.
  ASSERT_EQ(planner.wrench_requests.size(), 1u);
  const v1::AnalyzeWrenchRequest& w = planner.wrench_requests[0];
  EXPECT_DOUBLE_EQ(w.reference().force().z(), 0.10);
  EXPECT_DOUBLE_EQ(w.current().force().z(), 0.64);
  EXPECT_DOUBLE_EQ(w.tube_mass(), cell.tube.mass);
  EXPECT_NEAR(w.tcp_pose().position().z(), p_Bin_grasp.z() + 0.4, kTol);

  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 1u);
  const json& a = attempts[0];
  EXPECT_EQ(a["round"], 3);
  EXPECT_EQ(a["attempt"], 1);
  EXPECT_EQ(a["tube"], 4);
  EXPECT_EQ(a["tubes_left_plan"], 1);
  EXPECT_EQ(a["trajectory_kind"], "upward");
  EXPECT_EQ(a["used_simulation"], false);
  EXPECT_EQ(a["gripper"]["object"], "stopped_closing");
  EXPECT_EQ(a["analysis"]["outcome"], "single");
  EXPECT_DOUBLE_EQ(a["wrench"]["reference"]["force"][2].get<double>(), 0.10);
  EXPECT_DOUBLE_EQ(a["wrench"]["lift"]["force"][2].get<double>(), 0.64);
  EXPECT_EQ(a["resolution"]["used"], 0);
  EXPECT_EQ(a["result"], "picked");
  EXPECT_FALSE(a.contains("planner_warnings"));
  EXPECT_FALSE(a.contains("short_tubes_planned"));
  EXPECT_EQ(DescribePlannerWarnings(result), "");
  EXPECT_DOUBLE_EQ(a["grasp"]["tcp_pose"]["position"][0].get<double>(), p_Bin_grasp.x());
  EXPECT_GE(a["durations"]["planning_wall_s"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(a["durations"]["planning_server_s"].get<double>(), 0.5);
  EXPECT_EQ(Records("end").at(0)["picks"], 1);
}

TEST_F(CellControllerTest, APlanOfATubeTooShortForAWholeOneIsRecordedAsALastResort) {
  // Every tube of the scan was shorter than a whole one (a tree half hidden against a wall): the
  // planner planned them anyway and says so; the record keeps how many were too short.
  auto answer = Plans({MakePlan(4, p_Bin_grasp)}, 1);
  answer.response.mutable_counts()->set_too_short(1);
  answer.response.mutable_counts()->set_short_tubes_planned(true);
  planner.plan_answers.push_back(answer);
  ft.readings = {Reading(0.10), Reading(0.64)};
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));

  EXPECT_EQ(Run().picks, 1u);
  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 1u);
  EXPECT_EQ(attempts[0]["short_tubes_planned"], 1);
}

TEST_F(CellControllerTest, ThePlannersWarningsAboutTheCellAreInEveryAttemptRecord) {
  // The planner answers with its plans and a warning that the cell's tube.length is too short: the
  // controller picks as planned and each attempt record carries the warning's code and values.
  auto answer = Plans({MakePlan(4, p_Bin_grasp)}, 1);
  v1::ModelingWarning* w = answer.response.mutable_modeling()->add_warnings();
  w->set_code("tube_length_shorter_than_scan");
  w->set_message("tube.length 0.300 m: ...");
  w->set_stated(0.30);
  w->set_observed(0.48);
  planner.plan_answers.push_back(answer);
  ft.readings = {Reading(0.10), Reading(0.64)};
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));

  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u);
  // The second scan (bin empty) came without the warning: 1 of the round's 2 scans.
  EXPECT_EQ(result.scans, 2u);
  EXPECT_EQ(result.planner_warnings,
            (std::map<std::string, std::uint32_t>{{"tube_length_shorter_than_scan", 1}}));
  EXPECT_EQ(DescribePlannerWarnings(result),
            "; the planner warned: tube_length_shorter_than_scan in 1 of 2 scans (check the cell)");
  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 1u);
  ASSERT_TRUE(attempts[0].contains("planner_warnings"));
  const json& recorded = attempts[0]["planner_warnings"];
  ASSERT_EQ(recorded.size(), 1u);
  EXPECT_EQ(recorded[0]["code"], "tube_length_shorter_than_scan");
  EXPECT_DOUBLE_EQ(recorded[0]["stated"].get<double>(), 0.30);
  EXPECT_DOUBLE_EQ(recorded[0]["observed"].get<double>(), 0.48);
}

TEST_F(CellControllerTest, NothingGraspedOpensAndTriesTheNextPlanOfTheSameScan) {
  const Eigen::Vector3d p_Bin_other(-0.2, 0.1, 0.02);
  planner.plan_answers.push_back(Plans({MakePlan(1, p_Bin_grasp), MakePlan(2, p_Bin_other)}, 2));
  gripper.close_results = {ClosedOnNothing()};
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));

  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty);
  EXPECT_EQ(result.picks, 1u);
  EXPECT_EQ(result.attempts, 2u);
  EXPECT_EQ(planner.plan_requests.size(), 2u);  // the second plan came from the first scan
  EXPECT_EQ(gripper.closes, 2);
  EXPECT_TRUE(robot.Visited(DownPose(p_Bin_other)));

  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 2u);
  EXPECT_EQ(attempts[0]["result"], "grasp_failed");
  EXPECT_EQ(attempts[0]["gripper"]["object"], "at_position");
  EXPECT_FALSE(attempts[0].contains("analysis"));
  EXPECT_EQ(attempts[1]["result"], "picked");
  EXPECT_EQ(attempts[1]["scan"], 0);
  EXPECT_EQ(attempts[1]["plan_rank"], 1);
  EXPECT_EQ(attempts[1]["tube"], 2);
}

TEST_F(CellControllerTest, NothingGraspedOnTheLastPlanRescans) {
  params.max_plans_per_scan = 1;
  planner.plan_answers.push_back(Plans({MakePlan(1, p_Bin_grasp), MakePlan(2, GraspSpot(1))}, 2));
  planner.plan_answers.push_back(Plans({MakePlan(1, GraspSpot(2))}, 2));
  gripper.close_results = {ClosedOnNothing()};
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));

  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u);
  EXPECT_EQ(result.scans, 3u);
  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 2u);
  EXPECT_EQ(attempts[0]["result"], "grasp_failed");
  EXPECT_EQ(attempts[1]["scan"], 1);
  EXPECT_EQ(planner.plan_requests[1].options().seed(), params.seed + 1);  // a rescan gets a new seed
}

TEST_F(CellControllerTest, PlansTheToolCannotExecuteAreSkipped) {
  // Tube 1 lies 0.25 m from the bin's centre along y: the 0.13 m wide housing would reach 0.315 m,
  // past the +y wall at 0.30 m.
  const Eigen::Vector3d p_Bin_wall(0.0, 0.25, 0.03);
  planner.plan_answers.push_back(Plans({MakePlan(1, p_Bin_wall), MakePlan(2, p_Bin_grasp)}, 2));
  planner.plan_answers.push_back(Plans({MakePlan(1, p_Bin_wall)}, 1));
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));

  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u);
  EXPECT_EQ(result.attempts, 1u);
  EXPECT_FALSE(robot.Visited(DownPose(p_Bin_wall)));
  const std::vector<json> records = Records("attempt");
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[0]["tube"], 2);
  EXPECT_EQ(records[0]["plan_rank"], 1);
  ASSERT_EQ(records[0]["skipped_plans"].size(), 1u);
  EXPECT_EQ(records[0]["skipped_plans"][0]["tube"], 1);
  EXPECT_NE(records[0]["skipped_plans"][0]["reason"].get<std::string>().find("+y wall"), std::string::npos);
  // The second scan has only the unreachable plan: no attempt, a no_plan record, a rescan.
  EXPECT_EQ(records[1]["result"], "no_plan");
  EXPECT_EQ(records[1]["skipped_plans"].size(), 1u);
  EXPECT_EQ(result.scans, 3u);
}

TEST_F(CellControllerTest, PlansBeyondTheRobotsLimitsAreSkipped) {
  // The arm reaches z ≤ 0.35 m: plan 1 lifts 0.4 m, plan 2 only 0.3 m.
  robot.limits.reach_Bin = Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -0.1), Eigen::Vector3d(1, 1.2, 0.35));
  const std::vector<Eigen::Vector3d> short_lift_Bin{Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.3)};
  planner.plan_answers.push_back(Plans(
      {MakePlan(1, p_Bin_grasp), MakePlan(2, p_Bin_grasp, v1::TRAJECTORY_KIND_UPWARD, short_lift_Bin)}, 2));
  planner.plan_answers.push_back(Plans({}, 0));
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));

  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u);
  const std::vector<json> records = Records("attempt");
  ASSERT_GE(records.size(), 1u);
  EXPECT_EQ(records[0]["tube"], 2);
  ASSERT_EQ(records[0]["skipped_plans"].size(), 1u);
  const std::string reason = records[0]["skipped_plans"][0]["reason"];
  EXPECT_NE(reason.find("robot limits at the waypoint 1"), std::string::npos) << reason;
  EXPECT_NE(reason.find("out of reach"), std::string::npos) << reason;
  // A tilted wrist beyond the limit is named too.
  devices::RobotLimits limits;
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();  // z_Tcp up: 180° from straight down
  EXPECT_NE(limits.Problem(X_BinTcp).find("beyond the wrist limit"), std::string::npos);
  X_BinTcp.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();  // z down
  EXPECT_EQ(limits.Problem(X_BinTcp), "");
}

TEST_F(CellControllerTest, NoneAfterLiftOpensAndRescans) {
  planner.plan_answers.push_back(Plans({MakePlan(1, p_Bin_grasp)}, 3));
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_NONE, 0.05));

  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty);
  EXPECT_EQ(result.picks, 0u);
  EXPECT_EQ(result.scans, 2u);
  EXPECT_TRUE(gripper.open);
  EXPECT_FALSE(robot.Visited(DownPose(Eigen::Vector3d(0.0, 0.8, 0.12))));  // never went to place
  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 1u);
  EXPECT_EQ(attempts[0]["analysis"]["outcome"], "none");
  EXPECT_EQ(attempts[0]["result"], "none");
}

TEST_F(CellControllerTest, AGraspThatLiftedNothingIsNotTriedAgainUntilAPick) {
  // Scan 1: the grasp at A lifts nothing (a branch pinned under another tube slips out of the pads).
  // Scan 2 plans A again, 3 mm off, and B: A is skipped, B picks. Scan 3, after the pick: A is tried.
  const Eigen::Vector3d A = p_Bin_grasp;
  const Eigen::Vector3d B = GraspSpot(3);
  planner.plan_answers.push_back(Plans({MakePlan(1, A)}, 3));
  planner.plan_answers.push_back(
      Plans({MakePlan(1, A + Eigen::Vector3d(0.003, 0.0, 0.0)), MakePlan(2, B)}, 3));
  planner.plan_answers.push_back(Plans({MakePlan(1, A)}, 2));
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_NONE, 0.01), Outcome(v1::HELD_OUTCOME_SINGLE, 1.0),
                            Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)};

  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 2u);
  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 3u);
  EXPECT_EQ(attempts[0]["result"], "none");
  EXPECT_EQ(attempts[1]["tube"], 2);
  ASSERT_EQ(attempts[1]["skipped_plans"].size(), 1u);
  const json& skipped = attempts[1]["skipped_plans"][0];
  EXPECT_EQ(skipped["check"], "failed_grasp");
  EXPECT_EQ(skipped["tube"], 1);
  EXPECT_THAT(skipped["reason"].get<std::string>(),
              ::testing::HasSubstr("0.003 m from the grasp of attempt 1 (none) at (0.100, -0.050, 0.030) m"));
  EXPECT_EQ(attempts[2]["tube"], 1);
  EXPECT_TRUE(attempts[2]["skipped_plans"].empty());
  EXPECT_EQ(attempts[2]["result"], "picked");
}

TEST_F(CellControllerTest, AFailedGraspIsTriedAgainOnceTubesWerePutBack) {
  // Attempt 1 at A lifts nothing; attempt 2 at B lifts two tubes, which are put back: the bin changed,
  // so scan 3's grasp at A is executed again.
  planner.plan_answers = {Plans({MakePlan(1, p_Bin_grasp)}, 3), Plans({MakePlan(2, GraspSpot(3))}, 3),
                          Plans({MakePlan(1, p_Bin_grasp)}, 3)};
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_NONE, 0.01), Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.0),
                            Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)};
  Run();
  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 3u);
  EXPECT_EQ(attempts[0]["result"], "none");
  EXPECT_EQ(attempts[1]["result"], "multiple_returned");
  EXPECT_EQ(attempts[2]["tube"], 1);
  EXPECT_TRUE(attempts[2]["skipped_plans"].empty());
}

TEST_F(CellControllerTest, AGraspThatClosedOnNothingIsNotTriedAgain) {
  ScriptGraspFailedThenSameGrasp();
  EXPECT_EQ(Run().picks, 1u);
  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 2u);
  EXPECT_EQ(attempts[0]["result"], "grasp_failed");
  EXPECT_EQ(attempts[1]["tube"], 2);
  EXPECT_EQ(attempts[1]["skipped_plans"][0]["check"], "failed_grasp");
}

TEST_F(CellControllerTest, AFailedGraspRadiusOfZeroTriesTheSameGraspAgain) {
  ScriptGraspFailedThenSameGrasp();
  params.failed_grasp_radius = 0.0;
  EXPECT_EQ(Run().picks, 1u);
  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 2u);
  EXPECT_EQ(attempts[0]["result"], "grasp_failed");
  EXPECT_EQ(attempts[1]["tube"], 1);
  EXPECT_TRUE(attempts[1]["skipped_plans"].empty());
}

TEST_F(CellControllerTest, LiftsThatWeighNoWholeNumberOfTubesDoubtTubeMass) {
  // Tubes lighter than the cell's tube.mass says: each lift weighs about 0.75 tubes, Algorithm 3's
  // "none" every time. From the third such lift on, the records and the round's line name tube.mass.
  for (int i = 0; i < 3; ++i) planner.plan_answers.push_back(Plans({MakePlan(1, GraspSpot(i))}, 3));
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_NONE, 0.74), Outcome(v1::HELD_OUTCOME_NONE, 0.76),
                            Outcome(v1::HELD_OUTCOME_NONE, 0.75)};

  const CellRunResult result = Run();
  EXPECT_EQ(result.attempts, 3u);
  EXPECT_EQ(result.tube_mass_doubts, 1u);
  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 3u);
  EXPECT_FALSE(attempts[0].contains("tube_mass_doubt"));
  EXPECT_FALSE(attempts[1].contains("tube_mass_doubt"));
  ASSERT_TRUE(attempts[2].contains("tube_mass_doubt"));
  const json& doubt = attempts[2]["tube_mass_doubt"];
  EXPECT_EQ(doubt["lifts"], 3);
  EXPECT_DOUBLE_EQ(doubt["median_ratio"].get<double>(), 0.75);
  EXPECT_DOUBLE_EQ(doubt["mass_if_single"].get<double>(), 0.75 * cell.tube.mass);
  const std::string line = DescribeTubeMassDoubt(result);
  EXPECT_NE(line.find("the lifts doubt tube.mass after 1 of 3 attempts"), std::string::npos) << line;
  EXPECT_NE(line.find("0.74-0.76 times tube.mass"), std::string::npos) << line;
  // The decision stays Algorithm 3's: nothing was placed.
  EXPECT_EQ(result.picks, 0u);
  EXPECT_EQ(attempts[2]["result"], "none");
}

TEST_F(CellControllerTest, LiftsOfWholeTubesRaiseNoDoubt) {
  for (int i = 0; i < 3; ++i) planner.plan_answers.push_back(Plans({MakePlan(1, GraspSpot(i))}, 3));
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_NONE, 0.74), Outcome(v1::HELD_OUTCOME_NONE, 0.76),
                            Outcome(v1::HELD_OUTCOME_NONE, 0.85)};
  const CellRunResult result = Run();
  EXPECT_EQ(result.attempts, 3u);
  EXPECT_EQ(result.tube_mass_doubts, 0u);
  EXPECT_EQ(DescribeTubeMassDoubt(result), "");
}

TEST_F(CellControllerTest, TheTubeMassCheckTakesItsLimitsFromTheControllerParams) {
  for (int i = 0; i < 3; ++i) planner.plan_answers.push_back(Plans({MakePlan(1, GraspSpot(i))}, 3));
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_NONE, 0.74), Outcome(v1::HELD_OUTCOME_NONE, 0.76),
                            Outcome(v1::HELD_OUTCOME_NONE, 0.75)};
  params.tube_mass_check.limits.window = 2;
  params.tube_mass_check.limits.min_lifts = 2;
  const CellRunResult result = Run();
  EXPECT_EQ(result.attempts, 3u);
  EXPECT_EQ(result.tube_mass_doubts, 2u);  // from the second lift on
  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 3u);
  EXPECT_FALSE(attempts[0].contains("tube_mass_doubt"));
  ASSERT_TRUE(attempts[1].contains("tube_mass_doubt"));
  EXPECT_EQ(attempts[1]["tube_mass_doubt"]["lifts"], 2);
}

TEST_F(CellControllerTest, ATubeMassCheckTurnedOffRecordsNoDoubt) {
  for (int i = 0; i < 3; ++i) planner.plan_answers.push_back(Plans({MakePlan(1, GraspSpot(i))}, 3));
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_NONE, 0.74), Outcome(v1::HELD_OUTCOME_NONE, 0.76),
                            Outcome(v1::HELD_OUTCOME_NONE, 0.75)};
  params.tube_mass_check.enabled = false;
  const CellRunResult result = Run();
  EXPECT_EQ(result.attempts, 3u);
  EXPECT_EQ(result.tube_mass_doubts, 0u);
  for (const json& attempt : Records("attempt")) EXPECT_FALSE(attempt.contains("tube_mass_doubt"));
}

TEST_F(CellControllerTest, MultipleThenResolutionLeavesOneTubeWhichIsPlaced) {
  planner.plan_answers.push_back(
      Plans({MakePlan(5, p_Bin_grasp, v1::TRAJECTORY_KIND_ESCAPE,
                      {Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 0.02), Eigen::Vector3d(0.1, 0, 0.02),
                       Eigen::Vector3d(0.1, 0, 0.42)})},
            4, /*simulated=*/true));
  const Eigen::Isometry3d X_BinTcpLift = DownPose(p_Bin_grasp + Eigen::Vector3d(0.1, 0, 0.42));
  Eigen::Isometry3d X_BinTcpTilted = X_BinTcpLift;
  X_BinTcpTilted.linear() =
      X_BinTcpLift.linear() * Eigen::AngleAxisd(M_PI / 4, Eigen::Vector3d::UnitX()).toRotationMatrix();
  v1::AnalyzeWrenchResponse multiple = Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.1, 2);
  AddWaypoint(multiple, 0, X_BinTcpTilted);
  AddWaypoint(multiple, 1, X_BinTcpLift * Eigen::AngleAxisd(-M_PI / 4, Eigen::Vector3d::UnitX()));
  planner.wrench_answers = {multiple, Outcome(v1::HELD_OUTCOME_SINGLE, 1.02)};
  ft.readings = {Reading(0.1), Reading(1.3, 0.03, -0.01), Reading(0.66)};

  // The payload (1.2 N, its torque 0.03 / -0.01 N·m in the TCP axes) is first carried over the
  // bin's middle: the rotation turns about the TCP there.
  const ResolutionHold hold =
      PlanResolutionHold(devices::AsWrench(Reading(0.1)), devices::AsWrench(Reading(1.3, 0.03, -0.01)),
                         X_BinTcpLift, cell.bin.inner_size, params.resolution_wall_margin);
  ASSERT_GT(hold.shift_Bin.norm(), 0.05);
  const Eigen::Translation3d shift(hold.shift_Bin);

  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u) << result.message;
  EXPECT_FALSE(robot.Visited(X_BinTcpTilted));
  // Lift pose, hold pose, the rotation there, back to the hold pose, then on to the place pose.
  int tilted_index = -1;
  for (std::size_t i = 0; i < robot.moves.size(); ++i)
    if (robot.moves[i].X_BinTcpTarget.isApprox(shift * X_BinTcpTilted, kTol))
      tilted_index = static_cast<int>(i);
  ASSERT_GE(tilted_index, 1);
  EXPECT_TRUE(robot.moves[tilted_index - 1].X_BinTcpTarget.isApprox(shift * X_BinTcpLift, kTol));
  EXPECT_DOUBLE_EQ(robot.moves[tilted_index - 1].speed, params.lift_speed);
  EXPECT_TRUE(robot.moves[tilted_index + 1].X_BinTcpTarget.isApprox(shift * X_BinTcpLift, kTol));
  EXPECT_DOUBLE_EQ(robot.moves[tilted_index].speed, params.resolution_speed);
  // It paused at the tilt (resolution_dwell) before turning back, and nowhere else.
  ASSERT_EQ(robot.holds.size(), 1u);
  EXPECT_TRUE(robot.holds[0].X_BinTcp.isApprox(shift * X_BinTcpTilted, kTol));
  EXPECT_EQ(robot.holds[0].after_moves, static_cast<std::size_t>(tilted_index) + 1);
  EXPECT_DOUBLE_EQ(robot.holds[0].seconds, params.resolution_dwell);
  EXPECT_GT(params.resolution_dwell, 0.0);
  EXPECT_TRUE(robot.Visited(DownPose(Eigen::Vector3d(0.0, 0.8, 0.12))));
  // The second analysis used the same reference and the new reading at the lift pose.
  ASSERT_EQ(planner.wrench_requests.size(), 2u);
  EXPECT_DOUBLE_EQ(planner.wrench_requests[1].reference().force().z(), 0.1);
  EXPECT_DOUBLE_EQ(planner.wrench_requests[1].current().force().z(), 0.66);
  EXPECT_TRUE(
      FromProto(planner.wrench_requests[1].tcp_pose(), "tcp_pose").isApprox(shift * X_BinTcpLift, kTol));

  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["trajectory_kind"], "escape");
  EXPECT_EQ(a["used_simulation"], true);
  EXPECT_EQ(a["analysis"]["outcome"], "multiple");
  EXPECT_EQ(a["resolution"]["available"], 2);
  EXPECT_EQ(a["resolution"]["used"], 1);
  EXPECT_EQ(a["resolution"]["succeeded"], true);
  EXPECT_NEAR(a["resolution"]["hold_shift"][0].get<double>(), hold.shift_Bin.x(), 1e-12);
  EXPECT_NEAR(a["resolution"]["payload_offset"][1].get<double>(), hold.p_TcpPayload_Bin.y(), 1e-12);
  ASSERT_EQ(a["wrench"]["after_resolution"].size(), 1u);
  EXPECT_EQ(a["wrench"]["after_resolution"][0]["outcome"], "single");
  EXPECT_DOUBLE_EQ(a["wrench"]["lift"]["torque"][0].get<double>(), 0.03);
  EXPECT_EQ(a["result"], "picked");
}

TEST_F(CellControllerTest, WithoutTheHoldTheRotationTurnsAtTheLiftPose) {
  params.resolution_hold_over_bin = false;
  planner.plan_answers.push_back(Plans({MakePlan(5, p_Bin_grasp)}, 4));
  const Eigen::Isometry3d X_BinTcpLift = DownPose(p_Bin_grasp + Eigen::Vector3d(0, 0, 0.4));
  const Eigen::Isometry3d X_BinTcpTilted = X_BinTcpLift * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY());
  v1::AnalyzeWrenchResponse multiple = Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.0, 2);
  AddWaypoint(multiple, 0, X_BinTcpTilted);
  planner.wrench_answers = {multiple, Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)};
  ft.readings = {Reading(0.1), Reading(1.3, 0.03, -0.01), Reading(0.66)};

  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u) << result.message;
  EXPECT_TRUE(robot.Visited(X_BinTcpTilted));
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["resolution"]["hold_shift"], json::array({0.0, 0.0}));
}

/// A double pick whose first motion (about the lift reading's torque axis) frees nothing. The
/// lift plan's second motion turns -0.7 rad about y; the reading at the hold pose after the first
/// plans its own, 0.6 rad about x there. The second frees one tube either way.
class ResolutionReplanTest : public CellControllerTest {
 protected:
  /// The double pick and its lift plan's two motions, then `after`: the analyses of the readings
  /// (`readings`) at the hold pose after each motion driven.
  void Script(std::vector<v1::AnalyzeWrenchResponse> after, std::vector<devices::WrenchReading> readings) {
    planner.plan_answers.push_back(Plans({MakePlan(5, p_Bin_grasp)}, 4));
    v1::AnalyzeWrenchResponse multiple = Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.0, 2);
    AddWaypoint(multiple, 0, X_BinTcpLift * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY()));
    AddWaypoint(multiple, 1, X_BinTcpLift * Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitY()));
    planner.wrench_answers = {multiple};
    planner.wrench_answers.insert(planner.wrench_answers.end(), after.begin(), after.end());
    ft.readings = {Reading(0.1), Reading(1.3, 0.03, -0.01)};
    ft.readings.insert(ft.readings.end(), readings.begin(), readings.end());
    result = Run();
  }
  /// Several tubes still, and the motion planned from that reading: `angle` about `axis` at the
  /// hold pose.
  v1::AnalyzeWrenchResponse StillSeveral(double ratio, double angle, const Eigen::Vector3d& axis) {
    v1::AnalyzeWrenchResponse still = Outcome(v1::HELD_OUTCOME_MULTIPLE, ratio, 1);
    AddWaypoint(still, 0, Shift() * X_BinTcpLift * Eigen::AngleAxisd(angle, axis));
    return still;
  }
  /// Where the double pick is carried before the motions (PlanResolutionHold of the lift reading).
  Eigen::Translation3d Shift() const {
    return Eigen::Translation3d(PlanResolutionHold(devices::AsWrench(Reading(0.1)),
                                                   devices::AsWrench(Reading(1.3, 0.03, -0.01)), X_BinTcpLift,
                                                   cell.bin.inner_size, params.resolution_wall_margin)
                                    .shift_Bin);
  }
  void Drive(bool replan) {
    params.resolution_replan = replan;
    shift = Shift();
    Script({StillSeveral(1.9, 0.6, Eigen::Vector3d::UnitX()), Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)},
           {Reading(1.2, -0.02, 0.02), Reading(0.66)});
  }

  const Eigen::Isometry3d X_BinTcpLift = DownPose(p_Bin_grasp + Eigen::Vector3d(0, 0, 0.4));
  Eigen::Translation3d shift = Eigen::Translation3d::Identity();
  CellRunResult result;
};

TEST_F(ResolutionReplanTest, TheSecondMotionIsPlannedFromTheReadingAfterTheFirst) {
  Drive(/*replan=*/true);
  EXPECT_EQ(result.picks, 1u) << result.message;
  ASSERT_GT(shift.translation().norm(), 0.05);
  EXPECT_TRUE(robot.Visited(shift * X_BinTcpLift * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY())));
  // The hold pose's own motion, not shifted again; the lift plan's second motion not driven.
  EXPECT_TRUE(robot.Visited(shift * X_BinTcpLift * Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitX())));
  EXPECT_FALSE(robot.Visited(shift * X_BinTcpLift * Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitY())));
  EXPECT_FALSE(
      robot.Visited(shift * shift * X_BinTcpLift * Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitX())));
  // The reading it was planned from: taken at the hold pose after the first motion.
  ASSERT_EQ(planner.wrench_requests.size(), 3u);
  EXPECT_TRUE(
      FromProto(planner.wrench_requests[1].tcp_pose(), "tcp_pose").isApprox(shift * X_BinTcpLift, kTol));
  EXPECT_DOUBLE_EQ(planner.wrench_requests[1].current().torque().x(), -0.02);
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["resolution"]["replanned"], json::array({1}));
  EXPECT_EQ(a["resolution"]["used"], 2);
  EXPECT_EQ(a["resolution"]["succeeded"], true);
}

TEST_F(ResolutionReplanTest, WithoutReplanTheLiftPlansMotionsRunInOrder) {
  Drive(/*replan=*/false);
  EXPECT_EQ(result.picks, 1u) << result.message;
  EXPECT_TRUE(robot.Visited(shift * X_BinTcpLift * Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitY())));
  EXPECT_FALSE(robot.Visited(shift * X_BinTcpLift * Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitX())));
  const json a = Records("attempt").at(0);
  EXPECT_FALSE(a["resolution"].contains("replanned"));
  EXPECT_EQ(a["resolution"]["used"], 2);
  EXPECT_EQ(a["resolution"]["succeeded"], true);
}

/// Two motions that free nothing, then a third from the reading after the second
/// (resolution_extra_motions, 1) that frees one tube.
class ResolutionExtraMotionTest : public ResolutionReplanTest {
 protected:
  void DriveExtra(std::uint32_t extra) {
    params.resolution_extra_motions = extra;
    shift = Shift();
    Script({StillSeveral(1.9, 0.6, Eigen::Vector3d::UnitX()),
            StillSeveral(1.8, -0.5, Eigen::Vector3d::UnitX()), Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)},
           {Reading(1.2, -0.02, 0.02), Reading(1.1, 0.01, 0.03), Reading(0.66)});
  }
  const Eigen::Isometry3d X_BinTcpThird = X_BinTcpLift * Eigen::AngleAxisd(-0.5, Eigen::Vector3d::UnitX());
};

TEST_F(ResolutionExtraMotionTest, AThirdMotionFromTheReadingAfterTheSecondFreesWhatTwoDidNot) {
  DriveExtra(1);
  EXPECT_EQ(result.picks, 1u) << result.message;
  EXPECT_TRUE(robot.Visited(shift * X_BinTcpThird));
  // Planned from the reading after the second motion.
  ASSERT_EQ(planner.wrench_requests.size(), 4u);
  EXPECT_DOUBLE_EQ(planner.wrench_requests[2].current().torque().y(), 0.03);
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["resolution"]["available"], 2);
  EXPECT_EQ(a["resolution"]["replanned"], json::array({1, 2}));
  EXPECT_EQ(a["resolution"]["used"], 3);
  EXPECT_EQ(a["resolution"]["succeeded"], true);
  EXPECT_EQ(a["result"], "picked");
}

TEST_F(ResolutionExtraMotionTest, WithoutExtraMotionsTheTangleIsPutBackAfterThePlansTwo) {
  DriveExtra(0);
  EXPECT_EQ(result.picks, 0u);
  EXPECT_FALSE(robot.Visited(shift * X_BinTcpThird));
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["resolution"]["used"], 2);
  EXPECT_EQ(a["resolution"]["succeeded"], false);
  EXPECT_EQ(a["result"], "multiple_returned");
}

TEST_F(ResolutionExtraMotionTest, AReadingsMotionBeyondTheWristLimitEndsTheExtraMotions) {
  // The reading after the second motion plans a 0.8 rad turn, past a 0.75 rad wrist limit: skipped
  // once and recorded, and with no other motion from that reading the tangle goes back.
  robot.limits.max_tilt = 0.75;
  params.resolution_extra_motions = 3;
  shift = Shift();
  const Eigen::Isometry3d X_BinTcpTooFar = X_BinTcpLift * Eigen::AngleAxisd(0.8, Eigen::Vector3d::UnitX());
  Script({StillSeveral(1.9, 0.6, Eigen::Vector3d::UnitX()), StillSeveral(1.8, 0.8, Eigen::Vector3d::UnitX())},
         {Reading(1.2, -0.02, 0.02), Reading(1.1, 0.01, 0.03), Reading(1.1, 0.01, 0.03)});
  EXPECT_EQ(result.picks, 0u);
  EXPECT_FALSE(robot.Visited(shift * X_BinTcpTooFar));
  const json a = Records("attempt").at(0);
  ASSERT_EQ(a["resolution"]["beyond_limits"].size(), 1u) << a["resolution"].dump();
  EXPECT_EQ(a["resolution"]["beyond_limits"][0]["motion"], 2);
  EXPECT_EQ(a["resolution"]["used"], 2);
  EXPECT_EQ(a["result"], "multiple_returned");
}

/// resolution_rest_load: the tangle is let down from the hold pose in put_back_step steps (0.37 m
/// to the grasp + release_height in four of 0.0925 m here) until less than 1.5 tube weights hang on
/// the tool, and turned there.
class ResolutionRestLoadTest : public ResolutionReplanTest {
 protected:
  void SetUp() override {
    ResolutionReplanTest::SetUp();
    params.resolution_rest_load = 1.5;
    params.put_back_step = 0.1;
    ft.tcp = &robot.X_BinTcp;
    shift = Shift();
  }
  /// The lift plan's first motion, `down` below the hold pose.
  Eigen::Isometry3d Turned(double down) const {
    return Eigen::Translation3d(0.0, 0.0, -down) * shift * X_BinTcpLift *
           Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY());
  }
  const double step = (0.4 - params.release_height) / 4.0;
};

TEST_F(ResolutionRestLoadTest, TheTangleIsTurnedWhereTheHeapTakesTheOthers) {
  ASSERT_NEAR(X_BinTcpLift.translation().z() - p_Bin_grasp.z(), 0.4, 1e-12);
  // The heap takes the load from two steps down; one step down both tubes still hang.
  ft.rests_below_z = X_BinTcpLift.translation().z() - 1.5 * step;
  Script({Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)}, {Reading(1.3, 0.03, -0.01), Reading(0.66)});
  EXPECT_EQ(result.picks, 1u) << result.message;
  EXPECT_TRUE(robot.Visited(Turned(2.0 * step)));
  EXPECT_FALSE(robot.Visited(Turned(0.0)));
  EXPECT_FALSE(robot.Visited(Turned(step)));
  // Read at the hold pose again, not where it turned.
  ASSERT_EQ(planner.wrench_requests.size(), 2u);
  EXPECT_TRUE(
      FromProto(planner.wrench_requests[1].tcp_pose(), "tcp_pose").isApprox(shift * X_BinTcpLift, kTol));
  EXPECT_DOUBLE_EQ(planner.wrench_requests[1].current().force().z(), 0.66);
  const json a = Records("attempt").at(0);
  ASSERT_EQ(a["resolution"]["lowered"].size(), 1u);
  EXPECT_NEAR(a["resolution"]["lowered"][0].get<double>(), 2.0 * step, 1e-9);
  EXPECT_EQ(a["resolution"]["succeeded"], true);
}

TEST_F(ResolutionRestLoadTest, ALoadThatNeverGetsLighterIsTurnedNoLowerThanAPutBackGoes) {
  // Two tubes' weight at each of the three steps between: on down to the grasp + release_height (not
  // read there), turned there.
  Script({Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)},
         {Reading(1.3, 0.03, -0.01), Reading(1.3, 0.03, -0.01), Reading(1.3, 0.03, -0.01), Reading(0.66)});
  EXPECT_EQ(result.picks, 1u) << result.message;
  EXPECT_TRUE(robot.Visited(Turned(4.0 * step)));
  EXPECT_NEAR(Turned(4.0 * step).translation().z(), p_Bin_grasp.z() + params.release_height, 1e-9);
  const json a = Records("attempt").at(0);
  EXPECT_NEAR(a["resolution"]["lowered"][0].get<double>(), 0.4 - params.release_height, 1e-9);
  // The reading after the turn is the one at the hold pose (every scripted reading used, none left).
  EXPECT_TRUE(ft.readings.empty());
  EXPECT_DOUBLE_EQ(planner.wrench_requests.at(1).current().force().z(), 0.66);
}

TEST_F(CellControllerTest, MultipleAfterEveryResolutionIsLoweredIntoTheBinOpenedAndRescanned) {
  planner.plan_answers.push_back(Plans({MakePlan(5, p_Bin_grasp)}, 4));
  const Eigen::Isometry3d X_BinTcpLift = DownPose(p_Bin_grasp + Eigen::Vector3d(0, 0, 0.4));
  v1::AnalyzeWrenchResponse multiple = Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.0, 2);
  AddWaypoint(multiple, 0, X_BinTcpLift * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY()));
  AddWaypoint(multiple, 1, X_BinTcpLift * Eigen::AngleAxisd(-0.7, Eigen::Vector3d::UnitY()));
  planner.wrench_answers = {multiple, Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.0),
                            Outcome(v1::HELD_OUTCOME_MULTIPLE, 1.9)};
  ft.held_force = 2.0 * 1.08;  // two tubes' weight hangs on the tool ...
  ft.tcp = &robot.X_BinTcp;
  ft.rests_below_z = 0.25;        // ... until the heap takes it
  params.resolution_dwell = 0.0;  // turns back at once

  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty);
  EXPECT_EQ(result.picks, 0u);
  EXPECT_EQ(result.scans, 2u);
  EXPECT_EQ(planner.wrench_requests.size(), 3u);
  EXPECT_TRUE(robot.holds.empty());
  // Its centre of mass well inside the walls (no torque): lowered where it was lifted, straight down
  // in put_back_step steps reading the F/T (what hangs under the tube grasped meets the heap before
  // the grasp height), opened where the heap takes the load (0.25 m up here), back up.
  std::vector<double> stops = StopsOver(p_Bin_grasp, 0.2, 0.43);
  // (The resolution's turns and the way back from them stop at the lift height too: from the last.)
  while (stops.size() > 1 && std::abs(stops[1] - 0.43) < kTol) stops.erase(stops.begin());
  // The lift pose, equal steps of at most put_back_step towards the release height (0.37 m in 19)
  // down to the first at or below 0.25 m (the 10th, at 0.235 m), back up.
  const double release_z = p_Bin_grasp.z() + params.release_height;
  const int steps = static_cast<int>(std::ceil((0.43 - release_z) / params.put_back_step - 1e-9));
  const double step = (0.43 - release_z) / steps;
  const double z_open = 0.43 - step * std::ceil((0.43 - 0.25) / step - 1e-9);
  ASSERT_EQ(stops.size(), static_cast<std::size_t>(std::lround((0.43 - z_open) / step)) + 2);
  EXPECT_NEAR(stops.front(), 0.43, kTol);
  EXPECT_NEAR(stops[1], 0.43 - step, kTol);
  EXPECT_NEAR(stops[stops.size() - 2], z_open, kTol);
  EXPECT_LT(z_open, 0.25);
  EXPECT_GT(z_open, 0.25 - step);
  EXPECT_NEAR(stops.back(), 0.43, kTol);
  EXPECT_TRUE(std::any_of(gripper.opened_at.begin(), gripper.opened_at.end(), [&](const Eigen::Vector3d& p) {
    return p.isApprox(Eigen::Vector3d(p_Bin_grasp.x(), p_Bin_grasp.y(), z_open), kTol);
  }));
  EXPECT_FALSE(robot.Visited(DownPose(p_Bin_grasp + Eigen::Vector3d(0, 0, params.release_height))));
  EXPECT_FALSE(robot.Visited(DownPose(Eigen::Vector3d(0.0, 0.8, 0.12))));
  EXPECT_TRUE(gripper.open);

  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["resolution"]["used"], 2);
  EXPECT_EQ(a["resolution"]["succeeded"], false);
  EXPECT_EQ(a["wrench"]["after_resolution"].size(), 2u);
  EXPECT_EQ(a["resolution"]["put_back_shift"], json::array({0.0, 0.0}));
  EXPECT_NEAR(a["put_back_touchdown"]["above_release"].get<double>(),
              z_open - (p_Bin_grasp.z() + params.release_height), 1e-9);
  EXPECT_EQ(a["result"], "multiple_returned");
}

TEST_F(CellControllerTest, AReadingNoHangingLoadGivesIsPutBackWhereLiftedNotCarriedAway) {
  // Seed 14 of the 20-tree bins (2026-12-07): after a resolution motion the F/T read two trees'
  // weight with 1.9 N*m, a centre of mass 1.2 m from the TCP, and the put-back went 1.1 m over a
  // wall. Here 1.2 N with 0.98 N*m: 0.82 m, beyond a 0.5 m tube.
  planner.plan_answers.push_back(Plans({MakePlan(5, p_Bin_grasp)}, 4));
  const Eigen::Isometry3d X_BinTcpLift = DownPose(p_Bin_grasp + Eigen::Vector3d(0, 0, 0.4));
  v1::AnalyzeWrenchResponse multiple = Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.0, 1);
  AddWaypoint(multiple, 0, X_BinTcpLift * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY()));
  planner.wrench_answers = {multiple, Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.0)};
  ft.readings = {Reading(0.1), Reading(1.3, 0.03, -0.01), Reading(1.3, 0.9, -0.4)};
  ft.held_force = 2.0 * 1.08;
  ft.tcp = &robot.X_BinTcp;
  ft.rests_below_z = 0.25;
  params.resolution_dwell = 0.0;
  ASSERT_LT(cell.tube.length, 0.8);

  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 0u) << result.message;
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["result"], "multiple_returned");
  EXPECT_EQ(a["resolution"]["put_back_payload_implausible"], true);
  EXPECT_EQ(a["resolution"]["put_back_shift"], json::array({0.0, 0.0}));
  EXPECT_TRUE(std::any_of(gripper.opened_at.begin(), gripper.opened_at.end(), [&](const Eigen::Vector3d& p) {
    return std::abs(p.x() - p_Bin_grasp.x()) < kTol && std::abs(p.y() - p_Bin_grasp.y()) < kTol;
  }));
}

TEST_F(CellControllerTest, AResolutionMotionBeyondTheWristLimitIsSkippedNotDriven) {
  // The first motion turns the tool 0.7 rad past a 0.5 rad wrist limit (a tool tilted at the
  // grasp, turned further); the second stays within it and frees a tube.
  robot.limits.max_tilt = 0.5;
  params.resolution_hold_over_bin = false;  // turns about the lift pose itself
  planner.plan_answers.push_back(Plans({MakePlan(5, p_Bin_grasp)}, 4));
  const Eigen::Isometry3d X_BinTcpLift = DownPose(p_Bin_grasp + Eigen::Vector3d(0, 0, 0.4));
  const Eigen::Isometry3d X_BinTcpFar = X_BinTcpLift * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY());
  const Eigen::Isometry3d X_BinTcpNear = X_BinTcpLift * Eigen::AngleAxisd(-0.4, Eigen::Vector3d::UnitY());
  v1::AnalyzeWrenchResponse multiple = Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.0, 2);
  AddWaypoint(multiple, 0, X_BinTcpFar);
  AddWaypoint(multiple, 1, X_BinTcpNear);
  planner.wrench_answers = {multiple, Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)};

  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u) << result.message;
  EXPECT_FALSE(robot.Visited(X_BinTcpFar));
  EXPECT_TRUE(robot.Visited(X_BinTcpNear));
  // The pause at the tilt only where the tool went: not for the motion skipped.
  ASSERT_EQ(robot.holds.size(), 1u);
  EXPECT_TRUE(robot.holds[0].X_BinTcp.isApprox(X_BinTcpNear, kTol));
  EXPECT_EQ(planner.wrench_requests.size(), 2u);
  const json a = Records("attempt").at(0);
  ASSERT_EQ(a["resolution"]["beyond_limits"].size(), 1u);
  EXPECT_EQ(a["resolution"]["beyond_limits"][0]["motion"], 0);
  EXPECT_THAT(a["resolution"]["beyond_limits"][0]["problem"].get<std::string>(),
              ::testing::HasSubstr("waypoint 0: "));
  EXPECT_EQ(a["resolution"]["used"], 2);
  EXPECT_EQ(a["resolution"]["succeeded"], true);
}

/// The reading of a payload of `weight` newtons hanging at r_Bin (horizontal, bin frame) from a TCP
/// at orientation R_BinTcp, in the sensor's (TCP) axes, the empty tool reading zero.
devices::WrenchReading PayloadReading(const Eigen::Matrix3d& R_BinTcp, double weight,
                                      const Eigen::Vector3d& r_Bin) {
  const Eigen::Vector3d force_Bin(0.0, 0.0, -weight);
  devices::WrenchReading r;
  r.force = R_BinTcp.transpose() * force_Bin;
  r.torque = R_BinTcp.transpose() * r_Bin.cross(force_Bin);
  return r;
}

TEST_F(CellControllerTest, TubesNotFreedWithTheirCentreOfMassAtAWallArePutBackFurtherInside) {
  // Seed 14 of the 20-tree bins (2026-12-05): two trees lifted at the +x wall, their centre of mass
  // 1 cm inside it, lowered there: both fell over the wall. Here: TCP at x = 0.30 m, the centre of
  // mass 0.09 m further along +x (at 0.39 m in a 0.8 m bin), nothing to rotate.
  const Eigen::Vector3d p_Bin_wall_grasp(0.30, -0.05, 0.03);
  planner.plan_answers.push_back(Plans({MakePlan(5, p_Bin_wall_grasp)}, 4));
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.0)};
  const Eigen::Matrix3d R_BinTcp = DownPose(p_Bin_wall_grasp).linear();
  ft.readings = {devices::WrenchReading{}, PayloadReading(R_BinTcp, 1.08, {0.09, 0.0, 0.0})};

  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 0u) << result.message;
  // put_back_margin 0.15: the centre of mass to x = 0.25, the TCP to 0.16; y stays.
  const Eigen::Vector3d p_Bin_release(0.16, -0.05, 0.03 + params.release_height);
  EXPECT_TRUE(robot.Visited(DownPose(Eigen::Vector3d(0.16, -0.05, 0.43))));
  EXPECT_TRUE(std::any_of(gripper.opened_at.begin(), gripper.opened_at.end(),
                          [&](const Eigen::Vector3d& p) { return p.isApprox(p_Bin_release, kTol); }));
  // Nowhere did the gripper open over the place where the tubes were lifted.
  for (const Eigen::Vector3d& p : gripper.opened_at) EXPECT_GT(std::abs(p.x() - 0.30), 0.1) << p.transpose();
  const json a = Records("attempt").at(0);
  EXPECT_NEAR(a["resolution"]["put_back_payload_offset"][0].get<double>(), 0.09, 1e-9);
  EXPECT_NEAR(a["resolution"]["put_back_shift"][0].get<double>(), -0.14, 1e-9);
  EXPECT_NEAR(a["resolution"]["put_back_shift"][1].get<double>(), 0.0, 1e-9);
  EXPECT_EQ(a["result"], "multiple_returned");
}

TEST_F(CellControllerTest, WithoutAPutBackMarginTubesAtAWallGoDownWhereTheyWereLifted) {
  params.put_back_margin = 0.0;
  const Eigen::Vector3d p_Bin_wall_grasp(0.30, -0.05, 0.03);
  planner.plan_answers.push_back(Plans({MakePlan(5, p_Bin_wall_grasp)}, 4));
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.0)};
  ft.readings = {devices::WrenchReading{},
                 PayloadReading(DownPose(p_Bin_wall_grasp).linear(), 1.08, {0.09, 0.0, 0.0})};
  Run();
  EXPECT_TRUE(std::any_of(gripper.opened_at.begin(), gripper.opened_at.end(), [&](const Eigen::Vector3d& p) {
    return p.isApprox(p_Bin_wall_grasp + Eigen::Vector3d(0, 0, params.release_height), kTol);
  }));
  EXPECT_EQ(Records("attempt").at(0)["resolution"]["put_back_shift"], json::array({0.0, 0.0}));
}

/// A double pick at the +x wall (TCP at x = 0.30 m, the payload's centre of mass 0.09 m further):
/// put back 0.14 m further inside, over a heap it did not come up through.
class PutBackInsideTest : public CellControllerTest {
 protected:
  void SetUp() override {
    CellControllerTest::SetUp();
    planner.plan_answers.push_back(Plans({MakePlan(5, p_Bin_wall_grasp)}, 4));
    planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.0)};
    ft.tcp = &robot.X_BinTcp;
  }
  devices::WrenchReading Lifted() const {
    return PayloadReading(DownPose(p_Bin_wall_grasp).linear(), 1.08, {0.09, 0.0, 0.0});
  }
  const Eigen::Vector3d p_Bin_wall_grasp{0.30, -0.05, 0.03};
  const Eigen::Vector3d p_Bin_release{0.16, -0.05, 0.03 + params.release_height};
  const double top = 0.43;
  /// The put-back's stops at (0.16, -0.05), in order, up to the lift height (not home's transit).
  std::vector<double> Stops() const { return StopsOver(p_Bin_release, -1.0, top); }
};

TEST_F(PutBackInsideTest, TubesAreLetGoWhereTheyRestOnTheHeapNotPressedIntoIt) {
  ft.readings = {devices::WrenchReading{}, Lifted()};
  ft.rests_below_z = 0.25;  // the heap takes the load from 0.25 m down
  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 0u) << result.message;
  const int steps = static_cast<int>(std::ceil((top - p_Bin_release.z()) / params.put_back_step - 1e-9));
  const double step = (top - p_Bin_release.z()) / steps;
  const std::vector<double> stops = Stops();
  // The put-back pose, the steps down to the first at or below 0.25 m, back up to the put-back pose.
  ASSERT_GE(stops.size(), 3u);
  EXPECT_NEAR(stops.front(), top, kTol);
  EXPECT_NEAR(stops.back(), top, kTol);
  const double z_open = stops[stops.size() - 2];
  EXPECT_LE(z_open, 0.25 + kTol);
  EXPECT_GT(z_open + step, 0.25 + kTol);
  EXPECT_EQ(stops.size(), static_cast<std::size_t>(std::lround((top - z_open) / step)) + 2);
  EXPECT_TRUE(std::any_of(gripper.opened_at.begin(), gripper.opened_at.end(), [&](const Eigen::Vector3d& p) {
    return p.isApprox(Eigen::Vector3d(0.16, -0.05, z_open), kTol);
  }));
  const json a = Records("attempt").at(0);
  EXPECT_NEAR(a["put_back_touchdown"]["above_release"].get<double>(), z_open - p_Bin_release.z(), 1e-9);
  EXPECT_NEAR(a["put_back_touchdown"]["load"].get<double>(), 0.0, 1e-9);
}

TEST_F(PutBackInsideTest, OverALowHeapTubesGoDownToTheReleaseHeightInSteps) {
  ft.readings = {devices::WrenchReading{}, Lifted()};
  Run();
  const std::vector<double> stops = Stops();
  const int steps = static_cast<int>(std::ceil((top - p_Bin_release.z()) / params.put_back_step - 1e-9));
  // The put-back pose, steps - 1 stops on the way, the release, back up.
  ASSERT_EQ(stops.size(), static_cast<std::size_t>(steps) + 2);
  for (int k = 0; k <= steps; ++k)
    EXPECT_NEAR(stops[k], top - (top - p_Bin_release.z()) * k / steps, kTol) << k;
  EXPECT_TRUE(std::any_of(gripper.opened_at.begin(), gripper.opened_at.end(),
                          [&](const Eigen::Vector3d& p) { return p.isApprox(p_Bin_release, kTol); }));
  EXPECT_FALSE(Records("attempt").at(0).contains("put_back_touchdown"));
}

TEST_F(PutBackInsideTest, TubesWhoseReadingsDisagreeGoOnDownNotDroppedThere) {
  // A tangle touching the heap swings and slides: the readings of the first step disagree. Seed 14
  // of the 20-tree bins, opened there (0.10 m above the release height), lost three trees.
  params.ft_samples = 3;
  params.ft_unsettled_retries = 0;
  const devices::WrenchReading none{}, lifted = Lifted();
  devices::WrenchReading swing = lifted;
  ft.readings = {none, none, none, lifted, lifted, lifted, swing, swing, swing};
  ft.readings[6].force.z() += 10.0;
  ft.readings[8].force.z() -= 12.0;
  ft.readings.push_back(lifted);
  const CellRunResult result = Run();
  EXPECT_FALSE(result.fault) << result.message;
  EXPECT_TRUE(std::any_of(gripper.opened_at.begin(), gripper.opened_at.end(),
                          [&](const Eigen::Vector3d& p) { return p.isApprox(p_Bin_release, kTol); }));
  const json a = Records("attempt").at(0);
  ASSERT_EQ(a["wrench"]["put_back_unsettled"].size(), 1u);
  const int steps = static_cast<int>(std::ceil((top - p_Bin_release.z()) / params.put_back_step - 1e-9));
  EXPECT_NEAR(a["wrench"]["put_back_unsettled"][0].get<double>(), top - (top - p_Bin_release.z()) / steps,
              1e-9);
  EXPECT_FALSE(a.contains("put_back_touchdown"));
}

TEST_F(PutBackInsideTest, WithoutStepsTubesGoDownInOneMove) {
  params.put_back_step = 0.0;
  ft.readings = {devices::WrenchReading{}, Lifted()};
  ft.rests_below_z = 0.25;  // not read
  Run();
  EXPECT_EQ(Stops().size(), 3u);  // the put-back pose, the release, back up
  EXPECT_TRUE(std::any_of(gripper.opened_at.begin(), gripper.opened_at.end(),
                          [&](const Eigen::Vector3d& p) { return p.isApprox(p_Bin_release, kTol); }));
}

TEST_F(CellControllerTest, AttemptLimitPerTubeStopsWithTheReason) {
  params.max_attempts_per_tube = 3;
  params.max_plans_per_scan = 1;
  for (int i = 0; i < 5; ++i) planner.plan_answers.push_back(Plans({MakePlan(1, GraspSpot(i))}, 2));
  for (int i = 0; i < 5; ++i) gripper.close_results.push_back(ClosedOnNothing());

  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kLimitReached);
  EXPECT_EQ(result.attempts, 3u);
  EXPECT_NE(result.message.find("max_attempts_per_tube = 3: 3 × grasp_failed)"), std::string::npos)
      << result.message;
  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 3u);
  for (const json& a : attempts) EXPECT_EQ(a["result"], "grasp_failed");
  const json end = Records("end").at(0);
  EXPECT_EQ(end["reason"], "limit_reached");
  EXPECT_EQ(end["message"], result.message);
  EXPECT_TRUE(Records("safe_stop").empty());
}

TEST_F(CellControllerTest, AnAttemptLimitSaysWhatEachLiftSinceTheLastPickWeighed) {
  // Tubes twice as heavy as tube.mass: every lift weighs two tubes, which fits a double pick, so no
  // tube.mass doubt; the limit's message shows the same two tubes every time.
  params.max_attempts_per_tube = 3;
  for (int i = 0; i < 4; ++i) planner.plan_answers.push_back(Plans({MakePlan(1, p_Bin_grasp)}, 3));
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_SINGLE, 1.01), Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.02),
                            Outcome(v1::HELD_OUTCOME_MULTIPLE, 1.97),
                            Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.06)};
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kLimitReached);
  EXPECT_EQ(result.picks, 1u);
  EXPECT_EQ(result.attempts, 4u);
  // The pick's lift is not among them: the list starts after it.
  EXPECT_NE(result.message.find("(max_attempts_per_tube = 3: multiple 2.02 tubes, multiple 1.97 tubes, "
                                "multiple 2.06 tubes)"),
            std::string::npos)
      << result.message;
  EXPECT_EQ(result.tube_mass_doubts, 0u);
}

TEST_F(CellControllerTest, AnAttemptLimitListsTheLastEightAttempts) {
  // Eleven failures since the last pick: two scans without plan, then a failed grasp and a scan without
  // plan in turn: ten entries, the last eight shown, the three failures before them counted.
  params.max_attempts_per_tube = 20;
  params.max_consecutive_failures = 11;
  params.max_plans_per_scan = 1;
  planner.plan_answers.push_back(Plans({}, 2));
  for (int i = 0; i < 5; ++i) {
    planner.plan_answers.push_back(Plans({}, 2));
    planner.plan_answers.push_back(Plans({MakePlan(1, GraspSpot(i))}, 2));
    gripper.close_results.push_back(ClosedOnNothing());
  }
  const CellRunResult result = Run();
  EXPECT_EQ(result.attempts, 5u);
  EXPECT_NE(result.message.find("since the last pick: 3 earlier, then no plan, grasp_failed, no plan, "
                                "grasp_failed, no plan, grasp_failed, no plan, grasp_failed)"),
            std::string::npos)
      << result.message;
}

TEST_F(CellControllerTest, AnAttemptLimitCountsARunOfTheSameOutcomeOnce) {
  params.max_attempts_per_tube = 10;
  params.max_consecutive_failures = 20;
  params.max_plans_per_scan = 1;
  for (int i = 0; i < 10; ++i) planner.plan_answers.push_back(Plans({MakePlan(1, GraspSpot(i))}, 2));
  for (int i = 0; i < 10; ++i) gripper.close_results.push_back(ClosedOnNothing());
  const CellRunResult result = Run();
  EXPECT_EQ(result.attempts, 10u);
  EXPECT_NE(result.message.find("(max_attempts_per_tube = 10: 10 × grasp_failed)"), std::string::npos)
      << result.message;
}

TEST_F(CellControllerTest, ScansWithoutPlanCountAsConsecutiveFailures) {
  params.max_consecutive_failures = 2;
  for (int i = 0; i < 3; ++i) planner.plan_answers.push_back(Plans({}, 1));

  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kLimitReached);
  EXPECT_EQ(result.attempts, 0u);
  EXPECT_NE(result.message.find("2 consecutive failures (max_consecutive_failures = 2; since the last pick: "
                                "2 × no plan)"),
            std::string::npos)
      << result.message;
  const std::vector<json> records = Records("attempt");
  ASSERT_EQ(records.size(), 2u);
  EXPECT_EQ(records[0]["result"], "no_plan");
  EXPECT_TRUE(records[0]["attempt"].is_null());
}

/// A PlanPick answer without plans whose one modeled tube lies along the −y wall (axis 3 cm from it).
testing::ScriptedPlanner::PlanAnswer WallTubeWithoutPlan() {
  testing::ScriptedPlanner::PlanAnswer a = Plans({}, 0);
  v1::Tube* tube = a.response.add_tubes();
  tube->set_id(0);
  tube->set_occlusion(v1::OCCLUSION_NONE);
  v1::Cylinder* c = tube->add_cylinders();
  *c->mutable_start() = ToProto(Eigen::Vector3d(-0.2, -0.27, 0.0125));
  *c->mutable_end() = ToProto(Eigen::Vector3d(0.2, -0.27, 0.0125));
  c->set_radius(0.0125);
  return a;
}

TEST_F(CellControllerTest, TubeAlongAWallWithoutExecutablePlanIsNudgedThenPicked) {
  planner.plan_answers.push_back(WallTubeWithoutPlan());
  planner.plan_answers.push_back(Plans({MakePlan(0, p_Bin_grasp)}, 1));
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));

  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty);
  EXPECT_EQ(result.nudges, 1u);
  EXPECT_EQ(result.picks, 1u);
  EXPECT_EQ(result.attempts, 1u);  // the nudge is not a picking attempt
  EXPECT_EQ(result.scans, 3u);
  EXPECT_EQ(gripper.closes, 2);  // closed for the nudge, then on the tube

  const std::vector<json> records = Records("attempt");
  ASSERT_EQ(records.size(), 2u);
  const json& nudge = records[0];
  EXPECT_EQ(nudge["result"], "nudge");
  EXPECT_TRUE(nudge["attempt"].is_null());
  EXPECT_EQ(nudge["nudge"]["tube"], 0);
  EXPECT_NEAR(nudge["nudge"]["direction"][1].get<double>(), 1.0, kTol);
  EXPECT_NEAR(nudge["nudge"]["wall_distance"].get<double>(), 0.03, 1e-9);
  const double distance = nudge["nudge"]["distance"].get<double>();
  EXPECT_NEAR(distance, params.nudge.max_push, kTol);  // 2 · (0.15 − 0.03) = 0.24 → 0.22
  EXPECT_GT(nudge["durations"]["robot_wall_s"].get<double>(), 0.0);
  EXPECT_EQ(records[1]["result"], "picked");

  // The robot pressed at the planned pose and pushed along +y by the planned distance.
  bool pushed = false;
  for (const testing::ScriptedRobot::Move& m : robot.moves) {
    if (m.through && m.waypoints_Bin.size() == 2 &&
        m.waypoints_Bin.back().isApprox(Eigen::Vector3d(0.0, distance, 0.0), 1e-12)) {
      pushed = true;
      EXPECT_DOUBLE_EQ(m.speed, params.nudge.speed);
    }
  }
  EXPECT_TRUE(pushed);
  EXPECT_EQ(Records("end").back()["nudges"], 1);
}

TEST_F(CellControllerTest, TheNudgeMovesItsFingersOnlyAboveTheWalls) {
  // In a heap as high as the walls, fingers that open at the approach height sweep into the next
  // tube. The nudge closes them before it goes down and opens them back up at the transit height.
  planner.plan_answers.push_back(WallTubeWithoutPlan());
  const CellRunResult result = Run();
  EXPECT_EQ(result.nudges, 1u);
  EXPECT_EQ(Records("attempt")[0]["result"], "nudge");
  const double transit_height = TransitHeight(params, cell);
  ASSERT_EQ(gripper.closed_at.size(), 1u);
  EXPECT_GE(gripper.closed_at[0].z(), transit_height - kTol) << gripper.closed_at[0].transpose();
  // Opened once at the start of the round (home), once after the nudge: straight over the pushed pose.
  ASSERT_EQ(gripper.opened_at.size(), 2u);
  const json nudge = Records("attempt")[0]["nudge"];
  const Eigen::Vector3d p_Bin_press(nudge["tcp_pose"]["position"][0].get<double>(),
                                    nudge["tcp_pose"]["position"][1].get<double>(),
                                    nudge["tcp_pose"]["position"][2].get<double>());
  const Eigen::Vector3d push(0.0, nudge["distance"].get<double>(), 0.0);  // along +y
  const Eigen::Vector3d& opened = gripper.opened_at[1];
  EXPECT_NEAR(opened.z(), transit_height, kTol);
  EXPECT_TRUE(opened.head<2>().isApprox((p_Bin_press + push).head<2>(), kTol)) << opened.transpose();
  // The check after the push compares closed pads with closed pads: both read before the open.
  EXPECT_TRUE(Records("attempt")[0]["wrench"].contains("after_nudge"));
}

TEST_F(CellControllerTest, NudgesStopAtTheirLimitAndScansThenOnlyRescan) {
  params.nudge.max_nudges_per_bin = 2;
  for (int i = 0; i < 4; ++i) planner.plan_answers.push_back(WallTubeWithoutPlan());

  const CellRunResult result = Run();
  EXPECT_EQ(result.nudges, 2u);
  const std::vector<json> records = Records("attempt");
  ASSERT_EQ(records.size(), 4u);
  EXPECT_EQ(records[0]["result"], "nudge");
  EXPECT_EQ(records[1]["result"], "nudge");
  EXPECT_EQ(records[2]["result"], "no_plan");
  EXPECT_EQ(records[3]["result"], "no_plan");
  EXPECT_EQ(gripper.closes, 2);
  // Every one of them counted as a consecutive failure.
  params.max_consecutive_failures = 1;
  planner.plan_answers.push_back(WallTubeWithoutPlan());
  planner.plan_answers.push_back(WallTubeWithoutPlan());
  const CellRunResult limited = Run();
  EXPECT_EQ(limited.reason, CellStopReason::kLimitReached);
  EXPECT_EQ(limited.nudges, 1u);
  EXPECT_NE(limited.message.find("(max_consecutive_failures = 1; since the last pick: no plan, nudged tube "),
            std::string::npos)
      << limited.message;
}

TEST_F(CellControllerTest, ANudgeThatMovedNothingIsNotRepeated) {
  // The same tube along the wall in every scan: the nudges press at 0.5, 0.3 and 0.7 of its length;
  // the fourth would press at 0.5 again, where the first moved nothing.
  params.max_consecutive_failures = 5;
  for (int i = 0; i < 5; ++i) planner.plan_answers.push_back(WallTubeWithoutPlan());
  const CellRunResult result = Run();
  EXPECT_EQ(result.nudges, 3u);
  EXPECT_EQ(result.reason, CellStopReason::kLimitReached);
  const std::vector<json> records = Records("attempt");
  ASSERT_EQ(records.size(), 5u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(records[i]["result"], "nudge") << i;
  EXPECT_EQ(records[3]["result"], "no_plan");
  ASSERT_TRUE(records[3].contains("nudge_not_repeated"));
  const std::string reason = records[3]["nudge_not_repeated"]["reason"].get<std::string>();
  EXPECT_THAT(reason, ::testing::HasSubstr("tube 0 not nudged again: "
                                           "its contact at (0.000, -0.270, 0.013) m, 0.030 m from a wall, "
                                           "is 0.000 m from the nudge of scan 0, which did not move it "
                                           "(nudge.repeat_radius 0.005 m): it may be caught"));
  EXPECT_NEAR(records[3]["nudge_not_repeated"]["nudge"]["contact"][0].get<double>(),
              records[0]["nudge"]["contact"][0].get<double>(), 1e-9);
  EXPECT_THAT(result.message,
              ::testing::HasSubstr("nudged tube 0, 2 × "
                                   "no plan, tube 0 not nudged again (the last nudge there moved nothing)"));
  // Without the rule, the fourth and fifth scans nudge again.
  params.nudge.repeat_radius = 0.0;
  sink = MemoryRecordSink{};
  for (int i = 0; i < 5; ++i) planner.plan_answers.push_back(WallTubeWithoutPlan());
  EXPECT_EQ(Run().nudges, 5u);
}

TEST_F(CellControllerTest, NudgeDisabledOrWithoutGeometryIsANoPlanScan) {
  params.nudge.enabled = false;
  planner.plan_answers.push_back(WallTubeWithoutPlan());
  EXPECT_EQ(Run().nudges, 0u);
  EXPECT_EQ(Records("attempt").back()["result"], "no_plan");
  EXPECT_EQ(gripper.closes, 0);
}

TEST_F(CellControllerTest, RobotFaultDuringANudgeEndsInSafeStopAndIsRecorded) {
  robot.fail_through_from = 0;  // the push is the first MoveThrough
  planner.plan_answers.push_back(WallTubeWithoutPlan());

  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kFault);
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "robot");
  EXPECT_EQ(result.fault->state(), "nudge");
  const std::vector<json> records = Records("attempt");
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0]["result"], "fault");
  EXPECT_TRUE(records[0].contains("nudge"));
  EXPECT_EQ(records[0]["fault"]["state"], "nudge");
}

TEST_F(CellControllerTest, ATubeCaughtOnTheToolAfterANudgeIsNotCarriedHome) {
  // The reference above the press, then 0.60 N more after the push, and still after lowering the
  // tool into the bin once, and when the safe stop has opened over the bin: a hose hooked over a pad.
  planner.plan_answers.push_back(WallTubeWithoutPlan());
  ft.readings = {Reading(0.02), Reading(0.62), Reading(0.62), Reading(0.62)};

  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kFault);
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "ft_sensor");
  EXPECT_EQ(result.fault->kind(), FaultKind::kUnexpectedLoad);
  EXPECT_EQ(result.fault->state(), "nudge");
  EXPECT_THAT(result.fault->error(), ::testing::HasSubstr("carries 0.60 N (1.1 times a tube's weight)"));
  EXPECT_THAT(result.fault->error(), ::testing::HasSubstr("caught on the pads or the housing"));
  // Not carried home: the safe stop lowered it over the bin's middle and opened there; the load
  // still hangs on the tool (the fourth reading), so the arm stays there, inside the bin.
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->held, Held::kUnknown);
  EXPECT_EQ(result.safe_stop->action, "load_on_tool");
  ASSERT_FALSE(gripper.opened_at.empty());
  const Eigen::Vector3d p_Bin_release(0.0, 0.0, params.safe_release_height);
  EXPECT_TRUE(gripper.opened_at.back().isApprox(p_Bin_release, kTol));
  EXPECT_TRUE(robot.X_BinTcp.translation().isApprox(p_Bin_release, kTol));
  EXPECT_THAT(result.message, ::testing::HasSubstr("0.60 N still hang on the tool: the arm stays there"));
  const std::vector<json> records = Records("attempt");
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0]["result"], "fault");
  EXPECT_NEAR(records[0]["wrench"]["after_nudge"]["force"][2].get<double>(), 0.62, kTol);
  EXPECT_NEAR(records[0]["wrench"]["after_nudge_again"]["force"][2].get<double>(), 0.62, kTol);
}

TEST_F(CellControllerTest, ALoadThatStaysInTheBinWhenTheToolIsLoweredLetsTheRoundGoOn) {
  planner.plan_answers.push_back(WallTubeWithoutPlan());
  ft.readings = {Reading(0.02), Reading(0.62), Reading(0.03)};  // 0.01 N off: noise

  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty);
  EXPECT_EQ(result.nudges, 1u);
  EXPECT_TRUE(robot.X_BinTcp.isApprox(HomePose(params, cell), kTol));
  const std::vector<json> records = Records("attempt");
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0]["result"], "nudge");
  EXPECT_TRUE(records[0]["wrench"].contains("after_nudge_again"));
  // Without a load there is no second reading and no extra motion.
  ft.readings = {Reading(0.02), Reading(0.04)};
  sink = MemoryRecordSink{};
  planner.plan_answers.push_back(WallTubeWithoutPlan());
  EXPECT_EQ(Run().reason, CellStopReason::kBinEmpty);
  EXPECT_FALSE(Records("attempt")[0]["wrench"].contains("after_nudge_again"));
}

TEST_F(CellControllerTest, ATubeCaughtOnTheOpenFingersAfterAFailedGraspIsNotCarriedHome) {
  planner.plan_answers.push_back(Plans({MakePlan(0, p_Bin_grasp)}, 1));
  gripper.close_results.push_back(ClosedOnNothing());
  ft.readings = {Reading(0.02), Reading(0.60), Reading(0.60), Reading(0.60)};

  const CellRunResult result = Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->kind(), FaultKind::kUnexpectedLoad);
  EXPECT_EQ(result.fault->state(), "release");
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->action, "load_on_tool");
  EXPECT_TRUE(Records("attempt")[0]["wrench"].contains("after_failed_grasp_again"));
  // Shed when the safe stop opens over the bin: released there, and the arm moves up.
  ft.readings = {Reading(0.02), Reading(0.60), Reading(0.60), Reading(0.02)};
  planner.plan_answers.push_back(Plans({MakePlan(0, p_Bin_grasp)}, 1));
  gripper.close_results.push_back(ClosedOnNothing());
  const CellRunResult shed = Run();
  ASSERT_TRUE(shed.safe_stop);
  EXPECT_EQ(shed.safe_stop->action, "released_in_bin");
  EXPECT_THAT(shed.message, ::testing::HasSubstr("robot moved up out of the bin"));
}

TEST_F(CellControllerTest, PerBinLimitCountsAllAttempts) {
  params.max_attempts_per_bin = 2;
  for (int i = 0; i < 3; ++i) {
    planner.plan_answers.push_back(Plans({MakePlan(1, p_Bin_grasp)}, 3));
    planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));
  }
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kLimitReached);
  EXPECT_EQ(result.picks, 2u);
  EXPECT_NE(result.message.find("max_attempts_per_bin = 2"), std::string::npos) << result.message;
}

// ---------------------------------------------------------------- faults

TEST_F(CellControllerTest, ScannerTimeoutsAfterTheRetriesEndInASafeStopWhereTheArmIs) {
  const Failure timeout{true, "PhoXi: no frame within 30000 ms"};
  scanner.failures = {timeout, timeout, timeout};  // the scan and its two retries
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kFault);
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "scanner");
  EXPECT_EQ(result.fault->kind(), FaultKind::kTimeout);
  EXPECT_EQ(result.fault->state(), "scan");
  EXPECT_EQ(scanner.calls, 3);
  // Nothing held: no motion, the gripper as it was (opened once, at the start).
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->held, Held::kNothing);
  EXPECT_EQ(result.safe_stop->action, "stopped");
  EXPECT_EQ(gripper.opens, 1);
  EXPECT_TRUE(robot.X_BinTcp.isApprox(HomePose(params, cell), kTol));
  EXPECT_EQ(
      result.message.rfind("SAFE STOP: scanner timeout during scan: PhoXi: no frame within 30000 ms", 0), 0u)
      << result.message;
  EXPECT_NE(result.message.find("nothing held: stopped where it is"), std::string::npos) << result.message;
  const json stop = Records("safe_stop").at(0);
  EXPECT_EQ(stop["device"], "scanner");
  EXPECT_EQ(stop["kind"], "timeout");
  EXPECT_EQ(stop["held"], "nothing");
  EXPECT_EQ(stop["action"], "stopped");
  EXPECT_NEAR(stop["p_Bin_tcp"][2].get<double>(), 0.5, kTol);
  EXPECT_EQ(Records("end").at(0)["reason"], "fault");
  EXPECT_TRUE(Records("attempt").empty());
}

TEST_F(CellControllerTest, OneScannerTimeoutOrEmptyScanIsScannedAgain) {
  scanner.failures = {Failure{true, "PhoXi: no frame within 30000 ms"}};
  scanner.empty_at = {1};  // the retry returns no point, the next one works
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty) << result.message;
  EXPECT_EQ(scanner.calls, 3);
  EXPECT_EQ(planner.plan_requests.size(), 1u);  // only the good scan was planned on
}

TEST_F(CellControllerTest, EmptyScansAreAScannerFaultNeverAnEmptyBin) {
  scanner.empty_at = {0, 1, 2};
  const CellRunResult result = Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "scanner");
  EXPECT_NE(result.message.find("3 scans in a row returned no point"), std::string::npos) << result.message;
  EXPECT_TRUE(planner.plan_requests.empty());
}

TEST_F(CellControllerTest, GripperFaultWhileClosingCountsAsHoldingAndReleasesOverTheBin) {
  planner.plan_answers.push_back(Plans({MakePlan(1, p_Bin_grasp)}, 2));
  devices::GripperStatus fault;
  fault.activated = true;
  fault.fault = 0x08;
  fault.fault_text = "overcurrent";
  gripper.close_results = {fault};

  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kFault);
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "gripper");
  EXPECT_EQ(result.fault->kind(), FaultKind::kDeviceFault);
  EXPECT_EQ(result.fault->state(), "grasp");
  EXPECT_NE(result.message.find("fault 0x08: overcurrent"), std::string::npos) << result.message;
  // The close did not say what it holds: up to transit height, over the bin's middle, down to
  // safe_release_height, open there, back up.
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->held, Held::kUnknown);
  EXPECT_EQ(result.safe_stop->action, "released_in_bin");
  EXPECT_TRUE(robot.Visited(DownPose(Eigen::Vector3d(p_Bin_grasp.x(), p_Bin_grasp.y(), 0.5))));
  EXPECT_TRUE(robot.Visited(DownPose(Eigen::Vector3d(0.0, 0.0, params.safe_release_height))));
  ASSERT_EQ(gripper.opened_at.size(), 2u);  // the start, then the release
  EXPECT_TRUE(gripper.opened_at[1].isApprox(Eigen::Vector3d(0.0, 0.0, params.safe_release_height), kTol));
  EXPECT_NEAR(robot.X_BinTcp.translation().z(), 0.5, kTol);
  EXPECT_NE(result.message.find("possibly a tube released into the bin at X_BinTcp (0.000, 0.000, 0.150) m"),
            std::string::npos)
      << result.message;
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["result"], "fault");
  EXPECT_EQ(a["fault"]["device"], "gripper");
  EXPECT_EQ(a["fault"]["state"], "grasp");
  EXPECT_EQ(Records("safe_stop").at(0)["held"], "unknown");
}

TEST_F(CellControllerTest, RobotAlarmDuringLiftKeepsTheTubeAndSaysWhereItIsHeld) {
  planner.plan_answers.push_back(Plans({MakePlan(1, p_Bin_grasp)}, 2));
  robot.fail_through_from = 0;

  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kFault);
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "robot");
  EXPECT_EQ(result.fault->kind(), FaultKind::kDeviceFault);
  EXPECT_EQ(result.fault->state(), "lift");
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->held, Held::kTube);
  EXPECT_EQ(result.safe_stop->action, "kept_closed");
  EXPECT_EQ(gripper.opens, 1);  // only the start's: the tube is not dropped where it hangs
  EXPECT_TRUE(gripper.holding);
  EXPECT_NE(result.message.find("YRC1000 alarm 4107"), std::string::npos);
  EXPECT_NE(result.message.find("HOLDING a tube at X_BinTcp (0.100, -0.050, 0.030) m: the robot cannot move"),
            std::string::npos)
      << result.message;
  EXPECT_EQ(Records("attempt").at(0)["fault"]["device"], "robot");
  const json stop = Records("safe_stop").at(0);
  EXPECT_EQ(stop["action"], "kept_closed");
  EXPECT_NEAR(stop["p_Bin_tcp"][0].get<double>(), p_Bin_grasp.x(), kTol);
}

TEST_F(CellControllerTest, ForceTorqueLostAfterLiftReturnsTheTubeIntoTheBin) {
  planner.plan_answers.push_back(Plans({MakePlan(1, p_Bin_grasp)}, 2));
  ft.fail_read_from = 1;  // the reference works, every reading after the lift times out

  const CellRunResult result = Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "ft_sensor");
  EXPECT_EQ(result.fault->kind(), FaultKind::kTimeout);
  EXPECT_EQ(result.fault->state(), "analyze");
  EXPECT_EQ(ft.reads, 1 + 1 + static_cast<int>(params.ft_read_retries));
  EXPECT_EQ(result.message.rfind("SAFE STOP: ft_sensor timeout during analyze", 0), 0u) << result.message;
  EXPECT_TRUE(planner.wrench_requests.empty());
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->action, "released_in_bin");
  ASSERT_EQ(gripper.opened_at.size(), 2u);
  EXPECT_TRUE(gripper.opened_at[1].isApprox(Eigen::Vector3d(0.0, 0.0, params.safe_release_height), kTol));
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["result"], "fault");
  EXPECT_EQ(a["gripper"]["object"], "stopped_closing");
}

TEST_F(CellControllerTest, OneForceTorqueTimeoutIsReadAgain) {
  planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
  ft.fail_once_at = {1};
  ft.readings = {Reading(0.10), Reading(0.64)};
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty) << result.message;
  EXPECT_EQ(result.picks, 1u);
  ASSERT_EQ(planner.wrench_requests.size(), 1u);
  EXPECT_DOUBLE_EQ(planner.wrench_requests[0].current().force().z(), 0.64);
}

TEST_F(CellControllerTest, ForceTorqueSpikesAreDroppedFromTheMean) {
  params.ft_samples = 5;
  planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
  ft.readings = {Reading(0.10), Reading(0.10), Reading(0.10), Reading(0.10), Reading(0.10),
                 Reading(0.64), Reading(25.6), Reading(0.66), Reading(0.62), Reading(0.64)};
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));
  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u) << result.message;
  ASSERT_EQ(planner.wrench_requests.size(), 1u);
  EXPECT_NEAR(planner.wrench_requests[0].current().force().z(), 0.64, 1e-12);  // 25.6 N dropped
}

TEST_F(CellControllerTest, MostlySpikesInEveryMeasurementAreAForceTorqueFault) {
  params.ft_samples = 3;
  planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
  // Three measurements (ft_unsettled_retries = 2), each of them mostly spikes: no settling helps.
  ft.readings = {Reading(0.10), Reading(9.0),  Reading(-9.0), Reading(0.10), Reading(9.0),
                 Reading(-9.0), Reading(0.10), Reading(9.0),  Reading(-9.0)};
  const CellRunResult result = Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "ft_sensor");
  EXPECT_EQ(result.fault->state(), "reference");
  EXPECT_NE(result.message.find("2 of 3 readings are more than 2 N / 0.2 N*m off their median, in each of 3 "
                                "measurements"),
            std::string::npos)
      << result.message;
  EXPECT_EQ(ft.reads, 9);
  // A median load of 0.1 N: the sensor, not the payload.
  EXPECT_NE(result.message.find("their median load is 0.1 N: a loose cable"), std::string::npos)
      << result.message;
  params.ft_unsettled_retries = 0;  // the old behaviour: the first such measurement is a fault
  planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
  ft.readings = {Reading(0.10), Reading(9.0), Reading(-9.0)};
  const CellRunResult at_once = Run();
  ASSERT_TRUE(at_once.fault);
  EXPECT_NE(at_once.message.find("in each of 1 measurements"), std::string::npos) << at_once.message;
}

TEST_F(CellControllerTest, ReadingsThatDisagreeUnderAHeavyLoadNamePressingOnSomething) {
  params.ft_samples = 3;
  params.ft_unsettled_retries = 0;
  planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
  // The tool pressing into something that gives way: hundreds of newtons, drifting by 6 N.
  ft.readings = {Reading(444.0), Reading(450.0), Reading(456.0)};
  const CellRunResult result = Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "ft_sensor");
  const double tube_weight = cell.tube.mass * 9.81;
  EXPECT_NE(result.message.find(fmt::format("their median load is 450.0 N, {:.0f} times a tube's weight: the "
                                            "tool or the held tube is pressing on something",
                                            450.0 / tube_weight)),
            std::string::npos)
      << result.message;
}

TEST_F(CellControllerTest, AMeasurementOfASwingingPayloadIsTakenAgainAfterSettling) {
  params.ft_samples = 3;
  params.ft_settle_samples = 1;
  planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
  // Reference: settle + 3 steady readings. After the lift the payload swings through the first
  // measurement (2 of 3 far off), then hangs still: the second measurement is the one used.
  ft.readings = {Reading(0.10), Reading(0.10), Reading(0.10), Reading(0.10), Reading(3.0),  Reading(0.64),
                 Reading(-2.5), Reading(4.0),  Reading(0.9),  Reading(0.64), Reading(0.64), Reading(0.64)};
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));
  const CellRunResult result = Run();
  EXPECT_FALSE(result.fault) << result.message;
  EXPECT_EQ(result.picks, 1u) << result.message;
  ASSERT_EQ(planner.wrench_requests.size(), 1u);
  EXPECT_NEAR(planner.wrench_requests[0].current().force().z(), 0.64, 1e-12);
}

TEST_F(CellControllerTest, PlannerUnavailableBeforeTheGraspStopsWhereTheArmIs) {
  testing::ScriptedPlanner::PlanAnswer down;
  down.error =
      PlannerError("PlanPick", grpc::StatusCode::UNAVAILABLE, "failed to connect to all addresses", 4);
  planner.plan_answers.push_back(down);

  const CellRunResult result = Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "planner");
  EXPECT_EQ(result.fault->kind(), FaultKind::kServerUnavailable);
  EXPECT_EQ(result.fault->state(), "plan");
  EXPECT_NE(result.message.find("PlanPick failed after 4 tries: UNAVAILABLE: failed to connect"),
            std::string::npos)
      << result.message;
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->action, "stopped");
  EXPECT_EQ(gripper.opens, 1);
  EXPECT_EQ(Records("safe_stop").at(0)["kind"], "server_unavailable");
}

TEST_F(CellControllerTest, PlannerGoneWhileHoldingAnalysesLocallyAndPlaces) {
  planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
  // One 55 g tube: 0.54 N more along z_Tcp (down) after the lift.
  ft.readings = {Reading(0.10), Reading(0.10 + cell.tube.mass * 9.81)};
  planner.wrench_error =
      PlannerError("AnalyzeWrench", grpc::StatusCode::UNAVAILABLE, "failed to connect to all addresses", 6);

  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u) << result.message;
  EXPECT_EQ(result.local_analyses, 1u);
  EXPECT_EQ(planner.wrench_requests.size(), 1u);
  EXPECT_TRUE(robot.Visited(testing::PlacePose()));
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["result"], "picked");
  EXPECT_EQ(a["analysis"]["outcome"], "single");
  EXPECT_EQ(a["analysis_fallback"]["local_analyses"], 1);
  EXPECT_NE(a["analysis_fallback"]["planner_error"].get<std::string>().find("UNAVAILABLE"),
            std::string::npos);
}

TEST_F(CellControllerTest, PlannerRejectingTheAnalysisIsStillAFault) {
  planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
  planner.wrench_error =
      PlannerError("AnalyzeWrench", grpc::StatusCode::INVALID_ARGUMENT, "tube_mass: bad", 1);
  const CellRunResult result = Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->kind(), FaultKind::kServerError);
  EXPECT_EQ(result.local_analyses, 0u);
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->action, "released_in_bin");  // holding: back into the bin
}

// ---------------------------------------------------------------- the place descent

class PlaceDescentTest : public CellControllerTest {
 protected:
  void SetUp() override {
    CellControllerTest::SetUp();
    planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
    planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));
  }
  /// Heights (bin z) the robot stopped at straight above the place pose, in order.
  std::vector<double> StopsAboveThePlace() const {
    std::vector<double> z;
    const Eigen::Vector3d p = testing::PlacePose().translation();
    for (const auto& m : robot.moves) {
      const Eigen::Vector3d q = m.X_BinTcpTarget.translation();
      if (!m.through && (q.head<2>() - p.head<2>()).norm() < kTol && q.z() < p.z() + 0.1 - kTol)
        z.push_back(q.z());
    }
    return z;
  }
};

TEST_F(PlaceDescentTest, ATubeThatTouchesDownEarlyIsReleasedWhereItRestsNotPushedDown) {
  // Reference, lift, above the place, the first step (still one tube), the second (it rests: no load).
  ft.readings = {Reading(0.10), Reading(0.64), Reading(0.64), Reading(0.64), Reading(0.10)};
  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u) << result.message;
  // Place pose at z 0.12, above it 0.22: steps of 2 cm, stopped at the second, 6 cm above the pose.
  const std::vector<double> stops = StopsAboveThePlace();
  ASSERT_EQ(stops.size(), 2u);
  EXPECT_NEAR(stops[0], 0.20, kTol);
  EXPECT_NEAR(stops[1], 0.18, kTol);
  ASSERT_GE(gripper.opened_at.size(), 2u);
  EXPECT_NEAR(gripper.opened_at[1].z(), 0.18, kTol);
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["placed"], true);
  EXPECT_NEAR(a["place_touchdown"].get<double>(), 0.06, kTol);
}

TEST_F(PlaceDescentTest, ATubeThatHangsAsModeledGoesDownToThePlacePoseInSteps) {
  ft.readings = {Reading(0.10), Reading(0.64)};  // one tube from the lift on, until the gripper opens
  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u) << result.message;
  const std::vector<double> stops = StopsAboveThePlace();
  ASSERT_EQ(stops.size(), 5u);
  for (std::size_t i = 0; i < stops.size(); ++i) EXPECT_NEAR(stops[i], 0.20 - 0.02 * i, kTol) << i;
  EXPECT_TRUE(gripper.opened_at[1].isApprox(testing::PlacePose().translation(), kTol));
  EXPECT_FALSE(Records("attempt").at(0).contains("place_touchdown"));
  EXPECT_FALSE(Records("attempt").at(0).contains("place_raised"));  // the tool clears the ground
}

TEST_F(PlaceDescentTest, APlacePoseThatWouldPutAFingerIntoThePlaceSurfaceIsRaisedUntilTheToolClears) {
  // The place pose's TCP at z 0.12, the fingertips 5 mm below it: with the surface at 0.12 the
  // tool must rise by 5 mm + tool.margin (3 mm) to clear it.
  params.place_surface_height = 0.12;
  ft.readings = {Reading(0.10), Reading(0.64)};  // one tube from the lift on
  const CellRunResult result = Run();
  EXPECT_FALSE(result.fault) << result.message;
  EXPECT_EQ(result.picks, 1u) << result.message;
  const double raised = params.tool.finger_tip_depth + params.tool.margin;
  ASSERT_GE(gripper.opened_at.size(), 2u);
  EXPECT_NEAR(gripper.opened_at[1].z(), testing::PlacePose().translation().z() + raised, kTol);
  const std::vector<double> stops = StopsAboveThePlace();
  ASSERT_FALSE(stops.empty());
  EXPECT_NEAR(*std::min_element(stops.begin(), stops.end()), 0.12 + raised, kTol);  // never lower
  EXPECT_NEAR(Records("attempt").at(0)["place_raised"].get<double>(), raised, kTol);
}

TEST_F(PlaceDescentTest, ATubeJammedOnThePlaceSurfaceIsReleasedWhereTheReadingsStartToDisagree) {
  params.ft_samples = 3;
  params.ft_unsettled_retries = 0;
  // Reference, lift, above the place, the first step: one tube; the second step presses a rigid
  // tree on the surface (readings drifting by 10-15 N): it is down.
  ft.readings = {Reading(0.10), Reading(0.10), Reading(0.10),  Reading(0.64),  Reading(0.64),
                 Reading(0.64), Reading(0.64), Reading(0.64),  Reading(0.64),  Reading(0.64),
                 Reading(0.64), Reading(0.64), Reading(150.0), Reading(160.0), Reading(175.0)};
  const CellRunResult result = Run();
  EXPECT_FALSE(result.fault) << result.message;
  EXPECT_EQ(result.picks, 1u) << result.message;
  ASSERT_GE(gripper.opened_at.size(), 2u);
  EXPECT_NEAR(gripper.opened_at[1].z(), 0.18, kTol);
  const json a = Records("attempt").at(0);
  EXPECT_NEAR(a["place_touchdown"].get<double>(), 0.06, kTol);
  EXPECT_THAT(a["wrench"]["place_descent_unsettled"].get<std::string>(),
              ::testing::HasSubstr("pressing on something"));
}

TEST_F(PlaceDescentTest, ATubePressingOnThePlaceZoneIsReadAgainHigherUpThenLoweredInSteps) {
  params.ft_samples = 3;
  params.ft_unsettled_retries = 0;
  // Reference, lift; above the place the held tree presses on the zone (readings drifting by
  // 10-15 N); 0.2 m higher it hangs free, and it stays one tube down to the place pose.
  ft.readings = {Reading(0.10),  Reading(0.10),  Reading(0.10),  Reading(0.64), Reading(0.64), Reading(0.64),
                 Reading(190.0), Reading(200.0), Reading(215.0), Reading(0.64), Reading(0.64), Reading(0.64)};
  const CellRunResult result = Run();
  EXPECT_FALSE(result.fault) << result.message;
  EXPECT_EQ(result.picks, 1u) << result.message;
  const json a = Records("attempt").at(0);
  EXPECT_THAT(a["wrench"]["before_place_unsettled"].get<std::string>(),
              ::testing::HasSubstr("pressing on something"));
  // Up to 0.42 m (0.2 above the place approach), then down in 2 cm steps to the place pose.
  std::vector<double> z;  // the TCP's heights over the place pose, in order
  for (const auto& m : robot.moves) {
    const Eigen::Vector3d q = m.X_BinTcpTarget.translation();
    if ((q.head<2>() - testing::PlacePose().translation().head<2>()).norm() < kTol) z.push_back(q.z());
  }
  const auto up = std::find_if(z.begin(), z.end(), [](double h) { return std::abs(h - 0.42) < kTol; });
  ASSERT_NE(up, z.end());
  const auto down = std::find_if(up, z.end(), [](double h) { return std::abs(h - 0.12) < kTol; });
  ASSERT_NE(down, z.end());
  EXPECT_EQ(down - up, 15);  // 0.40, 0.38, ..., 0.14, then the place pose
  EXPECT_TRUE(gripper.opened_at[1].isApprox(testing::PlacePose().translation(), kTol));
}

// ---------------------------------------------------------------- faults during place

class PlaceFaultTest : public CellControllerTest {
 protected:
  void SetUp() override {
    CellControllerTest::SetUp();
    params.place_step = 0.0;  // one move down to the place pose (the stepped descent: PlaceDescentTest)
    planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
    ft.readings = {Reading(0.10), Reading(0.64), Reading(0.64)};  // reference, lift, above the place
    planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));
  }
  /// Every open after the start's happened over the bin's interior, below its wall top.
  void ExpectOpenedOnlyInTheBin() const {
    for (std::size_t i = 1; i < gripper.opened_at.size(); ++i) {
      const Eigen::Vector3d& p = gripper.opened_at[i];
      EXPECT_LE(std::abs(p.x()), 0.5 * cell.bin.inner_size.x()) << i;
      EXPECT_LE(std::abs(p.y()), 0.5 * cell.bin.inner_size.y()) << i;
      EXPECT_LE(p.z(), cell.bin.inner_size.z()) << i;
    }
  }
};

TEST_F(PlaceFaultTest, RobotAlarmOnTheDescentKeepsTheTubeOverThePlaceZone) {
  robot.alarm_on_move_to = [](const Eigen::Isometry3d& X) { return X.isApprox(testing::PlacePose(), kTol); };
  const CellRunResult result = Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "robot");
  EXPECT_EQ(result.fault->state(), "place");
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->held, Held::kTube);
  EXPECT_EQ(result.safe_stop->action, "kept_closed");
  EXPECT_EQ(gripper.opens, 1);
  EXPECT_TRUE(gripper.holding);
  // Stopped above the place pose (0, 0.8, 0.12 + 0.1): that is where the operator finds the tube.
  EXPECT_NE(result.message.find("HOLDING a tube at X_BinTcp (0.000, 0.800, 0.220) m: the robot cannot move"),
            std::string::npos)
      << result.message;
  EXPECT_EQ(result.picks, 0u);
}

TEST_F(PlaceFaultTest, ATubeCaughtOnThePadsAfterThePlaceIsCarriedBackIntoTheBinNotHome) {
  // Above the place after opening: still 0.54 N on the tool, also after lowering it onto the place
  // pose once; it comes off when the safe stop opens over the bin.
  ft.readings.insert(ft.readings.end(), {Reading(0.64), Reading(0.64), Reading(0.10)});
  const CellRunResult result = Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "ft_sensor");
  EXPECT_EQ(result.fault->kind(), FaultKind::kUnexpectedLoad);
  EXPECT_EQ(result.fault->state(), "place");
  EXPECT_THAT(result.fault->error(), ::testing::HasSubstr("carries 0.54 N (1.0 times a tube's weight) after "
                                                          "letting go, at X_BinTcp (0.000, 0.800, 0.220) m, "
                                                          "also after lowering it onto the place pose once"));
  EXPECT_EQ(result.picks, 0u);
  // Lowered onto the place pose twice (the place, the shed), then over the bin's middle.
  int at_place = 0;
  for (const auto& m : robot.moves) at_place += m.X_BinTcpTarget.isApprox(testing::PlacePose(), kTol);
  EXPECT_EQ(at_place, 2);
  EXPECT_TRUE(robot.X_BinTcp.translation().head<2>().isZero(kTol));  // up out of the bin's middle
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->held, Held::kUnknown);
  EXPECT_EQ(result.safe_stop->action, "released_in_bin");
  ASSERT_EQ(gripper.opened_at.size(), 3u);  // the start, the place, over the bin
  EXPECT_TRUE(gripper.opened_at[2].isApprox(Eigen::Vector3d(0.0, 0.0, params.safe_release_height), kTol));
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["result"], "fault");
  EXPECT_EQ(a["placed"], false);
  EXPECT_NEAR(a["wrench"]["after_place"]["force"][2].get<double>(), 0.64, kTol);
  EXPECT_NEAR(a["wrench"]["after_place_again"]["force"][2].get<double>(), 0.64, kTol);
  EXPECT_EQ(Records("end").at(0)["picks"], 0);
}

TEST_F(PlaceFaultTest, AHoseThatComesOffWhenLoweredOntoThePlaceAgainIsAPick) {
  ft.readings.insert(ft.readings.end(), {Reading(0.64), Reading(0.11)});  // 0.01 N off: noise
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty) << result.message;
  EXPECT_EQ(result.picks, 1u);
  EXPECT_TRUE(robot.X_BinTcp.isApprox(HomePose(params, cell), kTol));
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["result"], "picked");
  EXPECT_EQ(a["placed"], true);
  EXPECT_TRUE(a["wrench"].contains("after_place_again"));
}

TEST_F(PlaceFaultTest, RobotAlarmAfterTheTubeIsPlacedStillCountsThePick) {
  // The second move to the pose above the place is the way up after opening.
  int above_place = 0;
  robot.alarm_on_move_to = [&](const Eigen::Isometry3d& X) {
    const Eigen::Isometry3d X_above =
        DownPose(testing::PlacePose().translation() + Eigen::Vector3d(0, 0, 0.1));
    return X.isApprox(X_above, kTol) && ++above_place == 2;
  };
  const CellRunResult result = Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->state(), "place");
  EXPECT_EQ(result.picks, 1u);
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->held, Held::kNothing);
  EXPECT_EQ(result.safe_stop->action, "stopped");
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["result"], "picked");
  EXPECT_EQ(a["placed"], true);
  EXPECT_EQ(a["fault"]["device"], "robot");
  EXPECT_EQ(Records("end").at(0)["picks"], 1);
}

TEST_F(PlaceFaultTest, GripperThatCannotOpenAtThePlaceGoesBackOverTheBinAndSaysSo) {
  gripper.fail_open_from = 1;  // the start's open works
  const CellRunResult result = Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "gripper");
  EXPECT_EQ(result.fault->state(), "place");
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->action, "kept_closed");
  EXPECT_TRUE(robot.Visited(DownPose(Eigen::Vector3d(0.0, 0.0, params.safe_release_height))));
  EXPECT_EQ(gripper.opens, 3);  // the start, the place (failed), over the bin (failed)
  EXPECT_NE(
      result.message.find("HOLDING a tube over the bin at X_BinTcp (0.000, 0.000, 0.150) m: the gripper "
                          "cannot open (Robotiq 2F-85: no Modbus reply"),
      std::string::npos)
      << result.message;
}

TEST_F(PlaceFaultTest, ForceTorqueLostAboveThePlaceReturnsTheTubeIntoTheBin) {
  ft.fail_read_from = 2;  // reference and lift work; the check above the place does not
  const CellRunResult result = Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->device(), "ft_sensor");
  EXPECT_EQ(result.fault->state(), "place");
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->action, "released_in_bin");
  ExpectOpenedOnlyInTheBin();
  EXPECT_EQ(gripper.opened_at.size(), 2u);
}

TEST_F(PlaceFaultTest, PlannerGoneDuringThePlaceChangesNothing) {
  // From the place on, every planner call fails: the place needs none (its load check runs here).
  observer = [this](CellState state) {
    if (state != CellState::kPlace) return;
    planner.wrench_error =
        PlannerError("AnalyzeWrench", grpc::StatusCode::UNAVAILABLE, "connection refused", 6);
    testing::ScriptedPlanner::PlanAnswer down;
    down.error = PlannerError("PlanPick", grpc::StatusCode::UNAVAILABLE, "connection refused", 6);
    planner.plan_answers.push_back(down);
  };
  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u) << result.message;
  EXPECT_EQ(planner.wrench_requests.size(), 1u);  // the lift's, before the planner went
  EXPECT_TRUE(robot.Visited(testing::PlacePose()));
  ASSERT_EQ(gripper.opened_at.size(), 2u);  // the start's, then on the place pose only
  EXPECT_TRUE(gripper.opened_at[1].isApprox(testing::PlacePose().translation(), kTol));
  EXPECT_EQ(Records("attempt").at(0)["result"], "picked");
  // The next scan found no planner: nothing held, so the arm stops at home.
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->state(), "plan");
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->action, "stopped");
}

TEST_F(PlaceFaultTest, SlipInTransitIsRecordedAsLostAndTheRoundGoesOn) {
  gripper.drop_at_status = 1;  // after the lift it still holds; after the way up it does not
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty) << result.message;
  EXPECT_EQ(result.picks, 0u);
  EXPECT_EQ(result.lost, 1u);
  EXPECT_EQ(result.scans, 2u);  // rescanned after the loss
  EXPECT_FALSE(robot.Visited(testing::PlacePose()));
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["result"], "lost");
  EXPECT_EQ(a["lost"]["state"], "place_transit");
  EXPECT_EQ(a["lost"]["detected_by"], "gripper_status");
  EXPECT_EQ(a["lost"]["p_Bin_tcp"].size(), 3u);
  EXPECT_EQ(Records("end").at(0)["lost"], 1);
  EXPECT_EQ(SummarizeRecords(sink.records()).lost_in_transit, 1u);
  // The fingers were opened at home, not where the loss was noticed.
  ASSERT_EQ(gripper.opened_at.size(), 2u);
  EXPECT_TRUE(gripper.opened_at[1].isApprox(HomePose(params, cell).translation(), kTol));
}

TEST_F(PlaceFaultTest, NoLoadAboveThePlaceIsALostTubeEvenWhenTheGripperSaysHolding) {
  ft.readings = {Reading(0.10), Reading(0.64), Reading(0.11)};  // the tube is gone above the place
  const CellRunResult result = Run();
  EXPECT_EQ(result.lost, 1u) << result.message;
  EXPECT_EQ(result.picks, 0u);
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["result"], "lost");
  EXPECT_EQ(a["lost"]["detected_by"], "wrench");
  EXPECT_NEAR(a["wrench"]["before_place"]["force"][2].get<double>(), 0.11, 1e-12);
  // Read again 0.2 m higher (place_recheck_height) before calling it lost.
  EXPECT_TRUE(robot.Visited(DownPose(testing::PlacePose().translation() + Eigen::Vector3d(0, 0, 0.3))));
  EXPECT_NEAR(a["wrench"]["before_place_recheck"]["force"][2].get<double>(), 0.11, 1e-12);
  EXPECT_NE(a["lost"]["detail"].get<std::string>().find("also 0.20 m higher"), std::string::npos);
  EXPECT_FALSE(robot.Visited(testing::PlacePose()));
}

TEST_F(PlaceFaultTest, ATubeRestingOnThePlaceSurfaceIsCheckedHigherAndPlaced) {
  // Above the place the tube weighs 0.15 of its 0.54 N (a branch on the table); 0.2 m higher, all.
  ft.readings = {Reading(0.10), Reading(0.64), Reading(0.25), Reading(0.64)};
  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u) << result.message;
  EXPECT_EQ(result.lost, 0u);
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["result"], "picked");
  EXPECT_NEAR(a["wrench"]["before_place"]["force"][2].get<double>(), 0.25, 1e-12);
  EXPECT_NEAR(a["wrench"]["before_place_recheck"]["force"][2].get<double>(), 0.64, 1e-12);
  EXPECT_TRUE(robot.Visited(DownPose(testing::PlacePose().translation() + Eigen::Vector3d(0, 0, 0.3))));
  ASSERT_EQ(gripper.opened_at.size(), 2u);  // the start's, then on the place pose
  EXPECT_TRUE(gripper.opened_at[1].isApprox(testing::PlacePose().translation(), kTol));
}

TEST_F(PlaceFaultTest, WithoutTheRecheckALightLoadAboveThePlaceIsALostTube) {
  params.place_recheck_height = 0.0;
  ft.readings = {Reading(0.10), Reading(0.64), Reading(0.25), Reading(0.64)};
  const CellRunResult result = Run();
  EXPECT_EQ(result.lost, 1u) << result.message;
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["result"], "lost");
  EXPECT_FALSE(a["wrench"].contains("before_place_recheck"));
  EXPECT_EQ(a["lost"]["detail"].get<std::string>().find("higher"), std::string::npos);
}

TEST_F(CellControllerTest, RealClientWithNoServerWaitsItsBudgetThenSafeStops) {
  GrpcPlannerClientOptions options;
  options.unavailable_budget = std::chrono::milliseconds(200);
  options.initial_backoff = std::chrono::milliseconds(5);
  options.max_backoff = std::chrono::milliseconds(10);
  GrpcPlannerClient client("127.0.0.1:1", options);  // nothing listens on port 1
  CellController controller({&scanner, &robot, &gripper, &ft}, client, cell, params, &sink);

  const CellRunResult result = controller.Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->kind(), FaultKind::kServerUnavailable);
  EXPECT_NE(result.message.find("PlanPick failed after 1 try: UNAVAILABLE: no connection to the planner at "
                                "127.0.0.1:1 within 0.2 s (unavailable_budget)"),
            std::string::npos)
      << result.message;
  EXPECT_EQ(controller.state(), CellState::kSafeStop);
}

TEST_F(CellControllerTest, UnusablePlanIsAServerError) {
  v1::PickPlan plan = MakePlan(1, p_Bin_grasp);
  plan.clear_waypoints();
  planner.plan_answers.push_back(Plans({plan}, 1));
  const CellRunResult result = Run();
  ASSERT_TRUE(result.fault);
  EXPECT_EQ(result.fault->kind(), FaultKind::kServerError);
  EXPECT_NE(result.message.find("plans[0].waypoints: empty"), std::string::npos) << result.message;
}

// ---------------------------------------------------------------- plans against this cell

/// `plan` as a planner in millimetres sends it: every length × 1000.
v1::PickPlan InMillimetres(v1::PickPlan plan) {
  const auto scale = [](v1::Vector3* v) {
    v->set_x(v->x() * 1000.0);
    v->set_y(v->y() * 1000.0);
    v->set_z(v->z() * 1000.0);
  };
  scale(plan.mutable_grasp()->mutable_tcp_pose()->mutable_position());
  for (v1::Vector3& w : *plan.mutable_waypoints()) scale(&w);
  scale(plan.mutable_place_tcp_pose()->mutable_position());
  return plan;
}

TEST_F(CellControllerTest, APlannerInMillimetresDoesNotDriveTheArm) {
  planner.plan_answers.push_back(Plans(
      {InMillimetres(MakePlan(1, p_Bin_grasp)), InMillimetres(MakePlan(2, Eigen::Vector3d(0.0, 0.0, 0.02)))},
      2));
  const CellRunResult result = Run();
  EXPECT_EQ(result.attempts, 0u);
  EXPECT_EQ(gripper.closes, 0);  // no grasp, no nudge
  EXPECT_EQ(robot.throughs, 0);
  for (const testing::ScriptedRobot::Move& m : robot.moves)  // only the way home at the start
    EXPECT_GE(m.X_BinTcpTarget.translation().z(), 0.5 - kTol);
  const std::vector<json> records = Records("attempt");
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0]["result"], "no_plan");
  ASSERT_EQ(records[0]["skipped_plans"].size(), 2u);
  const json& skipped = records[0]["skipped_plans"][0];
  EXPECT_EQ(skipped["check"], "cell_frame");
  const std::string reason = skipped["reason"];
  EXPECT_NE(
      reason.find("cell check: the grasp at (100.000, -50.000, 30.000) m lies outside this controller's "
                  "bin (inner 0.800 x 0.600 x 0.200 m"),
      std::string::npos)
      << reason;
  EXPECT_NE(reason.find("millimetres read as metres"), std::string::npos) << reason;
  const std::string mismatch = records[0]["cell_mismatch"];
  EXPECT_NE(mismatch.find("all 2 plans of this scan lie outside this controller's cell"), std::string::npos)
      << mismatch;
}

TEST_F(CellControllerTest, APlannerWithAnotherBinSizeHasItsOutsideGraspsSkipped) {
  cell.bin.inner_size = Eigen::Vector3d(0.5, 0.4, 0.2);  // the controller's bin; the planner's is 0.8 x 0.6
  const Eigen::Vector3d p_Bin_far(0.32, 0.1, 0.03);
  planner.plan_answers.push_back(Plans({MakePlan(1, p_Bin_far), MakePlan(2, p_Bin_grasp)}, 3));
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));
  const CellRunResult result = Run();
  EXPECT_EQ(result.picks, 1u) << result.message;
  EXPECT_FALSE(robot.Visited(DownPose(p_Bin_far)));
  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["tube"], 2);
  ASSERT_EQ(a["skipped_plans"].size(), 1u);
  EXPECT_EQ(a["skipped_plans"][0]["check"], "cell_frame");
  const std::string reason = a["skipped_plans"][0]["reason"];
  EXPECT_NE(reason.find("the grasp at (0.320, 0.100, 0.030) m lies outside this controller's bin"),
            std::string::npos)
      << reason;
  EXPECT_NE(reason.find("|x| > 0.270 m"), std::string::npos) << reason;
  EXPECT_NE(reason.find("another bin (cell bin.inner_size)"), std::string::npos) << reason;
  EXPECT_FALSE(a.contains("cell_mismatch"));
}

TEST_F(CellControllerTest, APlannerWithAnotherPlaceFrameDoesNotDriveTheArm) {
  cell.place.X_BinPlace = Eigen::Isometry3d(Eigen::Translation3d(0.7, -0.9, 0.1));
  params.nudge.enabled = true;
  planner.plan_answers.push_back(Plans({MakePlan(1, p_Bin_grasp)}, 2));
  const CellRunResult result = Run();
  EXPECT_EQ(result.attempts, 0u);
  EXPECT_EQ(gripper.closes, 0);
  const json record = Records("attempt").at(0);
  EXPECT_EQ(record["result"], "no_plan");
  const std::string reason = record["skipped_plans"][0]["reason"];
  EXPECT_NE(
      reason.find("cell check: the place pose at (0.000, 0.800, 0.120) m is 1.839 m from this controller's "
                  "place frame at (0.700, -0.900, 0.100) m"),
      std::string::npos)
      << reason;
  EXPECT_NE(reason.find("another place frame (cell place.pose_in_bin)"), std::string::npos) << reason;
  EXPECT_TRUE(record.contains("cell_mismatch"));
  // Without the check the plan would be executed.
  params.cell_check.enabled = false;
  planner.plan_answers.push_back(Plans({MakePlan(1, p_Bin_grasp)}, 2));
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));
  EXPECT_EQ(Run().attempts, 1u);
}

// ---------------------------------------------------------------- operator stop

TEST_F(CellControllerTest, StopWhileHoldingATubeReleasesItOverTheBin) {
  planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));
  observer = [this](CellState state) {
    if (state == CellState::kAnalyze) running->RequestStop("operator stop (SIGINT)");
  };
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kStopped);
  EXPECT_FALSE(result.fault);
  ASSERT_TRUE(result.operator_stop);
  EXPECT_EQ(*result.operator_stop, "operator stop (SIGINT)");
  EXPECT_EQ(
      result.message.rfind("STOPPED: operator stop (SIGINT) during analyze; a tube released into the bin "
                           "at X_BinTcp (0.000, 0.000, 0.150) m",
                           0),
      0u)
      << result.message;
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->held, Held::kTube);
  EXPECT_EQ(result.safe_stop->action, "released_in_bin");
  ASSERT_EQ(gripper.opened_at.size(), 2u);  // the start, then over the bin
  EXPECT_TRUE(gripper.opened_at[1].isApprox(Eigen::Vector3d(0.0, 0.0, params.safe_release_height), kTol));
  EXPECT_TRUE(planner.wrench_requests.empty());  // stopped before the analysis
  EXPECT_FALSE(robot.Visited(testing::PlacePose()));
  EXPECT_EQ(result.picks, 0u);

  const json a = Records("attempt").at(0);
  EXPECT_EQ(a["result"], "stopped");
  EXPECT_EQ(a["stop"]["state"], "analyze");
  EXPECT_EQ(a["stop"]["reason"], "operator stop (SIGINT)");
  const json stop = Records("safe_stop").at(0);
  EXPECT_EQ(stop["reason"], "stopped");
  EXPECT_EQ(stop["device"], "operator");
  EXPECT_EQ(stop["kind"], "stop");
  EXPECT_EQ(stop["state"], "analyze");
  EXPECT_EQ(stop["error"], "operator stop (SIGINT)");
  EXPECT_EQ(stop["held"], "tube");
  EXPECT_EQ(stop["action"], "released_in_bin");
  const json end = Records("end").at(0);
  EXPECT_EQ(end["reason"], "stopped");
  EXPECT_EQ(end["message"], result.message);
}

// ---------------------------------------------------------------- a tube over a wall

class WallWatchTest : public CellControllerTest {
 protected:
  /// Scan 0 plans tube 4; tube 7 leans on the -y wall, over its top. Scan 1 models only tube 9,
  /// far from where tube 7 hung, and plans it. Scan 2: empty.
  void ScriptATubeOverAWallThenAnotherScan() {
    auto first = Plans({MakePlan(4, p_Bin_grasp)}, 0);
    AddTubeAxis(first.response, 4, {{0.05, -0.05, 0.03}, {0.15, -0.05, 0.03}});
    AddTubeAxis(first.response, 7, {{-0.08, -0.10, 0.11}, {-0.029, -0.304, 0.22}});
    auto second = Plans({MakePlan(9, GraspSpot(3))}, 0);
    AddTubeAxis(second.response, 9, {{0.0, 0.1, 0.03}, {0.1, 0.1, 0.03}});
    planner.plan_answers = {first, second};
  }
};

TEST_F(WallWatchTest, ATubeOverAWallThatTheNextScanNoLongerShowsIsNamedOnTheRound) {
  ScriptATubeOverAWallThenAnotherScan();  // nothing in the captures where tube 7 hung
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_SINGLE, 1.0), Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)};
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty);
  ASSERT_EQ(result.vanished_over_walls.size(), 1u);
  EXPECT_EQ(result.vanished_over_walls[0],
            "over the -y wall at (-0.029, -0.304, 0.220) m, not seen again after scan 0");
  EXPECT_THAT(DescribeRoundWarnings(result),
              ::testing::HasSubstr(
                  "1 tube hanging over a wall was not seen again, it may have fallen out of the bin"));
  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 2u);
  EXPECT_FALSE(attempts[0].contains("vanished_over_walls"));
  EXPECT_EQ(attempts[1]["vanished_over_walls"].size(), 1u);
}

TEST_F(WallWatchTest, ATubeGoneFromOverAWallIsAccountedForWhenEveryTubeOfTheBinWasPlaced) {
  // As above (one tube placed: the second scan's plan fails the cell check): in a bin of one tube
  // (tubes_per_bin), the one gone from over the wall was that tube, placed; in a bin of two, one is
  // missing and the warning stands.
  params.tubes_per_bin = 1;
  ScriptATubeOverAWallThenAnotherScan();
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_SINGLE, 1.0), Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)};
  const CellRunResult placed = Run();
  EXPECT_EQ(placed.picks, 1u);
  ASSERT_EQ(placed.vanished_over_walls.size(), 1u);
  EXPECT_EQ(
      DescribeRoundWarnings(placed),
      "; 1 tube hanging over a wall was not seen there again, but every tube of the bin was placed (1 of "
      "tubes_per_bin 1), so it did not fall out: over the -y wall at (-0.029, -0.304, 0.220) m, not seen "
      "again after scan 0");

  params.tubes_per_bin = 2;
  ScriptATubeOverAWallThenAnotherScan();
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_SINGLE, 1.0), Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)};
  const CellRunResult missing = Run();
  EXPECT_THAT(
      DescribeRoundWarnings(missing),
      ::testing::HasSubstr("; 1 tube hanging over a wall was not seen again, it may have fallen out of the "
                           "bin: over the -y wall"));
  EXPECT_THAT(DescribeRoundWarnings(missing), ::testing::HasSubstr("1 of the bin's 2 tubes unaccounted for"));
}

TEST_F(WallWatchTest, ATubeOverAWallThatTheNextCloudStillShowsIsNotMissedThoughTheModelDropsIt) {
  // The tube over the wall is still in every capture; scan 1's model lost it.
  for (int i = 0; i < 30; ++i) scanner.points_Bin.push_back({-0.04 + 0.001 * i, -0.295, 0.225});
  ScriptATubeOverAWallThenAnotherScan();
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_SINGLE, 1.0), Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)};
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty) << result.message;
  EXPECT_EQ(scanner.calls, 3);
  EXPECT_TRUE(result.vanished_over_walls.empty());
}

TEST_F(WallWatchTest, ATubeOverAWallIsNotMissedAfterALiftOfSeveralTubes) {
  // The first lift holds two tubes and is put back: the one over the wall may have come along.
  params.max_plans_per_scan = 1;
  ScriptATubeOverAWallThenAnotherScan();
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_MULTIPLE, 2.0), Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)};
  const CellRunResult result = Run();
  EXPECT_EQ(Records("attempt").at(0)["analysis"]["outcome"], "multiple");
  EXPECT_TRUE(result.vanished_over_walls.empty());
}

TEST_F(WallWatchTest, ATubeOverAWallThatAnAttemptTookIsNotMissed) {
  // Along x over the +x wall, grasped at its middle: the place lays it on the place frame (the
  // cell check).
  auto first = Plans({MakePlan(7, {0.205, 0.0, 0.19})}, 0);
  AddTubeAxis(first.response, 7, {{0.0, 0.0, 0.17}, {0.41, 0.0, 0.21}});
  ASSERT_EQ(TubesOverWalls(first.response, cell.bin, 0, params.wall_watch).size(), 1u);
  planner.plan_answers = {first};
  params.check_tool_clearance = false;
  planner.wrench_answers = {Outcome(v1::HELD_OUTCOME_SINGLE, 1.0)};
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty);
  EXPECT_EQ(result.picks, 1u) << result.message;
  EXPECT_TRUE(result.vanished_over_walls.empty());
  EXPECT_EQ(DescribeRoundWarnings(result), "");
}

TEST_F(WallWatchTest, ATubeOverAWallThatAGraspClosedOnNothingDidNotTakeIsNamedWhenGone) {
  // Scan 0 plans tube 7 itself, along the -y wall and over its top: the grasp closes on nothing;
  // scan 1 (the bin empty) no longer shows it. In seed 14's 20-tree bin a grasp that closed on
  // nothing pressed the heap and three trees fell over the walls.
  auto first = Plans({MakePlan(7, {-0.15, -0.285, 0.17})}, 0);
  AddTubeAxis(first.response, 7, {{-0.25, -0.28, 0.15}, {-0.05, -0.29, 0.19}, {0.0, -0.305, 0.21}});
  planner.plan_answers = {first};
  params.check_tool_clearance = false;
  gripper.close_results = {ClosedOnNothing()};
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kBinEmpty) << result.message;
  const std::vector<json> attempts = Records("attempt");
  ASSERT_EQ(attempts.size(), 1u);
  EXPECT_EQ(attempts[0]["result"], "grasp_failed");
  ASSERT_EQ(result.vanished_over_walls.size(), 1u);
  EXPECT_EQ(result.vanished_over_walls[0],
            "over the -y wall at (0.000, -0.305, 0.210) m, not seen again after scan 0");
}

// ---------------------------------------------------------------- the safe stop's descent

class SafeStopDescentTest : public CellControllerTest {
 protected:
  void SetUp() override {
    CellControllerTest::SetUp();
    planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
    planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));
    observer = [this](CellState state) {
      if (state == CellState::kAnalyze) running->RequestStop("operator stop (SIGINT)");
    };
    ft.tcp = &robot.X_BinTcp;
  }
  /// Heights (bin z) the robot stopped at over the bin's middle, below the transit height, in order.
  std::vector<double> StopsOverTheBin() const {
    std::vector<double> z;
    for (const auto& m : robot.moves) {
      const Eigen::Vector3d q = m.X_BinTcpTarget.translation();
      if (!m.through && q.head<2>().norm() < kTol && q.z() < TransitHeight(params, cell) - kTol)
        z.push_back(q.z());
    }
    return z;
  }
};

TEST_F(SafeStopDescentTest, AHeldTubeThatRestsOnTheHeapIsReleasedThereNotPushedIn) {
  // Transit at 0.5 m, release at 0.15: 12 steps of 0.35 / 12 m. The heap takes the tube's weight
  // from 0.45 m down: the second step.
  ft.rests_below_z = 0.45;
  const CellRunResult result = Run();
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->action, "released_in_bin");
  const std::vector<double> stops = StopsOverTheBin();
  ASSERT_EQ(stops.size(), 2u);
  EXPECT_NEAR(stops[0], 0.5 - 0.35 / 12, kTol);
  EXPECT_NEAR(stops[1], 0.5 - 0.35 / 6, kTol);
  ASSERT_EQ(gripper.opened_at.size(), 2u);
  EXPECT_TRUE(gripper.opened_at[1].isApprox(Eigen::Vector3d(0.0, 0.0, stops[1]), kTol));
  EXPECT_THAT(result.message,
              ::testing::HasSubstr("released into the bin at X_BinTcp (0.000, 0.000, 0.442) m, "
                                   "where it rests on the heap (the load changed by 0.54 N)"));
}

TEST_F(SafeStopDescentTest, AHeldTubeOverALowHeapGoesDownToTheReleaseHeightInSteps) {
  const CellRunResult result = Run();
  ASSERT_TRUE(result.safe_stop);
  const std::vector<double> stops = StopsOverTheBin();
  ASSERT_EQ(stops.size(), 12u);  // 11 steps, then the release height
  for (std::size_t i = 0; i < stops.size(); ++i) EXPECT_NEAR(stops[i], 0.5 - 0.35 * (i + 1) / 12, kTol) << i;
  EXPECT_TRUE(gripper.opened_at.back().isApprox(Eigen::Vector3d(0.0, 0.0, params.safe_release_height), kTol));
}

TEST_F(SafeStopDescentTest, AnFtThatStopsAnsweringOnTheWayDownLowersTheTubeWithoutIt) {
  observer = [this](CellState state) {
    if (state == CellState::kAnalyze) running->RequestStop("operator stop (SIGINT)");
    if (state == CellState::kSafeStop) ft.fail_read_from = ft.reads + 2;  // over the bin, one step
  };
  const CellRunResult result = Run();
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->action, "released_in_bin");
  EXPECT_TRUE(gripper.opened_at.back().isApprox(Eigen::Vector3d(0.0, 0.0, params.safe_release_height), kTol));
  EXPECT_THAT(result.message, ::testing::HasSubstr("the F/T did not answer on the way down"));
  EXPECT_EQ(StopsOverTheBin().size(), 3u);  // two steps, then straight down
}

TEST_F(SafeStopDescentTest, WithoutStepsItIsOneMove) {
  params.safe_release_step = 0.0;
  ft.rests_below_z = 0.45;  // not read
  const CellRunResult result = Run();
  ASSERT_TRUE(result.safe_stop);
  ASSERT_EQ(StopsOverTheBin().size(), 1u);
  EXPECT_TRUE(gripper.opened_at.back().isApprox(Eigen::Vector3d(0.0, 0.0, params.safe_release_height), kTol));
}

TEST_F(CellControllerTest, StopAtTheScanStopsWithNothingHeld) {
  planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
  observer = [this](CellState state) {
    if (state == CellState::kScan) running->RequestStop("operator stop (SIGTERM)");
  };
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kStopped);
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->held, Held::kNothing);
  EXPECT_EQ(result.safe_stop->action, "stopped");
  EXPECT_EQ(scanner.calls, 0);
  EXPECT_TRUE(planner.plan_requests.empty());
  EXPECT_EQ(gripper.opens, 1);
  EXPECT_TRUE(robot.X_BinTcp.isApprox(HomePose(params, cell), kTol));
  EXPECT_NE(
      result.message.find("STOPPED: operator stop (SIGTERM) during scan; nothing held: stopped where it is"),
      std::string::npos)
      << result.message;
  EXPECT_TRUE(Records("attempt").empty());
  EXPECT_EQ(Records("safe_stop").at(0)["action"], "stopped");
  EXPECT_EQ(Records("end").at(0)["reason"], "stopped");
}

TEST_F(CellControllerTest, StopFromAnotherThreadIsNoticedBeforeTheNextMotion) {
  planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
  observer = [this](CellState state) {
    if (state != CellState::kLift) return;
    std::thread operator_thread([this] { running->RequestStop("stop button"); });
    operator_thread.join();
    EXPECT_TRUE(running->stop_requested());
  };
  // The lift state is entered, then the lift's MoveThrough would be the next motion: it is not made.
  const CellRunResult result = Run();
  EXPECT_EQ(result.reason, CellStopReason::kStopped) << result.message;
  EXPECT_EQ(robot.throughs, 0);
  EXPECT_EQ(Records("attempt").at(0)["stop"]["state"], "lift");
  ASSERT_TRUE(result.safe_stop);
  EXPECT_EQ(result.safe_stop->action, "released_in_bin");
}

TEST_F(CellControllerTest, AStopDuringALongPlanCancelsItAndDoesNotWaitForIt) {
  planner.block_plans = true;  // PlanPick would run until cancelled
  std::thread operator_thread;
  observer = [this, &operator_thread](CellState state) {
    if (state != CellState::kPlan || operator_thread.joinable()) return;
    operator_thread = std::thread([this] {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
      running->RequestStop("operator stop (SIGINT)");
    });
  };
  const CellRunResult result = Run();
  operator_thread.join();
  EXPECT_EQ(planner.cancels.load(), 1) << "RequestStop cancelled the planner call";
  EXPECT_EQ(result.reason, CellStopReason::kStopped) << result.message;
  EXPECT_NE(result.message.find("STOPPED: operator stop (SIGINT) during plan"), std::string::npos)
      << result.message;
  EXPECT_FALSE(result.fault) << "the cancelled call is the stop, not a planner fault";
  EXPECT_EQ(Records("end").at(0)["reason"], "stopped");
}

TEST_F(CellControllerTest, StopBeforeTheRunMovesNothingAndKeepsTheFirstReason) {
  CellController controller({&scanner, &robot, &gripper, &ft}, planner, cell, params, &sink);
  EXPECT_FALSE(controller.stop_requested());
  controller.RequestStop("stop button");
  controller.RequestStop("operator stop (SIGINT)");
  const CellRunResult result = controller.Run(1);
  EXPECT_EQ(result.reason, CellStopReason::kStopped);
  EXPECT_EQ(*result.operator_stop, "stop button");
  EXPECT_FALSE(robot.servo_on);
  EXPECT_TRUE(robot.moves.empty());
  EXPECT_EQ(gripper.activations + gripper.opens + gripper.closes, 0);
  EXPECT_NE(result.message.find(
                "STOPPED: stop button during start; stopped before the cell started: nothing moved"),
            std::string::npos)
      << result.message;
  // The controller stays stopped.
  EXPECT_EQ(controller.Run(2).reason, CellStopReason::kStopped);
  EXPECT_TRUE(robot.moves.empty());
}

// ---------------------------------------------------------------- dry run

TEST_F(CellControllerTest, DryRunMovesNothingAndListsTheCommandsOfTheBestExecutablePlan) {
  robot.forbid_motion = true;
  gripper.forbid_motion = true;
  planner.plan_answers.push_back(
      Plans({InMillimetres(MakePlan(1, p_Bin_grasp)), MakePlan(4, p_Bin_grasp)}, 5));
  const DryRunResult dry = DryRun();

  EXPECT_EQ(dry.run.reason, CellStopReason::kDryRun) << dry.run.message;
  EXPECT_EQ(dry.run.message,
            "dry run: plan 1 (tube 4) of 2: 10 commands planned, nothing moved (1 plans skipped)");
  ASSERT_TRUE(dry.plan_rank);
  EXPECT_EQ(*dry.plan_rank, 1u);
  EXPECT_EQ(dry.tube, 4u);
  ASSERT_EQ(dry.skipped_plans.size(), 1u);
  EXPECT_EQ(dry.skipped_plans[0]["check"], "cell_frame");
  EXPECT_EQ(ft.biases, 0);
  EXPECT_EQ(scanner.calls, 1);
  ASSERT_TRUE(dry.X_BinTcpStart);
  EXPECT_NEAR(dry.X_BinTcpStart->translation().z(), 1.0, kTol);

  ASSERT_EQ(dry.motions.size(), 10u);
  const Eigen::Isometry3d X_BinTcpPreGrasp =
      DownPose(p_Bin_grasp + Eigen::Vector3d(0, 0, params.approach_height));
  // First the approach: from home at transit height across, then down to the pre-grasp pose.
  const PlannedMotion& approach = dry.motions[0];
  EXPECT_EQ(approach.kind, MotionKind::kTransit);
  EXPECT_EQ(approach.state, CellState::kApproach);
  EXPECT_TRUE(approach.X_BinTcp.isApprox(X_BinTcpPreGrasp, kTol));
  ASSERT_EQ(approach.via.size(), 1u);
  EXPECT_NEAR(approach.via[0].translation().z(), TransitHeight(params, cell), kTol);
  EXPECT_DOUBLE_EQ(approach.speed, params.transit_speed);
  EXPECT_EQ(dry.motions[1].kind, MotionKind::kGripperMoveTo);
  EXPECT_DOUBLE_EQ(*dry.motions[1].gripper_opening, 0.045);
  EXPECT_EQ(dry.motions[2].kind, MotionKind::kMoveTo);
  EXPECT_TRUE(dry.motions[2].X_BinTcp.isApprox(DownPose(p_Bin_grasp), kTol));
  EXPECT_DOUBLE_EQ(dry.motions[2].speed, params.approach_speed);
  EXPECT_EQ(dry.motions[3].kind, MotionKind::kGripperClose);
  EXPECT_EQ(dry.motions[4].kind, MotionKind::kMoveThrough);
  EXPECT_EQ(dry.motions[4].waypoints_Bin.size(), 2u);
  EXPECT_TRUE(dry.motions[4].X_BinTcp.isApprox(DownPose(p_Bin_grasp + Eigen::Vector3d(0, 0, 0.4)), kTol));
  bool place = false;
  for (const PlannedMotion& m : dry.motions)
    if (m.kind == MotionKind::kMoveTo && m.X_BinTcp.isApprox(testing::PlacePose(), kTol)) place = true;
  EXPECT_TRUE(place);
  EXPECT_EQ(dry.motions[7].kind, MotionKind::kGripperOpen);
  EXPECT_TRUE(dry.motions[7].X_BinTcp.isApprox(testing::PlacePose(), kTol));
  EXPECT_TRUE(dry.motions.back().X_BinTcp.isApprox(HomePose(params, cell), kTol));

  // Nothing moved (forbid_motion would have failed the test), and one record says what would.
  EXPECT_TRUE(robot.moves.empty());
  EXPECT_EQ(gripper.activations + gripper.opens + gripper.closes + gripper.moves, 0);
  ASSERT_EQ(sink.records().size(), 1u);
  const json& record = sink.records()[0];
  EXPECT_EQ(record["type"], "dry_run");
  EXPECT_EQ(record["reason"], "dry_run");
  EXPECT_EQ(record["plan_rank"], 1);
  EXPECT_EQ(record["motions"].size(), 10u);
  EXPECT_EQ(record["motions"][0]["kind"], "transit");
  EXPECT_NEAR(record["motions"][0]["tcp_pose"]["position"][2].get<double>(),
              X_BinTcpPreGrasp.translation().z(), kTol);
  EXPECT_EQ(record["motions"][1]["gripper_opening"], 0.045);
  const std::string text = FormatDryRun(dry);
  EXPECT_NE(text.find("approach  transit"), std::string::npos) << text;
  EXPECT_NE(text.find("skipped plan 0 (tube 1): cell check:"), std::string::npos) << text;
}

TEST_F(CellControllerTest, DryRunListsExactlyTheRobotCommandsOfARun) { ExpectTheDryRunIsTheRun(); }

TEST_F(CellControllerTest, DryRunRaisesThePlacePoseAsTheRunDoes) {
  params.place_surface_height = 0.12;  // the place pose's TCP at 0.12: raised by 8 mm
  ExpectTheDryRunIsTheRun();
  EXPECT_NEAR(Records("attempt").at(0)["place_raised"].get<double>(),
              params.tool.finger_tip_depth + params.tool.margin, kTol);
}

void CellControllerTest::ExpectTheDryRunIsTheRun() {
  planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
  const DryRunResult dry = DryRun();
  ASSERT_FALSE(dry.motions.empty()) << dry.run.message;
  ASSERT_TRUE(robot.moves.empty());
  // The same plan, run: after the start's way home, the robot gets exactly the dry run's commands.
  planner.plan_answers.push_back(Plans({MakePlan(4, p_Bin_grasp)}, 1));
  planner.wrench_answers.push_back(Outcome(v1::HELD_OUTCOME_SINGLE, 1.0));
  ASSERT_EQ(Run().picks, 1u);
  std::vector<testing::ScriptedRobot::Move> expected;
  for (const PlannedMotion& m : dry.motions) {
    for (const Eigen::Isometry3d& X : m.via) expected.push_back({false, X, {}, m.speed});
    if (m.kind == MotionKind::kTransit || m.kind == MotionKind::kMoveTo)
      expected.push_back({false, m.X_BinTcp, {}, m.speed});
    if (m.kind == MotionKind::kMoveThrough) expected.push_back({true, m.X_BinTcp, m.waypoints_Bin, m.speed});
  }
  ASSERT_GE(robot.moves.size(), expected.size());
  const std::size_t start = robot.moves.size() - expected.size();
  EXPECT_EQ(start, 2u);  // home from (0, 0, 1): across at 1 m, down to the home pose
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const testing::ScriptedRobot::Move& done = robot.moves[start + i];
    EXPECT_EQ(done.through, expected[i].through) << i;
    EXPECT_TRUE(done.X_BinTcpTarget.isApprox(expected[i].X_BinTcpTarget, kTol)) << i;
    EXPECT_DOUBLE_EQ(done.speed, expected[i].speed) << i;
    EXPECT_EQ(done.waypoints_Bin.size(), expected[i].waypoints_Bin.size()) << i;
  }
  EXPECT_EQ(gripper.openings, std::vector<double>{*dry.motions[1].gripper_opening});
}

TEST_F(CellControllerTest, DryRunOfAnEmptyBinOrWithoutAnExecutablePlanListsNothing) {
  const DryRunResult empty = DryRun();
  EXPECT_EQ(empty.run.reason, CellStopReason::kBinEmpty);
  EXPECT_TRUE(empty.bin_empty);
  EXPECT_TRUE(empty.motions.empty());

  planner.plan_answers.push_back(Plans({InMillimetres(MakePlan(1, p_Bin_grasp))}, 1));
  const DryRunResult mismatch = DryRun();
  EXPECT_EQ(mismatch.run.reason, CellStopReason::kDryRun);
  EXPECT_TRUE(mismatch.motions.empty());
  EXPECT_FALSE(mismatch.plan_rank);
  ASSERT_TRUE(mismatch.cell_mismatch);
  EXPECT_NE(mismatch.run.message.find("no executable plan (1 plans, 1 tubes modeled): all 1 plans"),
            std::string::npos)
      << mismatch.run.message;
  EXPECT_TRUE(robot.moves.empty());
}

TEST_F(CellControllerTest, DryRunFaultNeverMovesEvenWhenTheGripperHoldsSomething) {
  robot.forbid_motion = true;
  gripper.forbid_motion = true;
  gripper.holding = true;  // left closed on a tube
  const Failure timeout{true, "PhoXi: no frame within 30000 ms"};
  scanner.failures = {timeout, timeout, timeout};
  const DryRunResult dry = DryRun();
  EXPECT_EQ(dry.run.reason, CellStopReason::kFault);
  ASSERT_TRUE(dry.run.safe_stop);
  EXPECT_EQ(dry.run.safe_stop->held, Held::kTube);
  EXPECT_EQ(dry.run.safe_stop->action, "stopped");
  EXPECT_NE(dry.run.message.find("dry run: nothing moved (the gripper holds tube)"), std::string::npos)
      << dry.run.message;
  EXPECT_TRUE(robot.moves.empty());
  EXPECT_EQ(Records("dry_run").at(0)["reason"], "fault");
}

TEST(CellControllerParamsTest, InvalidValuesNameTheField) {
  CellControllerParams params;
  params.lift_speed = -0.1;
  try {
    params.Validate();
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("lift_speed"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("-0.1"), std::string::npos) << e.what();
  }
  params = CellControllerParams{};
  params.max_attempts_per_tube = 0;
  EXPECT_THROW(params.Validate(), InvalidArgument);
  // A place surface at no height would let the place pose through unraised.
  params = CellControllerParams{};
  params.place_surface_height = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT([&] { params.Validate(); }, ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr(
                                              "place_surface_height: must be finite, got nan")));
}

}  // namespace
}  // namespace tubepick::cell

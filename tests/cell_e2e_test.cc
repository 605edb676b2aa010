// The cell end to end: a real PlannerServer in-process on loopback, the real gRPC planner client,
// the cell controller and the simulated cell (Bullet world behind all four devices).
#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <functional>
#include <string>
#include <thread>

#include "clients/cell/cell_controller.h"
#include "clients/cell/cell_records.h"
#include "clients/cell/cell_statistics.h"
#include "clients/cell/planner_client.h"
#include "clients/cli/cell/operator_stop.h"
#include "clients/cli/cell/planner_outage.h"
#include "clients/cli/cell/sim_round.h"
#include "devices/sim/sim_cell.h"
#include "physics/tube_geometry.h"
#include "server/planner_server.h"
#include "server/server_config.h"

namespace tubepick {
namespace {

using nlohmann::json;

/// A state observer that calls `arm` the first time the controller enters the place.
std::function<void(cell::CellState)> OnFirstPlace(std::function<void()> arm) {
  return [arm = std::move(arm), done = false](cell::CellState state) mutable {
    if (state != cell::CellState::kPlace || done) return;
    arm();
    done = true;
  };
}

class CellEndToEndTest : public ::testing::Test {
 protected:
  void SetUp() override {
    server::ServerConfig config;
    config.address = "127.0.0.1:0";
    config.metrics_address = "";
    config.log_level = "warn";
    server_ = std::make_unique<server::PlannerServer>(config);
    server_->Start();
  }
  void TearDown() override { server_->Shutdown(std::chrono::milliseconds(1000)); }

  std::string address() const { return "127.0.0.1:" + std::to_string(server_->port()); }

  std::unique_ptr<server::PlannerServer> server_;
};

TEST_F(CellEndToEndTest, ThreePvcTubesAreAllPickedAndPlaced) {
  cell::GrpcPlannerClient planner(address());
  cell::MemoryRecordSink sink;
  cell::CellControllerParams params;
  params.seed = 42;
  const devices::sim::SimCellParams sim =
      devices::sim::SimCellParams::Thesis(devices::sim::Material::kPvc, 3, 7);

  const cli::SimRoundResult r = cli::RunSimRound(planner, sim, params, 0, &sink);

  EXPECT_EQ(r.run.reason, cell::CellStopReason::kBinEmpty) << r.run.message;
  EXPECT_EQ(r.tubes_in_bin, 0u);
  EXPECT_EQ(r.tubes_outside_bin, 3u);
  EXPECT_EQ(r.run.picks, 3u);
  EXPECT_EQ(r.tubes_in_place_zone, 3u);
  EXPECT_EQ(r.tubes_unnoticed, 0u);
  EXPECT_LE(r.run.attempts, 3u * params.max_attempts_per_tube);
  EXPECT_GT(server_->calls_served(), 3u);  // PlanPick per scan + AnalyzeWrench per lift

  // The records tell the same story: every pick analysed as one tube, the truth agreeing.
  const cell::CellStatistics stats = cell::SummarizeRecords(sink.records());
  EXPECT_EQ(stats.rounds, 1u);
  EXPECT_EQ(stats.bins_emptied, 1u);
  EXPECT_EQ(stats.picks, 3u);
  EXPECT_EQ(stats.tubes_total, 3u);
  EXPECT_EQ(stats.tubes_lost, 0u);
  for (const json& rec : sink.records()) {
    if (rec["type"] != "attempt" || rec["result"] != "picked") continue;
    EXPECT_EQ(rec["gripper"]["object"], "stopped_closing");
    const std::string final_outcome =
        rec["wrench"]["after_resolution"].empty()
            ? rec["analysis"]["outcome"].get<std::string>()
            : rec["wrench"]["after_resolution"].back()["outcome"].get<std::string>();
    EXPECT_EQ(final_outcome, "single");
    EXPECT_EQ(rec["truth_after"]["tubes_in_bin"].get<int>(),
              rec["truth_before"]["tubes_in_bin"].get<int>() - 1);
    EXPECT_GT(rec["durations"]["robot_device_s"].get<double>(), 1.0);  // simulated seconds of motion
  }
  const json& end = sink.records().back();
  EXPECT_EQ(end["type"], "end");
  EXPECT_EQ(end["truth"]["tubes_in_bin"], 0);
}

/// A straight tube on the floor along x (five nodes), bin frame.
physics::TubeGeometry StraightTubeAlongX(int id, double radius, double length, double y) {
  physics::TubeGeometry tube;
  tube.id = id;
  for (int i = 0; i < 5; ++i)
    tube.nodes.push_back({i + 1, Eigen::Vector3d((i / 4.0 - 0.5) * length, y, radius), radius});
  for (int i = 0; i < 4; ++i) {
    physics::TubeEdge e;
    e.node1 = i + 1;
    e.node2 = i + 2;
    e.order = i + 1;
    e.radius = radius;
    physics::SetEdgeFromNodes(tube, e);
    tube.edges.push_back(e);
  }
  return tube;
}

TEST_F(CellEndToEndTest, ATubeOnThePlaceZoneThatNoPickPutThereIsCountedAsCarriedOutUnnoticed) {
  // One tube in the bin, and one already lying over the place zone as if a pick had carried it out
  // beside the tube it placed: one pick, two tubes over the zone.
  devices::sim::SimCellParams sim_params =
      devices::sim::SimCellParams::Thesis(devices::sim::Material::kPvc, 1, 5);
  const double r = sim_params.cell.tube.radius;
  const double y_place = sim_params.cell.place.X_BinPlace.translation().y();
  devices::sim::SimCell sim(sim_params,
                            {StraightTubeAlongX(1, r, 0.5, 0.0), StraightTubeAlongX(2, r, 0.5, y_place)});
  cell::GrpcPlannerClient planner(address());
  cell::MemoryRecordSink sink;

  const cli::SimRoundResult result = cli::RunSimRound(planner, sim, {}, 0, &sink);

  EXPECT_EQ(result.run.reason, cell::CellStopReason::kBinEmpty) << result.run.message;
  EXPECT_EQ(result.run.picks, 1u);
  EXPECT_EQ(result.tubes_in_place_zone, 2u);
  EXPECT_EQ(result.tubes_unnoticed, 1u);
  EXPECT_EQ(result.tubes_elsewhere, 0u);
}

TEST_F(CellEndToEndTest, TubeAlongALongWallIsNudgedOffItAndPicked) {
  // The last tube of a failed 20-round run: PVC, its axis 23.5 mm from the −y wall (11 mm between
  // tube and wall). Every grasp across it drives a pad or the housing into the wall, so the planner
  // rejects them all; the controller drags it off the wall, rescans and picks it.
  devices::sim::SimCellParams sim_params =
      devices::sim::SimCellParams::Thesis(devices::sim::Material::kPvc, 1, 5);
  const double r = sim_params.cell.tube.radius;
  devices::sim::SimCell sim(sim_params, {StraightTubeAlongX(1, r, 0.5, -0.3 + 0.0235)});
  cell::GrpcPlannerClient planner(address());
  cell::MemoryRecordSink sink;
  cell::CellControllerParams params;
  params.seed = 11;

  const cli::SimRoundResult result = cli::RunSimRound(planner, sim, params, 0, &sink);

  EXPECT_EQ(result.run.reason, cell::CellStopReason::kBinEmpty) << result.run.message;
  EXPECT_EQ(result.tubes_in_bin, 0u);
  EXPECT_EQ(result.run.picks, 1u);
  EXPECT_GE(result.run.nudges, 1u);
  EXPECT_LE(result.run.nudges, params.nudge.max_nudges_per_bin);
  std::vector<json> nudges;
  for (const json& rec : sink.records())
    if (rec["type"] == "attempt" && rec["result"] == "nudge") nudges.push_back(rec);
  ASSERT_EQ(nudges.size(), result.run.nudges);
  const json& first = nudges.front();
  EXPECT_EQ(first["plans"], 0);  // the planner filtered every grasp of the wall tube
  EXPECT_EQ(first["tubes_left_plan"], 1);
  EXPECT_NEAR(first["nudge"]["direction"][1].get<double>(), 1.0, 1e-9);  // straight off the −y wall
  EXPECT_LT(first["nudge"]["wall_distance"].get<double>(), 0.04);
  EXPECT_EQ(first["truth_after"]["tubes_in_bin"], 1);  // nudged, not thrown out

  const cell::CellStatistics stats = cell::SummarizeRecords(sink.records());
  EXPECT_EQ(stats.bins_emptied, 1u);
  EXPECT_EQ(stats.nudges.uses, result.run.nudges);
  EXPECT_EQ(stats.nudges.successes, 1u);
  EXPECT_EQ(stats.attempts, 1u);  // nudges are not picking attempts
}

TEST_F(CellEndToEndTest, ServerGoneWhileATubeIsHeldIsAnalysedLocallyThenTheRoundSafeStops) {
  cell::GrpcPlannerClientOptions options;
  options.max_retries = 1;
  options.initial_backoff = std::chrono::milliseconds(10);
  cell::GrpcPlannerClient planner(address(), options);
  cell::MemoryRecordSink sink;
  devices::sim::SimCell sim(devices::sim::SimCellParams::Thesis(devices::sim::Material::kPvc, 2, 3));
  // The server goes away the first time a lifted tube is about to be analysed: mid-round, with
  // a tube in the gripper.
  bool stopped = false;
  const auto stop_server_at_analyze = [&](cell::CellState state) {
    if (state != cell::CellState::kAnalyze || stopped) return;
    ASSERT_FALSE(sim.HeldTubes().empty());
    server_->Shutdown(std::chrono::milliseconds(0));
    stopped = true;
  };
  const cli::SimRoundResult r = cli::RunSimRound(planner, sim, {}, 0, &sink, stop_server_at_analyze);

  ASSERT_TRUE(stopped);
  // The held tube was analysed here and placed; the next PlanPick found no planner: a safe stop
  // with nothing held, where the arm was.
  EXPECT_EQ(r.run.picks, 1u) << r.run.message;
  EXPECT_EQ(r.run.local_analyses, 1u);
  EXPECT_EQ(r.run.reason, cell::CellStopReason::kFault);
  ASSERT_TRUE(r.run.fault);
  EXPECT_EQ(r.run.fault->device(), "planner");
  EXPECT_EQ(r.run.fault->kind(), cell::FaultKind::kServerUnavailable);
  EXPECT_EQ(r.run.fault->state(), "plan");
  ASSERT_TRUE(r.run.safe_stop);
  EXPECT_EQ(r.run.safe_stop->action, "stopped");
  EXPECT_EQ(r.tubes_in_bin, 1u);
  EXPECT_EQ(r.tubes_in_place_zone, 1u);
  EXPECT_EQ(r.tubes_elsewhere, 0u);
  const json picked = sink.records().at(0);
  EXPECT_EQ(picked["result"], "picked");
  EXPECT_EQ(picked["analysis"]["outcome"], "single");
  EXPECT_EQ(picked["analysis_fallback"]["local_analyses"], 1);
  EXPECT_NE(r.run.message.find("SAFE STOP: planner server_unavailable during plan"), std::string::npos)
      << r.run.message;
}

#ifdef TUBEPICK_SERVER
TEST_F(CellEndToEndTest, AStopWhileHoldingATreeOverAHighHeapReleasesItOnTheHeapNotPressedIntoIt) {
  // 20 pvc set-C trees: the heap under the bin's middle is higher than a held tree hangs at the
  // safe release height. The operator's Ctrl-C comes as the first lifted tree is to be analysed.
  cell::GrpcPlannerClient planner(address());
  cell::MemoryRecordSink sink;
  devices::sim::SimCellParams sim_params =
      devices::sim::SimCellParams::Thesis(devices::sim::Material::kPvc, 20, 8);
  cli::WithShapes("C", &sim_params);
  devices::sim::SimCell sim(sim_params);
  cell::CellControllerParams params;
  params.seed = 8000;
  cli::OperatorStop stop;
  bool raised = false;
  const auto ctrl_c_at_analyze = [&](cell::CellState state) {
    if (state != cell::CellState::kAnalyze || raised) return;
    ASSERT_FALSE(sim.HeldTubes().empty());
    std::raise(SIGINT);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the watcher polls every 20 ms
    raised = true;
  };
  const cli::SimRoundResult r = cli::RunSimRound(planner, sim, params, 0, &sink, ctrl_c_at_analyze, &stop);

  ASSERT_TRUE(raised);
  EXPECT_EQ(r.run.reason, cell::CellStopReason::kStopped) << r.run.message;
  ASSERT_TRUE(r.run.safe_stop);
  EXPECT_EQ(r.run.safe_stop->action, "released_in_bin") << r.run.message;
  // Opened where the tree came to rest, well above the release height the one move went to.
  ASSERT_TRUE(r.run.safe_stop->p_Bin_tcp);
  EXPECT_GT(r.run.safe_stop->p_Bin_tcp->z(), params.safe_release_height + 0.05) << r.run.message;
  EXPECT_NE(r.run.message.find("rests on the heap"), std::string::npos) << r.run.message;
  EXPECT_EQ(r.tubes_in_bin, 20u);
  EXPECT_EQ(r.tubes_elsewhere, 0u);
}

TEST(PlannerProcessTest, APlannerKilledBetweenCallsIsGivenUpAfterTheUnavailableBudgetNotTheDeadline) {
  // tubepick-server as a process, killed after one call (SIGTERM then SIGKILL at once, as the
  // fault campaign's outage does). The next PlanPick must end within the unavailable budget
  // (here 2 s), not wait out its deadline (a run's plan_deadline is 180 s): a cell whose planner
  // died stops within seconds and says why.
  cli::RestartableServer server(TUBEPICK_SERVER, {"--metrics-address", "", "--log-level", "info"});
  cell::GrpcPlannerClientOptions options;
  options.unavailable_budget = std::chrono::seconds(2);
  cell::GrpcPlannerClient planner(server.address(), options);
  const v1::PlanPickRequest empty;  // no cloud: INVALID_ARGUMENT, at once
  try {
    planner.PlanPick(empty, std::chrono::seconds(10));
    FAIL() << "an empty request was planned";
  } catch (const cell::PlannerError& e) {
    ASSERT_EQ(e.code(), grpc::StatusCode::INVALID_ARGUMENT) << e.what();
  }
  // As the campaign's outage does (RestartableServer::Kill): SIGTERM, so the server says goodbye
  // on the connection, then SIGKILL; the call starts in between, on the channel still READY.
  const pid_t pid = server.pid();
  ::kill(pid, SIGTERM);
  ::kill(pid, SIGKILL);
  const auto start = std::chrono::steady_clock::now();
  try {
    planner.PlanPick(empty, std::chrono::seconds(60));
    FAIL() << "planned without a planner";
  } catch (const cell::PlannerError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::UNAVAILABLE) << e.what();
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10));
}
#endif

TEST_F(CellEndToEndTest, TubeThatSlipsInTransitFallsIntoTheBinOrThePlaceZoneAndIsRecordedAsLost) {
  cell::GrpcPlannerClient planner(address());
  cell::MemoryRecordSink sink;
  devices::sim::SimCell sim(devices::sim::SimCellParams::Thesis(devices::sim::Material::kPvc, 2, 3));
  // The first transit to the place: the tube slips out 1.2 s in (moving across at transit height).
  const cli::SimRoundResult r =
      cli::RunSimRound(planner, sim, {}, 0, &sink, OnFirstPlace([&] { sim.ArmSlip(1.2); }));

  ASSERT_EQ(sim.fault_events().slips, 1u);
  EXPECT_EQ(r.run.lost, 1u) << r.run.message;
  EXPECT_EQ(r.tubes_elsewhere, 0u);  // it fell back into the bin or onto the place zone
  EXPECT_EQ(r.tubes_held, 0u);
  const json& lost = sink.records().at(0);
  EXPECT_EQ(lost["result"], "lost");
  EXPECT_EQ(lost["lost"]["state"], "place_transit");
  EXPECT_EQ(lost["lost"]["detected_by"], "gripper_status");
  // The round went on: rescanned and picked what was left in the bin.
  EXPECT_EQ(r.run.reason, cell::CellStopReason::kBinEmpty) << r.run.message;
  EXPECT_EQ(r.tubes_in_bin, 0u);
  EXPECT_EQ(r.tubes_in_place_zone, 2u);
}

TEST_F(CellEndToEndTest, ATubeThatSlipsOntoThePlaceZoneIsLostNotCarriedOutUnnoticed) {
  cell::GrpcPlannerClient planner(address());
  cell::MemoryRecordSink sink;
  devices::sim::SimCell sim(devices::sim::SimCellParams::Thesis(devices::sim::Material::kPvc, 2, 3));
  // The first transit to the place: the tube slips out 3 s in, over the place zone.
  const cli::SimRoundResult r =
      cli::RunSimRound(planner, sim, {}, 0, &sink, OnFirstPlace([&] { sim.ArmSlip(3.0); }));

  ASSERT_EQ(sim.fault_events().slips, 1u);
  EXPECT_EQ(r.run.lost, 1u) << r.run.message;
  EXPECT_EQ(r.run.picks, 1u);
  EXPECT_EQ(r.tubes_in_bin, 0u);
  EXPECT_EQ(r.tubes_in_place_zone, 2u);  // the pick, and the lost tube that fell there
  EXPECT_EQ(r.tubes_unnoticed, 0u);      // the controller recorded it: not carried out unnoticed
  EXPECT_EQ(r.tubes_elsewhere, 0u);
}

TEST_F(CellEndToEndTest, TubeCaughtOnTheToolAtThePlaceGoesBackIntoTheBinNotHome) {
  cell::GrpcPlannerClient planner(address());
  cell::MemoryRecordSink sink;
  devices::sim::SimCell sim(devices::sim::SimCellParams::Thesis(devices::sim::Material::kPvc, 2, 3));
  // The first place: the tube stays hooked on the tool when the gripper opens.
  const cli::SimRoundResult r =
      cli::RunSimRound(planner, sim, {}, 0, &sink, OnFirstPlace([&] { sim.ArmSnag(); }));

  ASSERT_EQ(sim.fault_events().snags, 1u);
  ASSERT_TRUE(r.run.fault) << r.run.message;
  EXPECT_EQ(r.run.fault->device(), "ft_sensor");
  EXPECT_EQ(r.run.fault->kind(), cell::FaultKind::kUnexpectedLoad);
  EXPECT_EQ(r.run.fault->state(), "place");
  EXPECT_EQ(r.run.picks, 0u);
  ASSERT_TRUE(r.run.safe_stop);
  EXPECT_EQ(r.run.safe_stop->action, "released_in_bin") << r.run.message;
  // Back in the bin with the other one: nothing on the place zone, nothing outside, nothing held.
  EXPECT_EQ(r.tubes_in_bin, 2u);
  EXPECT_EQ(r.tubes_in_place_zone, 0u);
  EXPECT_EQ(r.tubes_elsewhere, 0u);
  EXPECT_EQ(r.tubes_held, 0u);
  const json& attempt = sink.records().at(0);
  EXPECT_EQ(attempt["result"], "fault");
  EXPECT_EQ(attempt["placed"], false);
  // The tube's weight on the tool after opening, also after lowering it onto the place pose once.
  const double tube_weight = sim.cell().tube.mass * 9.81;
  for (const char* key : {"after_place", "after_place_again"}) {
    const json& f = attempt["wrench"][key]["force"];
    const double load = Eigen::Vector3d(f[0], f[1], f[2]).norm();
    EXPECT_NEAR(load, tube_weight, 0.25 * tube_weight) << key;
  }
}

}  // namespace
}  // namespace tubepick

// The cell end to end: a real PlannerServer in-process on loopback, the real gRPC planner client,
// the cell controller and the simulated cell (Bullet world behind all four devices).
#include <gtest/gtest.h>

#include <chrono>
#include <string>

#include "clients/cell/cell_controller.h"
#include "clients/cell/cell_records.h"
#include "clients/cell/cell_statistics.h"
#include "clients/cell/planner_client.h"
#include "clients/cell/sim_round.h"
#include "devices/sim/sim_cell.h"
#include "server/planner_server.h"
#include "server/server_config.h"

namespace tubepick {
namespace {

using nlohmann::json;

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

  const cell::SimRoundResult r = cell::RunSimRound(planner, sim, params, 0, &sink);

  EXPECT_EQ(r.run.reason, cell::CellStopReason::kBinEmpty) << r.run.message;
  EXPECT_EQ(r.tubes_in_bin, 0u);
  EXPECT_EQ(r.tubes_outside_bin, 3u);
  EXPECT_EQ(r.run.picks, 3u);
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

TEST_F(CellEndToEndTest, ServerGoneMidRoundEndsInSafeStopWithTheGripperOpen) {
  cell::GrpcPlannerClientOptions options;
  options.max_retries = 1;
  options.initial_backoff = std::chrono::milliseconds(10);
  cell::GrpcPlannerClient planner(address(), options);
  server_->Shutdown(std::chrono::milliseconds(0));
  cell::MemoryRecordSink sink;
  const cell::SimRoundResult r = cell::RunSimRound(
      planner, devices::sim::SimCellParams::Thesis(devices::sim::Material::kPvc, 2, 3), {}, 0, &sink);
  EXPECT_EQ(r.run.reason, cell::CellStopReason::kFault);
  ASSERT_TRUE(r.run.fault);
  EXPECT_EQ(r.run.fault->device(), "planner");
  EXPECT_EQ(r.run.fault->kind(), cell::FaultKind::kServerUnavailable);
  EXPECT_TRUE(r.run.gripper_opened);
  EXPECT_TRUE(r.run.moved_up);
  EXPECT_EQ(r.tubes_in_bin, 2u);
  EXPECT_NE(r.run.message.find("SAFE STOP: planner server_unavailable during plan"), std::string::npos)
      << r.run.message;
}

}  // namespace
}  // namespace tubepick

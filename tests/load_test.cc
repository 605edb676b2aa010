// The load tool (clients/cli/load/load_engine.h) and the health check (clients/cli/remote/health_command.h)
// against a real PlannerServer in-process on loopback: counts, percentile order, errors counted by status
// code, RSS sampling from the real metrics endpoint. The load room's pure logic: clients/cli/load/test/.
#include <gtest/gtest.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>

#include "clients/cli/inputs/builtin_scene.h"
#include "clients/cli/load/load_engine.h"
#include "clients/cli/load/load_metrics.h"
#include "clients/cli/remote/health_command.h"
#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"
#include "server/planner_server.h"
#include "server/server_config.h"
#include "wire/packed_cloud.h"

namespace tubepick::cli {
namespace {

/// Loopback server: gRPC and metrics on free ports, `workers` workers, queue `queue`.
class LocalServer {
 public:
  LocalServer(std::uint32_t workers, std::uint32_t queue) {
    server::ServerConfig config;
    config.address = "127.0.0.1:0";
    config.metrics_address = "127.0.0.1:0";
    config.workers = workers;
    config.queue_capacity = queue;
    config.log_level = "warn";
    server_ = std::make_unique<server::PlannerServer>(config);
    server_->Start();
  }
  ~LocalServer() { server_->Shutdown(std::chrono::milliseconds(0)); }
  std::string target() const { return "127.0.0.1:" + std::to_string(server_->port()); }
  std::string metrics_url() const {
    return "http://127.0.0.1:" + std::to_string(server_->metrics_port()) + "/metrics";
  }

 private:
  std::unique_ptr<server::PlannerServer> server_;
};

/// Three generated tubes in the default bin, every `every`-th scanner return (2.3 M points at 1).
const Points& SceneCloud(std::uint32_t every) {
  static const BuiltInScene scene = MakeBuiltInScene(CellConfig{}, 3, /*seed=*/7);
  static std::map<std::uint32_t, Points> thinned;
  Points& points = thinned[every];
  if (points.empty())
    for (std::size_t i = 0; i < scene.points_Sensor.size(); i += every)
      points.push_back(scene.points_Sensor[i]);
  return points;
}

LoadCloud GoodCloud() { return {"scene", PackXyz(SceneCloud(20)), v1::LENGTH_UNIT_METRE}; }
/// 13 bytes: not a whole number of points, which the server must answer INVALID_ARGUMENT.
LoadCloud BadCloud() { return {"bad", std::string(13, '\x01'), v1::LENGTH_UNIT_METRE}; }

void ExpectOrdered(const LatencySummary& l) {
  EXPECT_GT(l.min, 0.0);
  EXPECT_LE(l.min, l.p50);
  EXPECT_LE(l.p50, l.p90);
  EXPECT_LE(l.p90, l.p95);
  EXPECT_LE(l.p95, l.p99);
  EXPECT_LE(l.p99, l.max);
  EXPECT_GE(l.mean, l.min);
  EXPECT_LE(l.mean, l.max);
}

TEST(LoadAgainstServer, CountsOkAndInvalidArgumentRoundRobin) {
  LocalServer server(/*workers=*/2, /*queue=*/8);
  LoadOptions o;
  o.channel.target = server.target();
  o.rpcs = {LoadRpc::kModelTubes};
  o.concurrency = 2;
  o.total = 6;
  o.warmup = 2;
  o.metrics_url = server.metrics_url();
  o.metrics_interval_seconds = 0.2;
  const LoadReport r = RunLoad(o, {GoodCloud(), BadCloud()});

  EXPECT_EQ(r.rpc, "model");
  EXPECT_EQ(r.method, "tubepick.v1.PickPlannerService/ModelTubes");
  EXPECT_EQ(r.total, 6u);
  // Round robin over two clouds: 3 good, 3 bad calls, whatever the interleaving.
  EXPECT_EQ(r.ok, 3u);
  EXPECT_EQ(r.status_counts.at("OK"), 3u);
  EXPECT_EQ(r.status_counts.at("INVALID_ARGUMENT"), 3u);
  EXPECT_EQ(r.status_counts.size(), 2u);
  EXPECT_NE(r.error_examples.at("INVALID_ARGUMENT").find("cloud.xyz"), std::string::npos)
      << r.error_examples.at("INVALID_ARGUMENT");
  ExpectOrdered(r.latency);
  EXPECT_GT(r.elapsed_seconds, 0.0);
  EXPECT_NEAR(r.requests_per_second, 6.0 / r.elapsed_seconds, 1e-9);
  EXPECT_NEAR(r.ok_per_second, 3.0 / r.elapsed_seconds, 1e-9);

  ASSERT_TRUE(r.rss.has_value());
  ASSERT_FALSE(r.rss->samples.empty());
  EXPECT_EQ(r.rss->failed_scrapes, 0u);
  EXPECT_GT(r.rss->peak, 10'000'000u);  // a planning server is more than 10 MB resident
  EXPECT_GE(r.rss->peak, r.rss->first_window_max);

  const std::string text = FormatLoadReportText(r);
  EXPECT_NE(text.find("[INVALID_ARGUMENT] 3 responses"), std::string::npos) << text;
  EXPECT_NE(text.find("Server RSS"), std::string::npos) << text;
  const std::string json = FormatLoadReportJson(r);
  EXPECT_NE(json.find("\"INVALID_ARGUMENT\": 3"), std::string::npos) << json;

  // The wall-clock timeline: every measured call once, in start order, inside the run, codes as counted.
  ASSERT_EQ(r.calls.size(), 6u);
  const double now =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  std::map<std::string, int> codes;
  for (std::size_t i = 0; i < r.calls.size(); ++i) {
    const CallTiming& c = r.calls[i];
    if (i > 0) {
      EXPECT_GE(c.start_unix_seconds, r.calls[i - 1].start_unix_seconds);
    }
    EXPECT_GT(c.start_unix_seconds, now - 60.0);
    EXPECT_LE(c.start_unix_seconds + c.seconds, now);
    EXPECT_GT(c.seconds, 0.0);
    ++codes[c.code];
  }
  EXPECT_EQ(codes["OK"], 3);
  EXPECT_EQ(codes["INVALID_ARGUMENT"], 3);
  EXPECT_NE(json.find("\"calls\": ["), std::string::npos) << json;
  EXPECT_NE(json.find("\"start_unix_seconds\""), std::string::npos) << json;
}

TEST(LoadAgainstServer, AFixedRateStartsCallsOnTheirSlots) {
  // 4 calls a second for 1.5 s, each answered at once (INVALID_ARGUMENT): slots at 0, 0.25 .. 1.25 s,
  // whatever the two threads could do in between.
  LocalServer server(/*workers=*/2, /*queue=*/8);
  LoadOptions o;
  o.channel.target = server.target();
  o.rpcs = {LoadRpc::kModelTubes};
  o.concurrency = 2;
  o.duration_seconds = 1.5;
  o.rate = 4.0;
  const LoadReport r = RunLoad(o, {BadCloud()});
  EXPECT_EQ(r.total, 6u);
  EXPECT_EQ(r.status_counts.at("INVALID_ARGUMENT"), 6u);
  ASSERT_EQ(r.calls.size(), 6u);
  for (std::size_t i = 1; i < r.calls.size(); ++i)
    EXPECT_GT(r.calls[i].start_unix_seconds - r.calls[i - 1].start_unix_seconds, 0.15) << "call " << i;
  EXPECT_GT(r.calls.back().start_unix_seconds - r.calls.front().start_unix_seconds, 1.2);
  EXPECT_EQ(r.rate, 4.0);
  EXPECT_GE(r.max_start_lag_seconds, 0.0);
  EXPECT_NE(FormatLoadReportText(r).find("Rate:         4.000 calls/s asked"), std::string::npos);

  // Two RPCs take the slots in turn: 3 calls each, whichever thread is free first.
  o.rpcs = {LoadRpc::kModelTubes, LoadRpc::kPlanPick};
  const LoadReport mix = RunLoad(o, {BadCloud()});
  ASSERT_EQ(mix.by_rpc.size(), 2u);
  EXPECT_EQ(mix.by_rpc[0].total, 3u);
  EXPECT_EQ(mix.by_rpc[1].total, 3u);

  o.rate = -1.0;
  EXPECT_THROW(RunLoad(o, {BadCloud()}), InvalidArgument);
}

TEST(LoadAgainstServer, PlanPickStreamInSmallChunks) {
  LocalServer server(/*workers=*/1, /*queue=*/4);
  LoadOptions o;
  o.channel.target = server.target();
  o.rpcs = {LoadRpc::kPlanPickStream};
  o.disable_simulation = true;
  o.chunk_bytes = 64 * 1024;  // ~1.4 MB cloud → 22 chunks
  o.concurrency = 1;
  o.total = 2;
  const LoadReport r = RunLoad(o, {GoodCloud()});
  EXPECT_EQ(r.total, 2u);
  EXPECT_EQ(r.ok, 2u) << FormatLoadReportText(r);
  ExpectOrdered(r.latency);
}

TEST(LoadAgainstServer, AMixOfRpcsIsReportedEachAndTogether) {
  LocalServer server(/*workers=*/2, /*queue=*/4);
  LoadOptions o;
  o.channel.target = server.target();
  o.rpcs = {LoadRpc::kPlanPick, LoadRpc::kPlanPickStream};
  o.disable_simulation = true;
  o.chunk_bytes = 256 * 1024;
  o.concurrency = 2;
  o.total = 4;
  const LoadReport r = RunLoad(o, {GoodCloud()});
  EXPECT_EQ(r.rpc, "plan,plan-stream");
  EXPECT_EQ(r.method,
            "tubepick.v1.PickPlannerService/PlanPick, tubepick.v1.PickPlannerService/PlanPickStream");
  EXPECT_EQ(r.total, 4u);
  EXPECT_EQ(r.ok, 4u) << FormatLoadReportText(r);
  ASSERT_EQ(r.by_rpc.size(), 2u);
  // One thread each: both start a call at once, the other two go to whichever finishes first.
  EXPECT_EQ(r.by_rpc[0].rpc, "plan");
  EXPECT_EQ(r.by_rpc[0].method, "tubepick.v1.PickPlannerService/PlanPick");
  EXPECT_GE(r.by_rpc[0].total, 1u);
  EXPECT_EQ(r.by_rpc[0].ok, r.by_rpc[0].total);
  EXPECT_EQ(r.by_rpc[1].rpc, "plan-stream");
  EXPECT_GE(r.by_rpc[1].total, 1u);
  EXPECT_EQ(r.by_rpc[1].status_counts.at("OK"), r.by_rpc[1].total);
  EXPECT_EQ(r.by_rpc[0].total + r.by_rpc[1].total, 4u);
  ExpectOrdered(r.by_rpc[0].latency);
  ExpectOrdered(r.by_rpc[1].latency);
  const std::string text = FormatLoadReportText(r);
  EXPECT_NE(text.find("By RPC"), std::string::npos) << text;
  EXPECT_NE(text.find("plan-stream"), std::string::npos) << text;
  EXPECT_NE(FormatLoadReportJson(r).find("\"by_rpc\""), std::string::npos);

  o.concurrency = 3;  // not a multiple of two RPCs
  EXPECT_THROW(RunLoad(o, {GoodCloud()}), InvalidArgument);
}

TEST(LoadAgainstServer, ExpiredDeadlinesAreCountedByCode) {
  LocalServer server(/*workers=*/1, /*queue=*/4);
  LoadOptions o;
  o.channel.target = server.target();
  o.rpcs = {LoadRpc::kPlanPick};
  o.concurrency = 1;
  o.total = 2;
  o.deadline_seconds = 0.001;  // far below one plan of 2.3 M points
  const LoadReport r = RunLoad(o, {{"full", PackXyz(SceneCloud(1)), v1::LENGTH_UNIT_METRE}});
  EXPECT_EQ(r.total, 2u);
  EXPECT_EQ(r.ok, 0u);
  EXPECT_EQ(r.status_counts.at("DEADLINE_EXCEEDED"), 2u);
  EXPECT_EQ(r.latency.max, 0.0);  // no successful call, no latency
}

TEST(LoadAgainstServer, FullQueueIsCountedAsResourceExhausted) {
  // One worker and one queue slot: of four calls arriving at once, at most two are admitted.
  LocalServer server(/*workers=*/1, /*queue=*/1);
  LoadOptions o;
  o.channel.target = server.target();
  o.rpcs = {LoadRpc::kModelTubes};
  o.concurrency = 4;
  o.total = 8;
  const LoadReport r = RunLoad(o, {{"full", PackXyz(SceneCloud(1)), v1::LENGTH_UNIT_METRE}});
  EXPECT_EQ(r.total, 8u);
  EXPECT_GE(r.ok, 1u);
  ASSERT_TRUE(r.status_counts.contains("RESOURCE_EXHAUSTED")) << FormatLoadReportText(r);
  EXPECT_EQ(r.ok + r.status_counts.at("RESOURCE_EXHAUSTED"), 8u) << FormatLoadReportText(r);
}

TEST(LoadAgainstServer, UnreachableTargetThrows) {
  LoadOptions o;
  o.channel.target = "127.0.0.1:1";
  o.total = 1;
  o.connect_timeout_seconds = 0.5;
  EXPECT_THROW(RunLoad(o, {GoodCloud()}), InvalidArgument);
  o.total = 0;
  EXPECT_THROW(RunLoad(o, {GoodCloud()}), InvalidArgument);  // neither total nor duration
}

TEST(Health, ServingServerAndClosedPort) {
  LocalServer server(/*workers=*/1, /*queue=*/1);
  ChannelOptions channel;
  channel.target = server.target();
  const HealthAnswer whole = CheckHealth(channel, "", std::chrono::seconds(5));
  EXPECT_EQ(whole.grpc_code, 0) << whole.grpc_message;
  EXPECT_EQ(whole.status, ServingStatus::kServing);
  const HealthAnswer service =
      CheckHealth(channel, "tubepick.v1.PickPlannerService", std::chrono::seconds(5));
  EXPECT_EQ(service.status, ServingStatus::kServing);
  const HealthAnswer unknown = CheckHealth(channel, "no.such.Service", std::chrono::seconds(5));
  EXPECT_EQ(unknown.grpc_code, static_cast<int>(grpc::StatusCode::NOT_FOUND));

  channel.target = "127.0.0.1:1";
  const HealthAnswer closed = CheckHealth(channel, "", std::chrono::seconds(2));
  EXPECT_EQ(closed.grpc_code, static_cast<int>(grpc::StatusCode::UNAVAILABLE)) << closed.grpc_message;
}

}  // namespace
}  // namespace tubepick::cli

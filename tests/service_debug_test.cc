// /debug/calls: a real PlannerServer keeps its last calls (debug.keep_last) and its HTTP port serves
// them: the list, each call's viewer page and its data.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/service_test_support.h"
#include "wire/proto_convert.h"

namespace tubepick {
namespace {

using service_test::HttpExchange;
using ::testing::HasSubstr;

// The body of a GET, or the whole answer when it is not 200.
std::string Get(int port, const std::string& path, int* status) {
  const std::string answer = HttpExchange(port, "GET " + path + " HTTP/1.1\r\nHost: x\r\n\r\n");
  *status = std::stoi(answer.substr(9, 3));
  const std::size_t body = answer.find("\r\n\r\n");
  return body == std::string::npos ? answer : answer.substr(body + 4);
}

nlohmann::json GetJson(int port, const std::string& path) {
  int status = 0;
  const std::string body = Get(port, path, &status);
  EXPECT_EQ(status, 200) << path << ": " << body;
  return nlohmann::json::parse(body);
}

TEST(DebugCalls, TheLastCallsAreKeptWithTheirCloudResponseOrError) {
  server::ServerConfig config = service_test::TestConfig(1);
  config.debug.keep_last = 2;
  config.debug.max_points = 5000;
  service_test::TestServer server(config);
  const int port = server.metrics_port();

  // 1: a model, 2: a plan, 3: a plan of a cloud in millimetres that the cell says are metres.
  v1::ModelTubesResponse model;
  {
    grpc::ClientContext context;
    ASSERT_TRUE(server.stub()
                    .ModelTubes(&context, service_test::ModelRequest(service_test::ThreeTubeCloud()), &model)
                    .ok());
  }
  v1::PlanPickResponse plan;
  {
    // The server's cell, but with its tubes said to be 0.30 m long (they are 0.46-0.50 m): answered
    // with a warning, which the list shows.
    v1::PlanPickRequest request = service_test::PlanRequest(service_test::ThreeTubeCloud());
    CellConfig cell;
    cell.tube.length = 0.30;
    *request.mutable_cell() = ToCellDescription(cell, cell.sensor.X_BinSensor);
    grpc::ClientContext context;
    ASSERT_TRUE(server.stub().PlanPick(&context, request, &plan).ok());
  }
  ASSERT_EQ(plan.tubes_size(), 3);
  ASSERT_GT(plan.plans_size(), 0);
  {
    Points mm;
    for (int i = 0; i < 2000; ++i) mm.emplace_back(0.1f * i, 0.2f * i, 1000.0f);
    v1::PlanPickResponse ignored;
    grpc::ClientContext context;
    EXPECT_EQ(server.stub()
                  .PlanPick(&context, service_test::PlanRequest(service_test::PackCloud(mm)), &ignored)
                  .error_code(),
              grpc::StatusCode::FAILED_PRECONDITION);
  }

  // Newest first; the ModelTubes call (1) is no longer kept.
  const nlohmann::json list = GetJson(port, "/debug/calls.json");
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0]["id"], 3);
  EXPECT_EQ(list[0]["code"], "FAILED_PRECONDITION");
  EXPECT_EQ(list[1]["id"], 2);
  EXPECT_EQ(list[1]["rpc"], "PlanPick");
  EXPECT_EQ(list[1]["tubes"], 3);
  EXPECT_EQ(list[1]["warnings"], nlohmann::json({"tube_length_shorter_than_scan"}));
  EXPECT_EQ(list[0]["warnings"], nlohmann::json::array());
  int status = 0;
  EXPECT_THAT(Get(port, "/debug/calls/1", &status), HasSubstr("call 1 is not kept"));
  EXPECT_EQ(status, 404);

  // The plan's page data: the response the client got, the cloud thinned to max_points.
  const nlohmann::json page = GetJson(port, "/debug/calls/2.json");
  EXPECT_EQ(page["format"], "tubepick-view/1");
  ASSERT_EQ(page["frames"].size(), 1u);
  const nlohmann::json& frame = page["frames"][0];
  EXPECT_EQ(frame["plan"]["tubes"].size(), 3u);
  EXPECT_EQ(frame["plan"]["plans"].size(), static_cast<std::size_t>(plan.plans_size()));
  EXPECT_EQ(frame["plan"]["plans"][0]["tubeId"], plan.plans(0).tube_id());
  const std::uint64_t total = service_test::ThreeTubeCloud().size() / 12;
  EXPECT_EQ(frame["cloud"]["total_points"], total);
  EXPECT_LE(frame["cloud"]["points"].get<std::uint64_t>(), 5000u);
  EXPECT_GE(frame["cloud"]["points"].get<std::uint64_t>(), 4000u);
  EXPECT_EQ(page["links"][0]["href"], "/debug/calls");

  // The failed call: its error and its cloud, no plan.
  const nlohmann::json failed = GetJson(port, "/debug/calls/3.json")["frames"][0];
  EXPECT_THAT(failed["error"].get<std::string>(), HasSubstr("FAILED_PRECONDITION"));
  EXPECT_EQ(failed["cloud"]["total_points"], 2000);
  EXPECT_FALSE(failed.contains("plan"));

  // The HTML: the list links each kept call; a call's page is the viewer with its data inline.
  const std::string html = Get(port, "/debug/calls", &status);
  EXPECT_EQ(status, 200);
  EXPECT_THAT(html, HasSubstr("<a data-call-id=\"3\" href=\"/debug/calls/3\">"));
  EXPECT_THAT(html, HasSubstr("<a data-call-id=\"2\" href=\"/debug/calls/2\">"));
  EXPECT_LT(html.find("data-call-id=\"3\""), html.find("data-call-id=\"2\""));
  EXPECT_THAT(html, HasSubstr("<td>warnings: tube_length_shorter_than_scan</td>"));
  const std::string viewer = Get(port, "/debug/calls/2", &status);
  EXPECT_EQ(status, 200);
  EXPECT_THAT(viewer, HasSubstr("<script type=\"application/json\" id=\"tubepick-data\">"));
  // A browser accepts Brotli and gzip; the page still comes uncompressed (the library would spend
  // seconds of a planning core on Brotli: docs/SERVICE.md).
  const std::string page_answer = service_test::HttpExchange(
      port, "GET /debug/calls/2 HTTP/1.1\r\nHost: x\r\nAccept-Encoding: gzip, deflate, br\r\n\r\n");
  EXPECT_EQ(page_answer.rfind("HTTP/1.1 200 ", 0), 0u);
  EXPECT_THAT(page_answer.substr(0, page_answer.find("\r\n\r\n")),
              ::testing::Not(HasSubstr("Content-Encoding")));
  EXPECT_THAT(page_answer, HasSubstr("id=\"tubepick-data\">"));
  EXPECT_EQ(Get(port, "/debug/calls/x", &status).empty(), false);
  EXPECT_EQ(status, 404);
}

}  // namespace
}  // namespace tubepick

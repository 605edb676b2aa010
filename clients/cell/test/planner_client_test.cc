#include "clients/cell/planner_client.h"

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <atomic>
#include <deque>
#include <mutex>
#include <thread>

#include "core/common/errors.h"
#include "tubepick/v1/service.grpc.pb.h"

namespace tubepick::cell {
namespace {

/// A real gRPC server whose PickPlannerService answers each call with the next scripted status
/// (OK answers carry a marker). It stands in for tubepick-server where a test needs failures the
/// real server cannot be made to produce on demand (UNAVAILABLE, RESOURCE_EXHAUSTED on call n).
class ScriptedService final : public v1::PickPlannerService::Service {
 public:
  std::deque<grpc::Status> statuses;
  std::atomic<int> calls{0};
  std::chrono::milliseconds delay{0};

  grpc::Status PlanPick(grpc::ServerContext*, const v1::PlanPickRequest* request,
                        v1::PlanPickResponse* response) override {
    ++calls;
    if (delay.count() > 0) std::this_thread::sleep_for(delay);
    const grpc::Status status = Next();
    if (status.ok()) response->set_total_seconds(request->options().max_plans());
    return status;
  }
  grpc::Status AnalyzeWrench(grpc::ServerContext*, const v1::AnalyzeWrenchRequest* request,
                             v1::AnalyzeWrenchResponse* response) override {
    ++calls;
    const grpc::Status status = Next();
    if (status.ok()) {
      response->set_outcome(v1::HELD_OUTCOME_SINGLE);
      response->set_tube_weight(request->tube_mass() * 9.81);
    }
    return status;
  }

 private:
  grpc::Status Next() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (statuses.empty()) return grpc::Status::OK;
    grpc::Status s = statuses.front();
    statuses.pop_front();
    return s;
  }
  std::mutex mutex_;
};

class PlannerClientTest : public ::testing::Test {
 protected:
  void SetUp() override {
    grpc::ServerBuilder builder;
    builder.AddListeningPort("127.0.0.1:0", grpc::InsecureServerCredentials(), &port_);
    builder.RegisterService(&service_);
    server_ = builder.BuildAndStart();
    ASSERT_TRUE(server_);
    ASSERT_GT(port_, 0);
    options_.initial_backoff = std::chrono::milliseconds(1);
    options_.max_backoff = std::chrono::milliseconds(4);
  }
  void TearDown() override { server_->Shutdown(); }

  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  v1::PlanPickRequest Request() const {
    v1::PlanPickRequest r;
    r.mutable_options()->set_max_plans(7);
    return r;
  }

  ScriptedService service_;
  int port_ = 0;
  std::unique_ptr<grpc::Server> server_;
  GrpcPlannerClientOptions options_;
  static constexpr std::chrono::milliseconds kDeadline{5000};
};

TEST_F(PlannerClientTest, AnswersPassThrough) {
  GrpcPlannerClient client(address(), options_);
  EXPECT_DOUBLE_EQ(client.PlanPick(Request(), kDeadline).total_seconds(), 7.0);
  v1::AnalyzeWrenchRequest w;
  w.set_tube_mass(0.1);
  const v1::AnalyzeWrenchResponse r = client.AnalyzeWrench(w, kDeadline);
  EXPECT_EQ(r.outcome(), v1::HELD_OUTCOME_SINGLE);
  EXPECT_NEAR(r.tube_weight(), 0.981, 1e-12);
  EXPECT_EQ(service_.calls, 2);
}

TEST_F(PlannerClientTest, RetriesUnavailableAndResourceExhaustedThenSucceeds) {
  service_.statuses = {grpc::Status(grpc::StatusCode::UNAVAILABLE, "shutting down"),
                       grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, "queue full (8 waiting)")};
  GrpcPlannerClient client(address(), options_);
  EXPECT_DOUBLE_EQ(client.PlanPick(Request(), kDeadline).total_seconds(), 7.0);
  EXPECT_EQ(service_.calls, 3);
}

TEST_F(PlannerClientTest, GivesUpAfterMaxRetriesWithTheLastStatus) {
  options_.max_retries = 2;
  for (int i = 0; i < 5; ++i)
    service_.statuses.push_back(grpc::Status(grpc::StatusCode::RESOURCE_EXHAUSTED, "queue full (8 waiting)"));
  GrpcPlannerClient client(address(), options_);
  try {
    client.PlanPick(Request(), kDeadline);
    FAIL() << "expected PlannerError";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
    EXPECT_EQ(e.tries(), 3u);
    EXPECT_EQ(e.rpc(), "PlanPick");
    EXPECT_EQ(e.message(), "queue full (8 waiting)");
    EXPECT_STREQ(e.what(), "PlanPick failed after 3 tries: RESOURCE_EXHAUSTED: queue full (8 waiting)");
  }
  EXPECT_EQ(service_.calls, 3);
}

TEST_F(PlannerClientTest, OtherCodesAreNotRetried) {
  service_.statuses = {
      grpc::Status(grpc::StatusCode::INVALID_ARGUMENT, "cloud.xyz: size 13 is not a multiple of 12")};
  GrpcPlannerClient client(address(), options_);
  try {
    client.PlanPick(Request(), kDeadline);
    FAIL() << "expected PlannerError";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::INVALID_ARGUMENT);
    EXPECT_EQ(e.tries(), 1u);
    EXPECT_NE(std::string(e.what()).find("after 1 try: INVALID_ARGUMENT: cloud.xyz"), std::string::npos);
  }
  EXPECT_EQ(service_.calls, 1);
}

TEST_F(PlannerClientTest, DeadlineExceededIsReportedAndNotRetried) {
  service_.delay = std::chrono::milliseconds(300);
  GrpcPlannerClient client(address(), options_);
  try {
    client.PlanPick(Request(), std::chrono::milliseconds(50));
    FAIL() << "expected PlannerError";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::DEADLINE_EXCEEDED);
    EXPECT_EQ(e.tries(), 1u);
  }
}

TEST_F(PlannerClientTest, NoServerIsUnavailableAfterTheRetries) {
  options_.max_retries = 1;
  GrpcPlannerClient client("127.0.0.1:1", options_);
  try {
    client.AnalyzeWrench(v1::AnalyzeWrenchRequest(), kDeadline);
    FAIL() << "expected PlannerError";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::UNAVAILABLE);
    EXPECT_EQ(e.tries(), 2u);
    EXPECT_EQ(e.rpc(), "AnalyzeWrench");
  }
}

TEST(GrpcPlannerClientOptionsTest, BadOptionsAreRejected) {
  GrpcPlannerClientOptions options;
  options.initial_backoff = std::chrono::milliseconds(500);
  options.max_backoff = std::chrono::milliseconds(100);
  EXPECT_THROW(GrpcPlannerClient("127.0.0.1:1", options), InvalidArgument);
  EXPECT_THROW(GrpcPlannerClient(""), InvalidArgument);
}

}  // namespace
}  // namespace tubepick::cell

#include "clients/cell/planner_client.h"

#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
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
  std::atomic<std::chrono::milliseconds> delay{std::chrono::milliseconds(0)};

  grpc::Status PlanPick(grpc::ServerContext*, const v1::PlanPickRequest* request,
                        v1::PlanPickResponse* response) override {
    ++calls;
    if (delay.load().count() > 0) std::this_thread::sleep_for(delay.load());
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
    EXPECT_EQ(e.message(), "queue full (8 waiting) (max_retries = 2)");
    EXPECT_STREQ(
        e.what(),
        "PlanPick failed after 3 tries: RESOURCE_EXHAUSTED: queue full (8 waiting) (max_retries = 2)");
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

TEST_F(PlannerClientTest, NoServerIsUnavailableAfterTheBudgetWithGrpcsReason) {
  options_.unavailable_budget = std::chrono::milliseconds(300);
  GrpcPlannerClient client("127.0.0.1:1", options_);
  const auto start = std::chrono::steady_clock::now();
  try {
    client.AnalyzeWrench(v1::AnalyzeWrenchRequest(), kDeadline);
    FAIL() << "expected PlannerError";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::UNAVAILABLE);
    EXPECT_EQ(e.tries(), 1u);
    EXPECT_EQ(e.rpc(), "AnalyzeWrench");
    const std::string what = e.what();
    EXPECT_NE(what.find("no connection to the planner at 127.0.0.1:1 within 0.3 s (unavailable_budget)"),
              std::string::npos)
        << what;
    // gRPC's own reason, and the likely cause.
    EXPECT_NE(what.find("refused"), std::string::npos) << what;
    EXPECT_NE(what.find("is the planner running and listening at 127.0.0.1:1?"), std::string::npos) << what;
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(3));
}

TEST_F(PlannerClientTest, ACallWaitsForThePlannerNoLongerThanItsDeadline) {
  GrpcPlannerClient client("127.0.0.1:1", options_);  // unavailable_budget 15 s
  const auto start = std::chrono::steady_clock::now();
  try {
    client.AnalyzeWrench(v1::AnalyzeWrenchRequest(), std::chrono::milliseconds(300));
    FAIL() << "expected PlannerError";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::UNAVAILABLE);
    EXPECT_NE(std::string(e.what()).find("within 0.3 s (the call's deadline)"), std::string::npos)
        << e.what();
  }
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(3));
}

TEST_F(PlannerClientTest, UnavailableAnswersAreRetriedWithinTheBudget) {
  options_.initial_backoff = std::chrono::milliseconds(50);
  options_.max_backoff = std::chrono::milliseconds(50);
  options_.unavailable_budget = std::chrono::milliseconds(230);  // 4 backoffs of 50 ms fit, not 5
  GrpcPlannerClient client(address(), options_);
  // Connected first: the wait for a connection counts against the budget too, and on a loaded
  // machine the first connection alone can take more than the 30 ms left over.
  client.PlanPick(Request(), kDeadline);
  ASSERT_EQ(service_.calls, 1);
  for (int i = 0; i < 10; ++i)
    service_.statuses.push_back(grpc::Status(grpc::StatusCode::UNAVAILABLE, "draining"));
  try {
    client.PlanPick(Request(), kDeadline);
    FAIL() << "expected PlannerError";
  } catch (const PlannerError& e) {
    EXPECT_EQ(e.code(), grpc::StatusCode::UNAVAILABLE);
    EXPECT_EQ(e.tries(), 5u);
    EXPECT_NE(std::string(e.what()).find(
                  "draining (unavailable_budget of 0.2 s spent unable to reach the planner)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(service_.calls, 1 + 5);
}

/// Calls `call` on another thread, cancels after `after`; returns how long the call ran and its error.
template <typename Call>
std::pair<std::chrono::steady_clock::duration, std::optional<PlannerError>> CancelledAfter(
    GrpcPlannerClient& client, std::chrono::milliseconds after, Call call) {
  std::optional<PlannerError> error;
  std::chrono::steady_clock::duration took{};
  std::thread caller([&] {
    const auto start = std::chrono::steady_clock::now();
    try {
      call();
    } catch (const PlannerError& e) {
      error = e;
    }
    took = std::chrono::steady_clock::now() - start;
  });
  std::this_thread::sleep_for(after);
  client.CancelCalls();
  caller.join();
  return {took, error};
}

TEST_F(PlannerClientTest, CancelCallsEndsAPlanPickInFlightAndLaterCallsRun) {
  service_.delay = std::chrono::milliseconds(2000);  // a long plan
  GrpcPlannerClient client(address(), options_);
  const auto [took, error] =
      CancelledAfter(client, std::chrono::milliseconds(300), [&] { client.PlanPick(Request(), kDeadline); });
  ASSERT_TRUE(error);
  EXPECT_EQ(error->code(), grpc::StatusCode::CANCELLED) << error->what();
  EXPECT_LT(took, std::chrono::milliseconds(1500)) << "the call did not wait for the plan";
  service_.delay = std::chrono::milliseconds(0);
  EXPECT_EQ(client.PlanPick(Request(), kDeadline).total_seconds(), 7) << "a call after the cancel runs";
}

TEST(GrpcPlannerClientCancelTest, CancelCallsEndsTheWaitForAPlannerThatIsAway) {
  GrpcPlannerClient client("127.0.0.1:1");  // the default 15 s budget
  const auto [took, error] = CancelledAfter(client, std::chrono::milliseconds(300), [&] {
    client.PlanPick(v1::PlanPickRequest(), std::chrono::seconds(300));
  });
  ASSERT_TRUE(error);
  EXPECT_EQ(error->code(), grpc::StatusCode::CANCELLED) << error->what();
  EXPECT_LT(took, std::chrono::milliseconds(1500));
}

TEST(GrpcPlannerClientOptionsTest, BadOptionsAreRejected) {
  GrpcPlannerClientOptions options;
  options.initial_backoff = std::chrono::milliseconds(500);
  options.max_backoff = std::chrono::milliseconds(100);
  EXPECT_THROW(GrpcPlannerClient("127.0.0.1:1", options), InvalidArgument);
  EXPECT_THROW(GrpcPlannerClient(""), InvalidArgument);
  options = {};
  options.unavailable_budget = std::chrono::milliseconds(0);
  EXPECT_THROW(GrpcPlannerClient("127.0.0.1:1", options), InvalidArgument);
}

TEST(GrpcPlannerClientOptionsTest, DefaultsRideOutARestartOfTenSeconds) {
  const GrpcPlannerClientOptions options;
  EXPECT_GE(options.unavailable_budget, std::chrono::seconds(10));
  EXPECT_LE(options.max_backoff, std::chrono::seconds(1));
  EXPECT_FALSE(options.max_retries);
}

// ---------------------------------------------------------------- a planner restart

/// A real gRPC server with `service` on `address` ("127.0.0.1:0" picks a port); *port gets it.
std::unique_ptr<grpc::Server> StartServer(
    grpc::Service& service, const std::string& address, int* port,
    std::shared_ptr<grpc::ServerCredentials> credentials = grpc::InsecureServerCredentials()) {
  grpc::ServerBuilder builder;
  builder.AddListeningPort(address, credentials, port);
  builder.RegisterService(&service);
  return builder.BuildAndStart();
}

TEST(PlannerRestartTest, ACallWaitingWhileThePlannerRestartsOnTheSamePortSucceeds) {
  ScriptedService service;
  int port = 0;
  std::unique_ptr<grpc::Server> server = StartServer(service, "127.0.0.1:0", &port);
  ASSERT_TRUE(server);
  const std::string address = "127.0.0.1:" + std::to_string(port);
  GrpcPlannerClient client(address);  // the defaults: unavailable_budget 15 s, reconnect ≤ 1 s apart
  v1::PlanPickRequest request;
  request.mutable_options()->set_max_plans(3);
  ASSERT_DOUBLE_EQ(client.PlanPick(request, std::chrono::seconds(5)).total_seconds(), 3.0);

  // The planner goes away; a call made now waits for it. It is back on the same port after 4 s.
  server->Shutdown();
  server.reset();
  constexpr auto kDown = std::chrono::seconds(4);
  std::unique_ptr<grpc::Server> restarted;
  std::chrono::steady_clock::time_point back;
  const auto start = std::chrono::steady_clock::now();
  std::thread restart([&] {
    std::this_thread::sleep_for(kDown);
    int same_port = 0;
    restarted = StartServer(service, address, &same_port);
    back = std::chrono::steady_clock::now();
  });
  request.mutable_options()->set_max_plans(5);
  v1::PlanPickResponse response;
  // A PlanPick's deadline in a run is minutes (plan_deadline 300 s): the budget (15 s) decides, not
  // the deadline (a 5 s deadline here made the test race the 4 s outage plus a reconnect under load).
  EXPECT_NO_THROW(response = client.PlanPick(request, std::chrono::seconds(60)));
  const auto answered = std::chrono::steady_clock::now();
  restart.join();
  ASSERT_TRUE(restarted) << "could not listen on " << address << " again";
  EXPECT_DOUBLE_EQ(response.total_seconds(), 5.0);
  EXPECT_EQ(service.calls, 2);
  EXPECT_GE(answered - start, kDown);
  // The restarted planner was found within the reconnect backoff (max 1 s) and some slack.
  EXPECT_LT(answered - back, std::chrono::milliseconds(2500));
  restarted->Shutdown();
}

TEST(PlannerRestartTest, ACallCutOffByAShutdownIsTriedAgainOnTheRestartedPlanner) {
  ScriptedService service;
  service.delay = std::chrono::milliseconds(1500);
  int port = 0;
  std::unique_ptr<grpc::Server> server = StartServer(service, "127.0.0.1:0", &port);
  ASSERT_TRUE(server);
  const std::string address = "127.0.0.1:" + std::to_string(port);
  GrpcPlannerClient client(address);
  std::unique_ptr<grpc::Server> restarted;
  std::thread restart([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // the call is on the planner
    server->Shutdown(std::chrono::system_clock::now());           // cut it off
    server.reset();
    std::this_thread::sleep_for(std::chrono::seconds(3));
    service.delay = std::chrono::milliseconds(0);
    int same_port = 0;
    restarted = StartServer(service, address, &same_port);
  });
  v1::PlanPickRequest request;
  request.mutable_options()->set_max_plans(2);
  v1::PlanPickResponse response;
  EXPECT_NO_THROW(response = client.PlanPick(request, std::chrono::seconds(10)));
  restart.join();
  ASSERT_TRUE(restarted);
  EXPECT_DOUBLE_EQ(response.total_seconds(), 2.0);
  EXPECT_GE(service.calls, 2);
  restarted->Shutdown();
}

// ---------------------------------------------------------------- TLS

/// Certificates made at test time by tests/test_certs.sh (openssl CLI): a CA, a server
/// certificate for localhost / 127.0.0.1 and a client certificate for mutual TLS.
class PlannerTlsTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    char pattern[] = "/tmp/tubepick-cell-tls-XXXXXX";
    ASSERT_NE(::mkdtemp(pattern), nullptr);
    dir_ = pattern;
    const std::string command =
        std::string("sh ") + TUBEPICK_SOURCE_DIR "/tests/test_certs.sh " + dir_ + " >/dev/null 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
  }
  static void TearDownTestSuite() { std::filesystem::remove_all(dir_); }

  static std::string Path(const std::string& name) { return dir_ + "/" + name; }
  static std::string Read(const std::string& name) {
    std::ifstream in(Path(name));
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  }

  /// The planner serving TLS; with `mutual`, it requires a client certificate signed by the CA.
  void Start(bool mutual) {
    grpc::SslServerCredentialsOptions ssl(mutual ? GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY
                                                 : GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE);
    if (mutual) ssl.pem_root_certs = Read("ca.pem");
    ssl.pem_key_cert_pairs.push_back({Read("server.key"), Read("server.pem")});
    server_ = StartServer(service_, "127.0.0.1:0", &port_, grpc::SslServerCredentials(ssl));
    ASSERT_TRUE(server_);
  }
  void TearDown() override {
    if (server_) server_->Shutdown();
  }

  std::string address() const { return "127.0.0.1:" + std::to_string(port_); }
  GrpcPlannerClientOptions Tls(bool client_cert) const {
    GrpcPlannerClientOptions options;
    options.tls_ca_file = Path("ca.pem");
    if (client_cert) {
      options.tls_cert_file = Path("client.pem");
      options.tls_key_file = Path("client.key");
    }
    options.unavailable_budget = std::chrono::milliseconds(1500);  // failures come quickly
    return options;
  }
  /// The PlannerError of one PlanPick, or "" when it succeeds.
  static std::string Failure(GrpcPlannerClient& client) {
    try {
      v1::PlanPickRequest request;
      request.mutable_options()->set_max_plans(4);
      return client.PlanPick(request, std::chrono::seconds(5)).total_seconds() == 4.0 ? "" : "wrong answer";
    } catch (const PlannerError& e) {
      EXPECT_EQ(e.code(), grpc::StatusCode::UNAVAILABLE) << e.what();
      return e.what();
    }
  }

  static std::string dir_;
  ScriptedService service_;
  int port_ = 0;
  std::unique_ptr<grpc::Server> server_;
};

std::string PlannerTlsTest::dir_;

TEST_F(PlannerTlsTest, ConnectsOverTlsToAPlannerItsCaSigned) {
  Start(false);
  GrpcPlannerClient client(address(), Tls(false));
  EXPECT_TRUE(client.tls());
  EXPECT_EQ(Failure(client), "");
  // The name checked against the certificate may be given (the certificate names localhost).
  GrpcPlannerClientOptions named = Tls(false);
  named.tls_server_name = "localhost";
  GrpcPlannerClient by_name(address(), named);
  EXPECT_EQ(Failure(by_name), "");
  // A plaintext client gets no answer, and is told why it may be.
  GrpcPlannerClientOptions plaintext;
  plaintext.unavailable_budget = std::chrono::milliseconds(1500);
  GrpcPlannerClient plain(address(), plaintext);
  EXPECT_FALSE(plain.tls());
  const std::string error = Failure(plain);
  EXPECT_NE(error.find("no connection to the planner at " + address()), std::string::npos) << error;
  EXPECT_NE(error.find("plaintext channel: a planner that serves TLS closes it (set tls_ca_file)"),
            std::string::npos)
      << error;
}

TEST_F(PlannerTlsTest, MutualTlsWorksWithTheClientCertificateAndFailsClearlyWithout) {
  Start(true);
  GrpcPlannerClient client(address(), Tls(true));
  EXPECT_EQ(Failure(client), "");
  EXPECT_EQ(service_.calls, 1);

  GrpcPlannerClient anonymous(address(), Tls(false));
  const std::string error = Failure(anonymous);
  EXPECT_NE(
      error.find("PlanPick failed after 1 try: UNAVAILABLE: no connection to the planner at " + address()),
      std::string::npos)
      << error;
  EXPECT_NE(error.find("TLS without a client certificate: a planner that requires mutual TLS "
                       "(tls.require_client_cert) refuses it (set tls_cert_file and tls_key_file)"),
            std::string::npos)
      << error;
  EXPECT_EQ(service_.calls, 1);  // never reached the service
}

TEST_F(PlannerTlsTest, InconsistentOrUnreadableTlsOptionsNameTheOptionAndTheFile) {
  const auto error = [](const GrpcPlannerClientOptions& options) -> std::string {
    try {
      GrpcPlannerClient client("127.0.0.1:1", options);
    } catch (const InvalidArgument& e) {
      return e.what();
    }
    return "";
  };
  GrpcPlannerClientOptions cert_only;
  cert_only.tls_ca_file = Path("ca.pem");
  cert_only.tls_cert_file = Path("client.pem");
  EXPECT_NE(error(cert_only).find("tls_cert_file '" + Path("client.pem") + "' is set without tls_key_file"),
            std::string::npos)
      << error(cert_only);
  GrpcPlannerClientOptions key_only;
  key_only.tls_key_file = Path("client.key");
  EXPECT_NE(error(key_only).find("tls_key_file '" + Path("client.key") + "' is set without tls_cert_file"),
            std::string::npos)
      << error(key_only);
  GrpcPlannerClientOptions name_only;
  name_only.tls_server_name = "planner.plant.local";
  EXPECT_NE(error(name_only).find("tls_server_name 'planner.plant.local' is set without tls_ca_file"),
            std::string::npos)
      << error(name_only);
  GrpcPlannerClientOptions missing;
  missing.tls_ca_file = Path("missing-ca.pem");
  EXPECT_NE(error(missing).find("tls_ca_file '" + Path("missing-ca.pem") + "': cannot read the file"),
            std::string::npos)
      << error(missing);
  GrpcPlannerClientOptions not_pem;
  not_pem.tls_ca_file = Path("not-pem.der");
  std::ofstream(Path("not-pem.der")) << "\x30\x82\x01\x0a";
  EXPECT_NE(error(not_pem).find("no PEM block"), std::string::npos) << error(not_pem);
  // The files the server takes, given consistently, build a client.
  GrpcPlannerClientOptions mutual = Tls(true);
  EXPECT_EQ(error(mutual), "");
}

}  // namespace
}  // namespace tubepick::cell

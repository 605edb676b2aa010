// The server's parts on their own: worker pool admission, Prometheus rendering, the metrics HTTP
// endpoint against bad clients, request-log formats.
#include <arpa/inet.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <future>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "core/common/errors.h"
#include "server/http_endpoints.h"
#include "server/metrics.h"
#include "server/request_log.h"
#include "server/upload_slots.h"
#include "server/upload_watchdog.h"
#include "server/worker_pool.h"
#include "tests/service_test_support.h"

namespace tubepick::server {
namespace {

using service_test::HttpExchange;
using service_test::MetricValue;
using ::testing::HasSubstr;

// --- WorkerPool ------------------------------------------------------------------------------------

TEST(WorkerPool, AdmitsWorkersPlusQueueThenRefuses) {
  WorkerPool pool(1, 2);
  std::promise<void> release;
  std::shared_future<void> released = release.get_future().share();
  std::atomic<int> ran{0};
  auto blocking = [&] {
    released.wait();
    ++ran;
  };
  ASSERT_EQ(pool.TrySubmit(blocking), WorkerPool::Admission::kAdmitted);
  ASSERT_TRUE(service_test::WaitFor([&] { return pool.load().busy == 1; }, std::chrono::seconds(5)));
  EXPECT_EQ(pool.TrySubmit(blocking), WorkerPool::Admission::kAdmitted);
  EXPECT_TRUE(pool.HasRoom());
  EXPECT_EQ(pool.TrySubmit(blocking), WorkerPool::Admission::kAdmitted);  // the third and last slot
  EXPECT_FALSE(pool.HasRoom());
  EXPECT_EQ(pool.TrySubmit(blocking), WorkerPool::Admission::kFull);
  const PoolLoad load = pool.load();
  EXPECT_EQ(load.workers, 1u);
  EXPECT_EQ(load.busy, 1u);
  EXPECT_EQ(load.queued, 2u);

  release.set_value();
  pool.Stop();  // runs what was queued, then joins
  EXPECT_EQ(ran.load(), 3);
  EXPECT_EQ(pool.TrySubmit(blocking), WorkerPool::Admission::kStopped);
  EXPECT_FALSE(pool.HasRoom());
}

// --- Upload admission and the idle watchdog --------------------------------------------------------

TEST(UploadSlots, AdmitsCapacityThenRefusesAndSlotsComeBack) {
  UploadSlots slots(2);
  std::optional<UploadSlots::Slot> a = slots.TryAcquire();
  std::optional<UploadSlots::Slot> b = slots.TryAcquire();
  ASSERT_TRUE(a && b);
  EXPECT_FALSE(slots.TryAcquire());
  EXPECT_EQ(slots.in_use(), 2u);
  a->Release();
  EXPECT_EQ(slots.in_use(), 1u);
  {
    std::optional<UploadSlots::Slot> c = slots.TryAcquire();
    ASSERT_TRUE(c);
    UploadSlots::Slot moved = std::move(*c);  // moving does not release twice
    EXPECT_EQ(slots.in_use(), 2u);
  }
  EXPECT_EQ(slots.in_use(), 1u);
}

TEST(UploadWatchdog, EndsAQuietUploadOnceAndLeavesActiveAndFinishedOnesAlone) {
  UploadWatchdog watchdog(std::chrono::milliseconds(200));
  std::atomic<int> quiet_ended{0}, active_ended{0}, done_ended{0};
  std::shared_ptr<UploadWatch> quiet = watchdog.Watch([&] { ++quiet_ended; });
  std::shared_ptr<UploadWatch> active = watchdog.Watch([&] { ++active_ended; });
  std::shared_ptr<UploadWatch> done = watchdog.Watch([&] { ++done_ended; });
  ASSERT_TRUE(done->StopWatching());  // complete upload: its job runs, however long
  const auto until = std::chrono::steady_clock::now() + std::chrono::milliseconds(800);
  while (std::chrono::steady_clock::now() < until) {
    EXPECT_TRUE(active->Touch());
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(quiet_ended.load(), 1);
  EXPECT_EQ(active_ended.load(), 0);
  EXPECT_EQ(done_ended.load(), 0);
  // The watchdog took the quiet call over: its reactor must neither read on nor finish it.
  EXPECT_FALSE(quiet->Touch());
  EXPECT_FALSE(quiet->ClaimFinish());
  EXPECT_TRUE(active->ClaimFinish());
  EXPECT_TRUE(done->ClaimFinish());
  EXPECT_FALSE(done->ClaimFinish());
}

TEST(WorkerPool, AJobThatThrowsDoesNotTakeTheWorkerOrTheProcessDown) {
  WorkerPool pool(1, 2);
  std::atomic<int> ran{0};
  ASSERT_EQ(pool.TrySubmit([] { throw std::runtime_error("bug"); }), WorkerPool::Admission::kAdmitted);
  ASSERT_EQ(pool.TrySubmit([] { throw 42; }), WorkerPool::Admission::kAdmitted);
  ASSERT_EQ(pool.TrySubmit([&] { ++ran; }), WorkerPool::Admission::kAdmitted);
  pool.Stop();  // runs what was queued, then joins
  EXPECT_EQ(ran.load(), 1);
  EXPECT_EQ(pool.escaped_exceptions(), 2u);
}

TEST(WorkerPool, RunsJobsInParallelOnItsWorkers) {
  WorkerPool pool(3, 0);
  std::atomic<int> inside{0}, peak{0};
  std::promise<void> go;
  std::shared_future<void> started = go.get_future().share();
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(pool.TrySubmit([&] {
      const int now = ++inside;
      int p = peak.load();
      while (now > p && !peak.compare_exchange_weak(p, now)) {
      }
      started.wait();
      --inside;
    }),
              WorkerPool::Admission::kAdmitted);
  }
  EXPECT_EQ(pool.TrySubmit([] {}), WorkerPool::Admission::kFull);  // queue capacity 0
  ASSERT_TRUE(service_test::WaitFor([&] { return peak.load() == 3; }, std::chrono::seconds(5)));
  go.set_value();
  pool.Stop();
  EXPECT_EQ(pool.load().busy, 0u);
}

// --- Metrics ---------------------------------------------------------------------------------------

TEST(Metrics, HistogramBucketsAreCumulative) {
  Metrics metrics;
  metrics.RecordCall("PlanPick", "OK", 0.005);
  metrics.RecordCall("PlanPick", "OK", 0.3);
  metrics.RecordCall("PlanPick", "INVALID_ARGUMENT", 0.002);
  metrics.RecordCall("PlanPick", "DEADLINE_EXCEEDED", 75.0);  // beyond the last bucket
  metrics.RecordRejected();
  PoolLoad load;
  load.workers = 4;
  load.busy = 2;
  load.queued = 3;
  const std::string text = metrics.RenderPrometheus(load, 1);
  auto value = [&](const std::string& series) { return MetricValue(text, series); };
  EXPECT_EQ(value("tubepick_rpc_requests_total{method=\"PlanPick\",code=\"OK\"}"), 2.0);
  EXPECT_EQ(value("tubepick_rpc_requests_total{method=\"PlanPick\",code=\"INVALID_ARGUMENT\"}"), 1.0);
  EXPECT_EQ(value("tubepick_rpc_requests_total{method=\"ModelTubes\",code=\"OK\"}"), 0.0);
  EXPECT_EQ(value("tubepick_rpc_duration_seconds_bucket{method=\"PlanPick\",le=\"0.01\"}"), 2.0);
  EXPECT_EQ(value("tubepick_rpc_duration_seconds_bucket{method=\"PlanPick\",le=\"0.25\"}"), 2.0);
  EXPECT_EQ(value("tubepick_rpc_duration_seconds_bucket{method=\"PlanPick\",le=\"0.5\"}"), 3.0);
  EXPECT_EQ(value("tubepick_rpc_duration_seconds_bucket{method=\"PlanPick\",le=\"60\"}"), 3.0);
  EXPECT_EQ(value("tubepick_rpc_duration_seconds_bucket{method=\"PlanPick\",le=\"+Inf\"}"), 4.0);
  EXPECT_EQ(value("tubepick_rpc_duration_seconds_count{method=\"PlanPick\"}"), 4.0);
  EXPECT_NEAR(value("tubepick_rpc_duration_seconds_sum{method=\"PlanPick\"}").value_or(0.0), 75.307, 1e-9);
  EXPECT_EQ(value("tubepick_rejected_total"), 1.0);
  EXPECT_EQ(value("tubepick_queue_depth"), 3.0);
  EXPECT_EQ(value("tubepick_workers_busy"), 2.0);
  EXPECT_EQ(value("tubepick_workers"), 4.0);
  EXPECT_EQ(value("tubepick_stream_uploads"), 1.0);
  // Every sample belongs to a metric with HELP and TYPE lines.
  std::istringstream lines(text);
  std::set<std::string> typed;
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("# TYPE ", 0) == 0) typed.insert(line.substr(7, line.find(' ', 7) - 7));
    if (line.empty() || line[0] == '#') continue;
    std::string name = line.substr(0, line.find_first_of("{ "));
    for (const char* suffix : {"_bucket", "_sum", "_count"}) {
      if (name.size() > std::strlen(suffix) && name.ends_with(suffix) &&
          typed.count(name.substr(0, name.size() - std::strlen(suffix))))
        name = name.substr(0, name.size() - std::strlen(suffix));
    }
    EXPECT_TRUE(typed.count(name)) << line;
  }
}

TEST(Metrics, ProcessMemoryComesFromProc) {
  const std::optional<ProcessMemory> memory = ReadProcessMemory();
  ASSERT_TRUE(memory);
  EXPECT_GT(memory->resident_bytes, 1u << 20);
  EXPECT_GE(memory->peak_resident_bytes, memory->resident_bytes);
}

// --- HTTP endpoints (/metrics, /healthz, /debug/calls) -----------------------------------------------

HttpEndpointsOptions MetricsOnly(std::function<bool()> serving = {}) {
  HttpEndpointsOptions o;
  o.render_metrics = [] { return std::string("up 1\n"); };
  o.serving = std::move(serving);
  o.io_timeout = std::chrono::milliseconds(300);
  return o;
}

bool StartsWith(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }

TEST(HttpEndpoints, RoutesAndRejects) {
  HttpEndpoints http("127.0.0.1:0", MetricsOnly());
  ASSERT_GT(http.port(), 0);
  const std::string ok = HttpExchange(http.port(), "GET /metrics HTTP/1.1\r\nHost: a\r\n\r\n");
  EXPECT_TRUE(StartsWith(ok, "HTTP/1.1 200 OK\r\n")) << ok;
  EXPECT_THAT(ok, HasSubstr("Content-Type: text/plain; version=0.0.4; charset=utf-8\r\n"));
  EXPECT_THAT(ok, HasSubstr("Content-Length: 5\r\n"));
  EXPECT_THAT(ok, HasSubstr("\r\n\r\nup 1\n"));
  EXPECT_TRUE(
      StartsWith(HttpExchange(http.port(), "GET /metrics?name[]=x HTTP/1.0\r\n\r\n"), "HTTP/1.1 200 "));
  const std::string head = HttpExchange(http.port(), "HEAD /metrics HTTP/1.1\r\nHost: a\r\n\r\n");
  EXPECT_TRUE(StartsWith(head, "HTTP/1.1 200 ")) << head;
  EXPECT_THAT(head, ::testing::Not(HasSubstr("up 1")));
  EXPECT_TRUE(StartsWith(HttpExchange(http.port(), "GET /metricsx HTTP/1.1\r\n\r\n"), "HTTP/1.1 404 "));
  EXPECT_TRUE(StartsWith(HttpExchange(http.port(), "GET / HTTP/1.1\r\n\r\n"), "HTTP/1.1 404 "));
  const std::string del = HttpExchange(http.port(), "DELETE /metrics HTTP/1.1\r\n\r\n");
  EXPECT_TRUE(StartsWith(del, "HTTP/1.1 405 ")) << del;
  EXPECT_THAT(del, HasSubstr("Allow: GET, HEAD\r\n"));
  // Without the debug store the viewer paths say how to turn it on.
  const std::string debug = HttpExchange(http.port(), "GET /debug/calls HTTP/1.1\r\n\r\n");
  EXPECT_TRUE(StartsWith(debug, "HTTP/1.1 404 ")) << debug;
  EXPECT_THAT(debug, HasSubstr("debug.keep_last is 0"));
  // Without a serving state there is no probe to answer.
  EXPECT_TRUE(StartsWith(HttpExchange(http.port(), "GET /healthz HTTP/1.1\r\n\r\n"), "HTTP/1.1 404 "));
}

TEST(HttpEndpoints, HealthProbeFollowsTheServingState) {
  std::atomic<bool> serving{true};
  HttpEndpoints http("127.0.0.1:0", MetricsOnly([&serving] { return serving.load(); }));
  std::string r = HttpExchange(http.port(), "GET /healthz HTTP/1.1\r\n\r\n");
  EXPECT_TRUE(StartsWith(r, "HTTP/1.1 200 ")) << r;
  EXPECT_THAT(r, HasSubstr("\r\n\r\nSERVING\n"));
  EXPECT_TRUE(
      StartsWith(HttpExchange(http.port(), "HEAD /healthz?probe=1 HTTP/1.0\r\n\r\n"), "HTTP/1.1 200 "));
  serving = false;
  r = HttpExchange(http.port(), "GET /healthz HTTP/1.1\r\n\r\n");
  EXPECT_TRUE(StartsWith(r, "HTTP/1.1 503 ")) << r;
  EXPECT_THAT(r, HasSubstr("\r\n\r\nNOT_SERVING\n"));
  EXPECT_TRUE(StartsWith(HttpExchange(http.port(), "POST /healthz HTTP/1.1\r\n\r\n"), "HTTP/1.1 405 "));
}

TEST(HttpEndpoints, SlowAndBrokenClientsDoNotStopTheEndpoint) {
  HttpEndpointsOptions options = MetricsOnly();
  options.io_timeout = std::chrono::milliseconds(2000);
  HttpEndpoints http("127.0.0.1:0", options);
  ASSERT_GT(http.port(), 0);
  // A client that sends half a request and waits holds its connection until the I/O budget ends it;
  // meanwhile the endpoint answers others.
  auto slow = std::async(std::launch::async, [&] {
    const auto start = std::chrono::steady_clock::now();
    const std::string answer = HttpExchange(http.port(), "GET /metr");
    return std::make_pair(answer, std::chrono::steady_clock::now() - start);
  });
  EXPECT_TRUE(StartsWith(HttpExchange(http.port(), "GET /metrics HTTP/1.1\r\n\r\n"), "HTTP/1.1 200 "));
  EXPECT_EQ(slow.wait_for(std::chrono::seconds(0)), std::future_status::timeout)
      << "answered before the slow one";
  const auto [answer, took] = slow.get();
  EXPECT_THAT(answer, ::testing::Not(HasSubstr("up 1"))) << answer;
  EXPECT_LT(took, std::chrono::seconds(10));
  // Oversized heads, connect-and-close, binary junk.
  EXPECT_TRUE(StartsWith(HttpExchange(http.port(), "GET /" + std::string(9000, 'x') + " HTTP/1.1\r\n\r\n"),
                         "HTTP/1.1 414 "));
  {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(http.port()));
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    ASSERT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    ::close(fd);
  }
  EXPECT_TRUE(StartsWith(HttpExchange(http.port(), std::string("\0\1\2\3\r\n\r\n", 8)), "HTTP/1.1 400 "));
  EXPECT_TRUE(StartsWith(HttpExchange(http.port(), "GET /metrics HTTP/1.1\r\n\r\n"), "HTTP/1.1 200 OK\r\n"));
  http.Stop();
  http.Stop();  // idempotent
}

TEST(HttpEndpoints, SplitsHostAndPort) {
  EXPECT_EQ(SplitHostPort("0.0.0.0:9464", "a"), (std::pair<std::string, int>("0.0.0.0", 9464)));
  EXPECT_EQ(SplitHostPort("[::]:0", "a"), (std::pair<std::string, int>("::", 0)));
  EXPECT_EQ(SplitHostPort("localhost:80", "a"), (std::pair<std::string, int>("localhost", 80)));
  EXPECT_THROW(SplitHostPort("localhost", "a"), InvalidArgument);
  EXPECT_THROW(SplitHostPort("localhost:", "a"), InvalidArgument);
  EXPECT_THROW(SplitHostPort("localhost:70000", "a"), InvalidArgument);
  EXPECT_THROW(SplitHostPort("localhost:8o", "a"), InvalidArgument);
  EXPECT_THROW(HttpEndpoints("127.0.0.1:99999", MetricsOnly()), InvalidArgument);
  HttpEndpoints first("127.0.0.1:0", MetricsOnly());
  EXPECT_THROW(HttpEndpoints("127.0.0.1:" + std::to_string(first.port()), MetricsOnly()), std::runtime_error);
}

// --- request log -----------------------------------------------------------------------------------

CallRecord SampleRecord() {
  CallRecord r;
  r.rpc = "PlanPick";
  r.request_id = "abc123";
  r.peer = "ipv4:127.0.0.1:5000";
  r.code = "INVALID_ARGUMENT";
  r.message = "cloud.xyz: 13 bytes is not a \"multiple\" of 12\nsecond line";
  r.points = 1234;
  r.tubes = 0;
  r.plans = 0;
  r.queue_ms = 1.25;
  r.run_ms = 20.0;
  r.total_ms = 21.5;
  r.stop_ms = 4.0;
  return r;
}

TEST(RequestLog, TextLineHasEveryField) {
  const std::string line = FormatCallText(SampleRecord());
  EXPECT_EQ(
      line,
      "call rpc=PlanPick id=abc123 peer=ipv4:127.0.0.1:5000 code=INVALID_ARGUMENT points=1234 tubes=0 "
      "plans=0 queue_ms=1.2 run_ms=20.0 total_ms=21.5 stop_ms=4.0 message=\"cloud.xyz: 13 bytes is not a "
      "\\\"multiple\\\" of 12\\nsecond line\"");
}

TEST(RequestLog, JsonLineIsValidJsonWithEveryField) {
  const nlohmann::json j = nlohmann::json::parse(FormatCallJson(SampleRecord()));
  EXPECT_EQ(j["event"], "call");
  EXPECT_EQ(j["rpc"], "PlanPick");
  EXPECT_EQ(j["request_id"], "abc123");
  EXPECT_EQ(j["peer"], "ipv4:127.0.0.1:5000");
  EXPECT_EQ(j["code"], "INVALID_ARGUMENT");
  EXPECT_EQ(j["points"], 1234);
  EXPECT_EQ(j["tubes"], 0);
  EXPECT_EQ(j["plans"], 0);
  EXPECT_DOUBLE_EQ(j["run_ms"].get<double>(), 20.0);
  EXPECT_DOUBLE_EQ(j["stop_ms"].get<double>(), 4.0);
  EXPECT_EQ(j["message"], "cloud.xyz: 13 bytes is not a \"multiple\" of 12\nsecond line");
  CallRecord ok = SampleRecord();
  ok.message.clear();
  ok.stop_ms.reset();
  const nlohmann::json k = nlohmann::json::parse(FormatCallJson(ok));
  EXPECT_FALSE(k.contains("message"));
  EXPECT_FALSE(k.contains("stop_ms"));
}

TEST(RequestLog, AnAnswersWarningsAreInItsLine) {
  CallRecord r = SampleRecord();
  r.code = "OK";
  r.message.clear();
  r.stop_ms.reset();
  r.warnings = {"tube_length_shorter_than_scan", "other"};
  EXPECT_THAT(FormatCallText(r),
              ::testing::EndsWith(" total_ms=21.5 warnings=tube_length_shorter_than_scan,other"));
  const nlohmann::json j = nlohmann::json::parse(FormatCallJson(r));
  EXPECT_EQ(j["warnings"], nlohmann::json({"tube_length_shorter_than_scan", "other"}));
  EXPECT_FALSE(nlohmann::json::parse(FormatCallJson(SampleRecord())).contains("warnings"));
}

TEST(RequestLog, JsonFormatterWritesOneObjectPerLine) {
  std::ostringstream out;
  auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(out);
  spdlog::logger logger("json-test", sink);
  logger.set_formatter(std::make_unique<JsonLineFormatter>());
  logger.info("listening on {}:{}", "127.0.0.1", 50051);
  logger.warn("a \"quoted\"\tmessage");
  logger.info("{}", FormatCallJson(SampleRecord()));
  std::istringstream lines(out.str());
  std::vector<nlohmann::json> parsed;
  for (std::string line; std::getline(lines, line);) parsed.push_back(nlohmann::json::parse(line));
  ASSERT_EQ(parsed.size(), 3u);
  EXPECT_EQ(parsed[0]["level"], "info");
  EXPECT_EQ(parsed[0]["msg"], "listening on 127.0.0.1:50051");
  EXPECT_THAT(parsed[0]["time"].get<std::string>(), ::testing::MatchesRegex("....-..-..T..:..:..\\....Z"));
  EXPECT_EQ(parsed[1]["level"], "warning");
  EXPECT_EQ(parsed[1]["msg"], "a \"quoted\"\tmessage");
  // A call record's fields become top-level keys.
  EXPECT_EQ(parsed[2]["rpc"], "PlanPick");
  EXPECT_EQ(parsed[2]["request_id"], "abc123");
  EXPECT_FALSE(parsed[2].contains("msg"));
}

TEST(RequestLog, ConfigureLoggingRejectsUnknownNames) {
  EXPECT_THROW(ConfigureLogging("loud", "text"), InvalidArgument);
  EXPECT_THROW(ConfigureLogging("info", "xml"), InvalidArgument);
}

}  // namespace
}  // namespace tubepick::server

// The real tubepick-server binary as a child process: flags over the config file, the
// "listening on HOST:PORT" line, JSON logs with request ids, and SIGTERM ⇒ graceful exit 0.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <regex>
#include <thread>

#include "server/server_config.h"
#include "tests/service_test_support.h"

extern char** environ;

namespace tubepick::service_test {
namespace {

using ::testing::HasSubstr;

/// tubepick-server with stdout and stderr captured; killed if still running at destruction.
class ServerProcess {
 public:
  /// `env`: NAME=VALUE entries added to (or replacing) this process's environment.
  explicit ServerProcess(std::vector<std::string> args, const std::vector<std::string>& env = {}) {
    args.insert(args.begin(), TUBEPICK_SERVER_BIN);
    std::vector<std::string> environment = env;
    for (char** e = environ; *e != nullptr; ++e) {
      const std::string entry = *e;
      const std::string name = entry.substr(0, entry.find('='));
      if (std::none_of(env.begin(), env.end(),
                       [&](const std::string& x) { return x.rfind(name + "=", 0) == 0; }))
        environment.push_back(entry);
    }
    std::vector<char*> envp;
    for (std::string& e : environment) envp.push_back(e.data());
    envp.push_back(nullptr);
    int fds[2];
    if (::pipe(fds) != 0) throw std::runtime_error("pipe");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDERR_FILENO);
    posix_spawn_file_actions_addclose(&actions, fds[0]);
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int rc = posix_spawn(&pid_, argv[0], &actions, nullptr, argv.data(), envp.data());
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[1]);
    if (rc != 0) throw std::runtime_error("posix_spawn failed");
    reader_ = std::thread([this, fd = fds[0]] {
      char buffer[4096];
      for (;;) {
        const ssize_t n = ::read(fd, buffer, sizeof buffer);
        if (n <= 0) break;
        std::lock_guard lock(mu_);
        output_.append(buffer, static_cast<std::size_t>(n));
      }
      ::close(fd);
    });
  }
  ~ServerProcess() {
    if (!exit_status_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    if (reader_.joinable()) reader_.join();
  }
  /// Everything the process wrote, once it has exited and closed its end of the pipe.
  std::string FinalOutput() {
    if (reader_.joinable()) reader_.join();
    return output();
  }

  std::string output() const {
    std::lock_guard lock(mu_);
    return output_;
  }
  /// The first capture of `pattern` in the output, waiting up to `timeout` for it.
  std::optional<std::string> WaitForMatch(const std::regex& pattern,
                                          std::chrono::milliseconds timeout) const {
    std::optional<std::string> found;
    WaitFor(
        [&] {
          std::smatch m;
          const std::string text = output();
          if (std::regex_search(text, m, pattern)) found = m[1].str();
          return found.has_value();
        },
        timeout);
    return found;
  }
  void Signal(int signal) { ::kill(pid_, signal); }
  /// Threads of the process now (/proc/PID/task), 0 when it is gone.
  int ThreadCount() const {
    std::error_code error;
    int n = 0;
    for (std::filesystem::directory_iterator it("/proc/" + std::to_string(pid_) + "/task", error), end;
         !error && it != end; it.increment(error))
      ++n;
    return n;
  }
  /// The exit status once the process exited within `timeout`.
  std::optional<int> WaitExit(std::chrono::milliseconds timeout) {
    WaitFor(
        [&] {
          int status = 0;
          if (::waitpid(pid_, &status, WNOHANG) == pid_) exit_status_ = status;
          return exit_status_.has_value();
        },
        timeout);
    return exit_status_;
  }

 private:
  pid_t pid_ = -1;
  std::thread reader_;
  mutable std::mutex mu_;
  std::string output_;
  std::optional<int> exit_status_;
};

const std::regex kListening(R"(listening on 127\.0\.0\.1:([0-9]+))");
const std::regex kMetrics(R"(metrics on http://127\.0\.0\.1:([0-9]+)/metrics)");

TEST(ServiceProcess, SigtermFinishesInFlightCallsAndExitsZero) {
  char pattern[] = "/tmp/tubepick-server-XXXXXX";
  ASSERT_NE(::mkdtemp(pattern), nullptr);
  const std::string dir = pattern;
  {
    std::ofstream config(dir + "/server.yaml");
    // --address and --workers on the command line override the file.
    config << "server:\n  address: \"127.0.0.1:1\"\n  workers: 3\n  shutdown_grace: 5.0\n"
              "  log_format: json\n";
  }
  (void)BusyBinCloud();
  ServerProcess process({"--config", dir + "/server.yaml", "--address", "127.0.0.1:0", "--metrics-address",
                         "127.0.0.1:0", "--workers", "1"});
  const std::optional<std::string> port = process.WaitForMatch(kListening, std::chrono::seconds(20));
  ASSERT_TRUE(port) << process.output();
  const std::optional<std::string> metrics_port = process.WaitForMatch(kMetrics, std::chrono::seconds(5));
  ASSERT_TRUE(metrics_port) << process.output();

  auto channel = grpc::CreateChannel("127.0.0.1:" + *port, grpc::InsecureChannelCredentials());
  auto stub = v1::PickPlannerService::NewStub(channel);
  {
    grpc::ClientContext context;
    context.AddMetadata("x-request-id", "process-test-1");
    SetTimeout(&context, std::chrono::seconds(30));
    v1::ModelTubesResponse response;
    const grpc::Status status = stub->ModelTubes(&context, ModelRequest(ThreeTubeCloud()), &response);
    ASSERT_TRUE(status.ok()) << status.error_message();
    EXPECT_EQ(response.tubes_size(), 3);
  }
  // A longer call in flight when SIGTERM arrives still completes within the 5 s grace. (First wait
  // until the worker of the call above counts itself free, so "busy" below means the new call.)
  const int metrics = std::stoi(*metrics_port);
  auto busy = [&] { return MetricValue(ScrapeMetrics(metrics), "tubepick_workers_busy"); };
  ASSERT_TRUE(WaitFor([&] { return busy() == 0.0; }, std::chrono::seconds(10)));
#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)
  {
    // tubepick-server allocates with jemalloc (not in sanitizer trees) and exports its account: live bytes
    // within the allocator's resident pages, and those within the process RSS.
    const std::string text = ScrapeMetrics(metrics);
    const std::optional<double> allocated = MetricValue(text, "tubepick_allocator_allocated_bytes");
    const std::optional<double> resident = MetricValue(text, "tubepick_allocator_resident_bytes");
    const std::optional<double> rss = MetricValue(text, "process_resident_memory_bytes");
    ASSERT_TRUE(allocated && resident && rss) << text;
    EXPECT_GT(*allocated, 1e6);
    EXPECT_GE(*resident, *allocated);
    EXPECT_LE(*resident, *rss);
  }
#endif
  auto in_flight = std::async(std::launch::async, [&] {
    grpc::ClientContext context;
    SetTimeout(&context, std::chrono::seconds(60));
    v1::ModelTubesRequest request = ModelRequest(BusyBinCloud());
    request.mutable_options()->set_profile("thesis");
    v1::ModelTubesResponse response;
    grpc::Status status = stub->ModelTubes(&context, request, &response);
    return std::pair(status, response.tubes_size());
  });
  ASSERT_TRUE(WaitFor([&] { return busy() == 1.0; }, std::chrono::seconds(20)));
  const auto signalled = std::chrono::steady_clock::now();
  process.Signal(SIGTERM);
  const auto [status, tubes] = in_flight.get();
  EXPECT_TRUE(status.ok()) << status.error_message() << "\n" << process.output();
  EXPECT_GT(tubes, 3);
  const std::optional<int> exit_status = process.WaitExit(std::chrono::seconds(10));
  ASSERT_TRUE(exit_status) << "still running 10 s after SIGTERM\n" << process.output();
  std::printf(
      "[ measure  ] SIGTERM to exit: %.0f ms (one call in flight)\n",
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - signalled).count());
  ASSERT_TRUE(WIFEXITED(*exit_status));
  EXPECT_EQ(WEXITSTATUS(*exit_status), 0);

  // Every line is one JSON object; the call lines carry the request id and the numbers.
  const std::string output = process.FinalOutput();
  EXPECT_THAT(output, HasSubstr("received SIGTERM"));
  std::istringstream lines(output);
  int call_lines = 0;
  bool saw_request_id = false;
  for (std::string line; std::getline(lines, line);) {
    if (line.empty()) continue;
    nlohmann::json j;
    ASSERT_NO_THROW(j = nlohmann::json::parse(line)) << line;
    ASSERT_TRUE(j.contains("time") && j.contains("level")) << line;
    if (j.value("event", "") != "call") continue;
    ++call_lines;
    EXPECT_EQ(j["rpc"], "ModelTubes");
    EXPECT_EQ(j["code"], "OK");
    EXPECT_TRUE(j.contains("queue_ms") && j.contains("run_ms") && j.contains("peer"));
    if (j["request_id"] == "process-test-1") {
      saw_request_id = true;
      EXPECT_EQ(j["tubes"], 3);
      EXPECT_EQ(j["points"], ThreeTubeCloud().size() / 12);
    }
  }
  EXPECT_EQ(call_lines, 2);
  EXPECT_TRUE(saw_request_id);
  std::filesystem::remove_all(dir);
}

// One thread budget: with 4 workers on a host whose OMP_NUM_THREADS says 16, four concurrent
// PlanPicks (modeling in OpenMP, simulation on Bullet worlds) run on at most workers × threads per
// call threads, plus the handful gRPC and the server keep. Without the budget each worker's OpenMP
// regions would start 15 more threads.
TEST(ServiceProcess, ThreadsStayWithinWorkersTimesThreadsPerCallWhateverOmpNumThreadsSays) {
  (void)BusyBinCloud();
  ServerProcess process({"--address", "127.0.0.1:0", "--metrics-address", "127.0.0.1:0", "--workers", "4"},
                        {"OMP_NUM_THREADS=16"});
  const std::optional<std::string> port = process.WaitForMatch(kListening, std::chrono::seconds(20));
  ASSERT_TRUE(port) << process.output();
  const std::optional<std::string> metrics_port = process.WaitForMatch(kMetrics, std::chrono::seconds(5));
  ASSERT_TRUE(metrics_port) << process.output();
  const std::optional<std::string> per_call =
      process.WaitForMatch(std::regex(R"(4 workers x ([0-9]+) threads per call)"), std::chrono::seconds(5));
  ASSERT_TRUE(per_call) << process.output();
  const int threads_per_call = std::stoi(*per_call);

  auto channel = grpc::CreateChannel("127.0.0.1:" + *port, grpc::InsecureChannelCredentials());
  auto stub = v1::PickPlannerService::NewStub(channel);
  {  // one call first, so that gRPC's own threads are up before the idle count
    grpc::ClientContext context;
    SetTimeout(&context, std::chrono::seconds(30));
    v1::ModelTubesResponse response;
    ASSERT_TRUE(stub->ModelTubes(&context, ModelRequest(ThreeTubeCloud()), &response).ok());
  }
  const int idle = process.ThreadCount();
  std::atomic<bool> done{false};
  std::atomic<int> peak{0};
  std::atomic<double> busiest{0};
  std::thread sampler([&] {
    const int metrics = std::stoi(*metrics_port);
    while (!done) {
      peak = std::max(peak.load(), process.ThreadCount());
      busiest =
          std::max(busiest.load(), MetricValue(ScrapeMetrics(metrics), "tubepick_workers_busy").value_or(0));
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
  });
  std::vector<std::future<grpc::Status>> calls;
  for (int i = 0; i < 4; ++i) {
    calls.push_back(std::async(std::launch::async, [&] {
      grpc::ClientContext context;
      SetTimeout(&context, std::chrono::seconds(240));
      v1::PlanPickResponse response;
      return stub->PlanPick(&context, PlanRequest(BusyBinCloud(), /*simulate=*/true), &response);
    }));
  }
  for (auto& call : calls) {
    const grpc::Status status = call.get();
    EXPECT_TRUE(status.ok()) << status.error_message();
  }
  done = true;
  sampler.join();
  EXPECT_EQ(busiest.load(), 4.0);  // full load: every worker ran a call at once
  // The workers exist before the idle count; each call may add threads_per_call - 1 for OpenMP and
  // as many for Bullet; 4 more for gRPC's pollers and timers.
  const int bound = idle + 4 * 2 * (threads_per_call - 1) + 4;
  EXPECT_LE(peak.load(), bound) << "idle " << idle << ", threads per call " << threads_per_call;
  std::printf(
      "[ measure  ] threads: %d idle, %d peak under 4 concurrent PlanPicks (OMP_NUM_THREADS=16, "
      "%d threads per call)\n",
      idle, peak.load(), threads_per_call);
}

TEST(ServiceProcess, PrintConfigShowsTheEmbeddedDefault) {
  ServerProcess process({"--print-config"});
  const std::optional<int> exit_status = process.WaitExit(std::chrono::seconds(10));
  ASSERT_TRUE(exit_status);
  EXPECT_EQ(WEXITSTATUS(*exit_status), 0);
  EXPECT_EQ(process.FinalOutput(), std::string(server::EmbeddedServerConfigYaml()));
}

TEST(ServiceProcess, ABadFlagValueExitsWithAConfigurationError) {
  ServerProcess process({"--address", "no-port-here", "--metrics-address", ""});
  const std::optional<int> exit_status = process.WaitExit(std::chrono::seconds(10));
  ASSERT_TRUE(exit_status);
  EXPECT_EQ(WEXITSTATUS(*exit_status), 2);
  EXPECT_THAT(process.FinalOutput(), HasSubstr("address"));
}

}  // namespace
}  // namespace tubepick::service_test

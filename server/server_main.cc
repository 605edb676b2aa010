// tubepick-server: the PickPlannerService as a long-running process.
//
//   tubepick-server                      # embedded default config (tubepick-server --print-config)
//   tubepick-server --config cell.yaml --address 0.0.0.0:50051 --workers 2
//
// Logs "listening on HOST:PORT" with the bound port (port 0 = any free port); scripts parse it.
// SIGTERM / SIGINT: health turns NOT_SERVING, in-flight calls get server.shutdown_grace seconds,
// then are cancelled; exit status 0.
#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <malloc.h>
#include <pthread.h>
#include <CLI/CLI.hpp>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <optional>
#include <string>
#include <thread>

#include "server/planner_server.h"
#include "server/request_log.h"
#include "server/server_config.h"

namespace {

struct Flags {
  std::string config_file;
  std::optional<std::string> address;
  std::optional<std::string> metrics_address;
  std::optional<std::uint32_t> workers;
  std::optional<std::string> log_level;
  std::optional<std::string> log_format;
  bool print_config = false;
};

tubepick::server::ServerConfig LoadConfig(const Flags& flags) {
  tubepick::server::ServerConfig config =
      flags.config_file.empty()
          ? tubepick::server::ParseServerConfig(std::string(tubepick::server::EmbeddedServerConfigYaml()))
          : tubepick::server::LoadServerConfig(flags.config_file);
  if (flags.address) config.address = *flags.address;
  if (flags.metrics_address) config.metrics_address = *flags.metrics_address;
  if (flags.workers) config.workers = *flags.workers;
  if (flags.log_level) config.log_level = *flags.log_level;
  if (flags.log_format) config.log_format = *flags.log_format;
  config.Validate();
  return config;
}

int Serve(const tubepick::server::ServerConfig& config) {
  // Block the shutdown signals in every thread (gRPC's and ours inherit this mask) and take them
  // synchronously in one thread with sigwait: no work in a signal handler.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  tubepick::server::PlannerServer server(config);
  server.Start();
  const auto grace = std::chrono::milliseconds(static_cast<std::int64_t>(config.shutdown_grace * 1000.0));
  std::thread signal_thread([&] {
    int signal = 0;
    if (sigwait(&signals, &signal) != 0) signal = SIGTERM;
    spdlog::info("received {}, shutting down (grace {:.1f} s)", signal == SIGINT ? "SIGINT" : "SIGTERM",
                 config.shutdown_grace);
    server.Shutdown(grace);
  });
  server.Wait();
  signal_thread.join();
  spdlog::info("bye");
  return 0;
}

}  // namespace

#ifdef TUBEPICK_WITH_JEMALLOC
// jemalloc's options (MALLOC_CONF overrides them). A call's big buffers — the request's cloud bytes,
// 27.6 MB at 2.3 M points, above all — stay in the normal arenas, where the next call reuses their pages
// and the background thread purges what has been unused for ~10 s (dirty and muzzy decay); jemalloc's
// default puts blocks of 8 MiB or more in an arena that purges them at once, so every call would fault
// them in afresh (about 10 µs a page on a paravirtual VM: half the call). The CI soak holds RSS flat.
extern "C" {
const char* malloc_conf = "oversize_threshold:0,background_thread:true";
}
#endif

int main(int argc, char** argv) {
#ifndef TUBEPICK_WITH_JEMALLOC
  // glibc (sanitizer builds): flat memory under load. glibc raises its mmap threshold to the size of
  // the largest block freed (a 28 MB cloud), after which cloud-sized buffers come from the heap arenas
  // and fragment them: a 10-minute soak at concurrency 4 crept +18 % in RSS. A fixed threshold (which
  // also disables the dynamic one) keeps every buffer of 1 MiB or more in its own mapping, returned to
  // the kernel on free; the workers trim the arenas after each call (WorkerPool).
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
#endif
  CLI::App app{"tubepick-server: the gRPC bin-picking planning service (tubepick.v1.PickPlannerService)"};
  Flags flags;
  app.add_option("--config", flags.config_file,
                 "Server YAML (default: the embedded config, see --print-config)")
      ->check(CLI::ExistingFile);
  app.add_option("--address", flags.address, "gRPC listen address HOST:PORT (port 0 = any free port)");
  app.add_option("--metrics-address", flags.metrics_address,
                 "Prometheus metrics HTTP address HOST:PORT; \"\" = off");
  app.add_option("--workers", flags.workers, "Planning worker threads (0 = the cores the process may use)");
  app.add_option("--log-level", flags.log_level, "trace, debug, info, warn, error, critical, off");
  app.add_option("--log-format", flags.log_format, "text or json (one JSON object per line)");
  app.add_flag("--print-config", flags.print_config,
               "Print the embedded default configuration YAML and exit");
  CLI11_PARSE(app, argc, argv);

  if (flags.print_config) {
    fmt::print("{}", tubepick::server::EmbeddedServerConfigYaml());
    return 0;
  }
  tubepick::server::ServerConfig config;
  try {
    config = LoadConfig(flags);
    tubepick::server::ConfigureLogging(config.log_level, config.log_format);
  } catch (const std::exception& e) {
    fmt::print(stderr, "tubepick-server: configuration error: {}\n", e.what());
    return 2;
  }
  try {
    return Serve(config);
  } catch (const std::exception& e) {
    spdlog::critical("tubepick-server: {}", e.what());
    return 1;
  }
}

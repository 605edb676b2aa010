#include "server/planner_server.h"

#include <fmt/format.h>
#include <grpcpp/ext/proto_server_reflection_plugin.h>
#include <grpcpp/grpcpp.h>
#include <grpcpp/health_check_service_interface.h>
#include <grpcpp/impl/server_builder_option.h>
#include <spdlog/spdlog.h>

#include <atomic>
#include <climits>
#include <cmath>
#include <condition_variable>
#include <fstream>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "core/common/thread_budget.h"
#include "grpc/health/v1/health.pb.h"
#include "server/debug_calls.h"
#include "server/http_endpoints.h"
#include "server/metrics.h"
#include "server/planner_service.h"
#include "server/worker_pool.h"

namespace tubepick::server {
namespace {

/// Takes gRPC's reflection plugin off one server (`server.reflection: false`). The plugin is
/// registered process-wide (InitProtoReflectionServerBuilderPlugin), so the switch is per builder.
class WithoutReflection final : public grpc::ServerBuilderOption {
 public:
  void UpdateArguments(grpc::ChannelArguments* /*args*/) override {}
  void UpdatePlugins(std::vector<std::unique_ptr<grpc::ServerBuilderPlugin>>* plugins) override {
    std::erase_if(*plugins, [](const std::unique_ptr<grpc::ServerBuilderPlugin>& plugin) {
      return plugin->name() == "proto_server_reflection";
    });
  }
};

constexpr const char* kServiceName = "tubepick.v1.PickPlannerService";

std::string ReadPem(const std::string& path, const char* what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("tls.{}: cannot read '{}'", what, path));
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::shared_ptr<grpc::ServerCredentials> MakeCredentials(const TlsConfig& tls) {
  if (!tls.enabled()) return grpc::InsecureServerCredentials();
  grpc_ssl_client_certificate_request_type request = GRPC_SSL_DONT_REQUEST_CLIENT_CERTIFICATE;
  if (tls.require_client_cert) {
    request = GRPC_SSL_REQUEST_AND_REQUIRE_CLIENT_CERTIFICATE_AND_VERIFY;
  } else if (!tls.client_ca_file.empty()) {
    request = GRPC_SSL_REQUEST_CLIENT_CERTIFICATE_AND_VERIFY;
  }
  grpc::SslServerCredentialsOptions options(request);
  if (!tls.client_ca_file.empty()) options.pem_root_certs = ReadPem(tls.client_ca_file, "client_ca_file");
  options.pem_key_cert_pairs.push_back(
      {ReadPem(tls.key_file, "key_file"), ReadPem(tls.cert_file, "cert_file")});
  return grpc::SslServerCredentials(options);
}

// "::" → "[::]", so that "HOST:PORT" stays parseable.
std::string HostForLog(const std::string& host) {
  return host.find(':') == std::string::npos ? host : "[" + host + "]";
}

int ClampToInt(std::uint64_t v) {
  return v > static_cast<std::uint64_t>(INT_MAX) ? INT_MAX : static_cast<int>(v);
}

int Milliseconds(double seconds) {
  return ClampToInt(static_cast<std::uint64_t>(std::llround(seconds * 1000.0)));
}

// Message sizes, gRPC's buffer memory and the HTTP/2 connection limits of server.connection.
void ApplyLimits(const ServerConfig& config, grpc::ServerBuilder& builder) {
  builder.SetMaxReceiveMessageSize(ClampToInt(config.max_message_bytes));
  builder.SetMaxSendMessageSize(ClampToInt(config.max_message_bytes));
  grpc::ResourceQuota quota("tubepick-server");
  quota.Resize(static_cast<std::size_t>(config.resource_quota_bytes));
  builder.SetResourceQuota(quota);
  const ConnectionLimits& c = config.connection;
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIME_MS, Milliseconds(c.keepalive_time));
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_TIMEOUT_MS, Milliseconds(c.keepalive_timeout));
  builder.AddChannelArgument(GRPC_ARG_KEEPALIVE_PERMIT_WITHOUT_CALLS, 1);
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MIN_RECV_PING_INTERVAL_WITHOUT_DATA_MS,
                             Milliseconds(c.min_client_ping_interval));
  builder.AddChannelArgument(GRPC_ARG_HTTP2_MAX_PING_STRIKES, 2);
  builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_IDLE_MS, Milliseconds(c.max_idle));
  builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_AGE_MS, Milliseconds(c.max_age));
  builder.AddChannelArgument(GRPC_ARG_MAX_CONNECTION_AGE_GRACE_MS, Milliseconds(c.max_age_grace));
  builder.AddChannelArgument(GRPC_ARG_MAX_CONCURRENT_STREAMS, ClampToInt(c.max_concurrent_streams));
}

}  // namespace

struct PlannerServer::Impl {
  enum class State { kCreated, kRunning, kStopping, kStopped };

  explicit Impl(ServerConfig c) : config(std::move(c)) {}

  ServerConfig config;
  std::unique_ptr<WorkerPool> pool;
  std::unique_ptr<Metrics> metrics;
  std::unique_ptr<PlannerService> service;
  std::unique_ptr<grpc::Server> server;
  std::unique_ptr<DebugCallStore> debug_calls;
  std::unique_ptr<HttpEndpoints> http;
  int port = 0;
  /// What grpc.health.v1 says, for the HTTP probe (/healthz): true from Start until Shutdown begins.
  std::atomic<bool> serving{false};

  std::mutex mu;
  std::condition_variable cv;
  State state = State::kCreated;
};

PlannerServer::PlannerServer(ServerConfig config) : impl_(std::make_unique<Impl>(std::move(config))) {
  impl_->config.Validate();
}

PlannerServer::~PlannerServer() { Shutdown(std::chrono::milliseconds(0)); }

void PlannerServer::Start() {
  Impl& m = *impl_;
  {
    std::lock_guard lock(m.mu);
    if (m.state != Impl::State::kCreated) throw std::runtime_error("PlannerServer::Start: already started");
  }
  const ServerConfig& config = m.config;
  // Both are process-wide switches read when a server is built.
  static std::once_flag global_setup;
  std::call_once(global_setup, [] {
    grpc::EnableDefaultHealthCheckService(true);
    grpc::reflection::InitProtoReflectionServerBuilderPlugin();
  });
  // gRPC's health service is not protobuf-generated, so reflection cannot describe it unless its
  // descriptor is in the generated pool: referencing it links health.pb.o and registers it, and
  // `buf curl .../grpc.health.v1.Health/Check` works without a local schema.
  (void)grpc::health::v1::HealthCheckRequest::descriptor();

  m.metrics = std::make_unique<Metrics>();
  m.pool = std::make_unique<WorkerPool>(WorkerCount(config), config.queue_capacity);
  if (config.debug.keep_last > 0)
    m.debug_calls = std::make_unique<DebugCallStore>(config.debug.keep_last, config.debug.max_points);
  m.service = std::make_unique<PlannerService>(config, m.pool.get(), m.metrics.get(), m.debug_calls.get());

  grpc::ServerBuilder builder;
  if (!config.reflection) builder.SetOption(std::make_unique<WithoutReflection>());
  builder.AddListeningPort(config.address, MakeCredentials(config.tls), &m.port);
  ApplyLimits(config, builder);
  // A second server on a fixed, busy port must fail rather than share it silently.
  builder.AddChannelArgument(GRPC_ARG_ALLOW_REUSEPORT, 0);
  builder.RegisterService(m.service.get());
  m.server = builder.BuildAndStart();
  if (m.server == nullptr || m.port == 0) {
    m.server.reset();
    m.pool->Stop();
    throw std::runtime_error(fmt::format("cannot listen on {} (address in use or invalid?)", config.address));
  }
  grpc::HealthCheckServiceInterface* health = m.server->GetHealthCheckService();
  health->SetServingStatus("", true);
  health->SetServingStatus(kServiceName, true);
  m.serving = true;

  if (!config.metrics_address.empty()) {
    try {
      HttpEndpointsOptions http;
      http.render_metrics = [&m] {
        return m.metrics->RenderPrometheus(m.pool->load(), m.service->uploads_in_progress());
      };
      http.serving = [&m] { return m.serving.load(); };
      http.debug_calls = m.debug_calls.get();
      m.http = std::make_unique<HttpEndpoints>(config.metrics_address, std::move(http));
    } catch (...) {
      m.server->Shutdown(std::chrono::system_clock::now());
      m.server.reset();
      m.pool->Stop();
      throw;
    }
  }
  {
    std::lock_guard lock(m.mu);
    m.state = Impl::State::kRunning;
  }
  const std::string host = HostForLog(SplitHostPort(config.address, "address").first);
  spdlog::info(
      "listening on {}:{} ({}, {} workers x {} threads per call on {} cores, queue {}, uploads {}, "
      "max message {} bytes)",
      host, m.port,
      config.tls.enabled() ? (config.tls.require_client_cert ? "mutual TLS" : "TLS") : "plaintext",
      m.pool->workers(), ThreadsPerCall(config), CoresAvailable(), config.queue_capacity, config.max_uploads,
      config.max_message_bytes);
  if (m.pool->workers() * ThreadsPerCall(config) > static_cast<std::uint32_t>(CoresAvailable())) {
    spdlog::warn(
        "{} workers x {} threads per call exceed the {} cores this process may use: calls will "
        "share cores (server.workers, server.threads_per_call)",
        m.pool->workers(), ThreadsPerCall(config), CoresAvailable());
  }
  if (m.http) {
    const std::string http_host = HostForLog(SplitHostPort(config.metrics_address, "metrics_address").first);
    spdlog::info("metrics on http://{}:{}/metrics (health probe: /healthz)", http_host, m.http->port());
    if (m.debug_calls) {
      spdlog::info("the last {} planning calls in the viewer at http://{}:{}/debug/calls (debug.keep_last)",
                   config.debug.keep_last, http_host, m.http->port());
    }
  }
}

int PlannerServer::port() const { return impl_->port; }

int PlannerServer::metrics_port() const { return impl_->http ? impl_->http->port() : 0; }

void PlannerServer::Shutdown(std::chrono::milliseconds grace) {
  Impl& m = *impl_;
  {
    std::unique_lock lock(m.mu);
    if (m.state == Impl::State::kStopped) return;
    if (m.state == Impl::State::kStopping) {
      m.cv.wait(lock, [&] { return m.state == Impl::State::kStopped; });
      return;
    }
    if (m.state == Impl::State::kCreated) {
      m.state = Impl::State::kStopped;
      m.cv.notify_all();
      return;
    }
    m.state = Impl::State::kStopping;
  }
  const auto started = std::chrono::steady_clock::now();
  spdlog::info("shutting down: {} calls in flight, grace {} ms", m.service->calls_in_flight(), grace.count());
  // Load balancers and health probes see NOT_SERVING first: the HTTP probe's flag before gRPC's health
  // status, so a client woken by a health watch never finds /healthz still SERVING.
  m.serving = false;
  m.server->GetHealthCheckService()->SetServingStatus(false);

  // gRPC refuses new calls at once and cancels the remaining ones at the deadline (their OnCancel
  // stops the tokens). The watchdog also stops every token then, in case a call is between states.
  const auto deadline = std::chrono::system_clock::now() + grace;
  std::mutex watchdog_mu;
  std::condition_variable watchdog_cv;
  bool drained = false;
  std::thread watchdog([&] {
    std::unique_lock lock(watchdog_mu);
    if (!watchdog_cv.wait_until(lock, deadline, [&] { return drained; })) m.service->CancelAll();
  });
  m.server->Shutdown(deadline);
  {
    std::lock_guard lock(watchdog_mu);
    drained = true;
  }
  watchdog_cv.notify_all();
  watchdog.join();
  m.service->CancelAll();
  m.pool->Stop();
  if (m.http) m.http->Stop();
  spdlog::info("shut down after {:.0f} ms; {} calls served",
               std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count(),
               m.service->calls_served());
  {
    std::lock_guard lock(m.mu);
    m.state = Impl::State::kStopped;
  }
  m.cv.notify_all();
}

void PlannerServer::Wait() {
  std::unique_lock lock(impl_->mu);
  impl_->cv.wait(lock, [&] { return impl_->state == Impl::State::kStopped; });
}

std::uint64_t PlannerServer::calls_served() const {
  return impl_->service ? impl_->service->calls_served() : 0;
}

std::uint32_t PlannerServer::workers_busy() const { return impl_->pool ? impl_->pool->load().busy : 0; }

}  // namespace tubepick::server

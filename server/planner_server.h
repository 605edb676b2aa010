#pragma once

#include <chrono>
#include <cstdint>
#include <memory>

#include "server/server_config.h"

namespace tubepick::server {

/// The PickPlannerService with everything around it: the gRPC server (callback API, TLS / mTLS,
/// message limits, grpc.health.v1, reflection), the planning worker pool with admission control,
/// the Prometheus metrics endpoint and graceful shutdown. Stateless between calls.
///
/// Usage (tests run it in-process exactly like tubepick-server does):
///   PlannerServer server(config);   // validates config; nothing bound yet
///   server.Start();                 // binds; throws std::runtime_error when it cannot
///   ... server.port() ...
///   server.Shutdown(std::chrono::seconds(5));
class PlannerServer {
 public:
  explicit PlannerServer(ServerConfig config);
  ~PlannerServer();  // Shutdown(0 s) if still running
  PlannerServer(const PlannerServer&) = delete;
  PlannerServer& operator=(const PlannerServer&) = delete;

  /// Binds the gRPC and metrics ports and starts serving. @throws std::runtime_error.
  void Start();
  /// The bound gRPC port (the real one when the config said port 0).
  int port() const;
  /// The bound metrics HTTP port; 0 when metrics are off.
  int metrics_port() const;
  /// Stops accepting calls (health turns NOT_SERVING), lets in-flight calls finish for up to
  /// `grace`, then cancels the rest, stops the workers and the metrics endpoint. Idempotent.
  void Shutdown(std::chrono::milliseconds grace);
  /// Blocks until Shutdown() completed.
  void Wait();

  /// Calls answered so far (any status), for tests and the metrics.
  std::uint64_t calls_served() const;
  /// Planning workers running a call right now (tests check that a cancelled call frees its worker).
  /// A worker counts as busy until its job has returned, i.e. a moment after the client got the answer.
  std::uint32_t workers_busy() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tubepick::server

#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <thread>
#include <utility>

namespace tubepick::server {

class DebugCallStore;

/// Splits "HOST:PORT" ("0.0.0.0:9464", "[::]:9464", "localhost:0") into host (brackets removed)
/// and port. @throws InvalidArgument naming `field` when there is no port or it is not 0..65535.
std::pair<std::string, int> SplitHostPort(std::string_view address, const std::string& field);

/// What the HTTP port serves besides gRPC.
struct HttpEndpointsOptions {
  /// Prometheus text (/metrics).
  std::function<std::string()> render_metrics;
  /// /healthz: 200 "SERVING" while it returns true, else 503 "NOT_SERVING" (the HTTP face of
  /// grpc.health.v1 for HAProxy, Docker and Kubernetes probes). Empty = no /healthz.
  std::function<bool()> serving;
  /// The kept calls for /debug/calls (debug.keep_last); null = those paths answer 404 saying so.
  const DebugCallStore* debug_calls = nullptr;
  /// Budget of one request's reading and of one answer's writing.
  std::chrono::milliseconds io_timeout{2000};
  /// Connections answered at once (the rest wait in the listen backlog): scrapes and probes are
  /// seconds apart, and every thread is one more for the allocator's arenas.
  int threads = 2;
};

/// The service's HTTP/1.1 side on cpp-httplib (Debian's libcpp-httplib):
///   GET|HEAD /metrics                 Prometheus text, version 0.0.4
///   GET|HEAD /healthz                 200 SERVING / 503 NOT_SERVING
///   GET /debug/calls                  the kept calls, newest first (HTML; .json for JSON)
///   GET /debug/calls/ID               the 3-D viewer page of one call (.json: its page data)
/// Other paths 404, other methods 405, request bodies over 4 KiB 413. Answers are never compressed
/// (no planning CPU for it). A slow or broken client holds one of `threads` connections for at most
/// io_timeout; it never blocks the gRPC side.
class HttpEndpoints {
 public:
  /// Binds and listens on `address` (HOST:PORT, port 0 = any free port) and starts serving.
  /// @throws InvalidArgument for a malformed address, std::runtime_error when it cannot bind.
  HttpEndpoints(const std::string& address, HttpEndpointsOptions options);
  ~HttpEndpoints();  // Stop()
  HttpEndpoints(const HttpEndpoints&) = delete;
  HttpEndpoints& operator=(const HttpEndpoints&) = delete;

  /// The bound port.
  int port() const { return port_; }
  /// Stops listening, finishes the requests in progress and joins. Idempotent.
  void Stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int port_ = 0;
  std::thread thread_;
};

}  // namespace tubepick::server

#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <string>
#include <string_view>
#include <thread>

namespace tubepick::server {

/// Splits "HOST:PORT" ("0.0.0.0:9464", "[::]:9464", "localhost:0") into host (brackets removed)
/// and port. @throws InvalidArgument naming `field` when there is no port or it is not 0..65535.
std::pair<std::string, int> SplitHostPort(std::string_view address, const std::string& field);

/// The answer to one HTTP request to the metrics endpoint.
struct HttpReply {
  int status = 200;
  std::string content_type;
  std::string body;
  /// Extra header lines, each ending in "\r\n".
  std::string extra_headers;
};

/// Decides the reply to a raw HTTP/1.x request head (request line and headers, no body):
/// GET or HEAD /metrics (query ignored) → 200 with `render()` as text/plain; version=0.0.4;
/// /healthz, when `serving` is given → 200 "SERVING" while it returns true, else 503 "NOT_SERVING"
/// (the HTTP face of grpc.health.v1 for load balancers and probes that speak only HTTP/1.1: HAProxy,
/// Docker, Kubernetes); other paths → 404; other methods → 405; anything malformed → 400. Pure.
HttpReply HandleMetricsRequest(std::string_view request_head, const std::function<std::string()>& render,
                               const std::function<bool()>& serving = {});

/// A tiny HTTP/1.1 server for Prometheus scrapes and the HTTP health probe (own socket code, no library). One
/// thread accepts and answers connections one at a time, each with a total I/O budget (`io_timeout`) and a
/// request head limit of 8 KiB, then closes it (Connection: close). Slow, oversized or garbage requests get
/// 400 / 431 or are dropped after the budget; they never block the gRPC side.
class MetricsHttpServer {
 public:
  /// Binds and listens on `address` (HOST:PORT, port 0 = any free port) and starts serving;
  /// `serving` (optional) answers /healthz. @throws std::runtime_error when it cannot bind.
  MetricsHttpServer(const std::string& address, std::function<std::string()> render,
                    std::chrono::milliseconds io_timeout = std::chrono::milliseconds(2000),
                    std::function<bool()> serving = {});
  ~MetricsHttpServer();  // Stop()
  MetricsHttpServer(const MetricsHttpServer&) = delete;
  MetricsHttpServer& operator=(const MetricsHttpServer&) = delete;

  /// The bound port.
  int port() const { return port_; }
  /// Closes the listening socket and joins the thread. Idempotent.
  void Stop();

 private:
  void Serve();
  void HandleConnection(int fd);
  /// Sends a serialized response within io_timeout, then half-closes and drains the connection.
  void Reply(int fd, std::string_view response);

  std::function<std::string()> render_;
  std::function<bool()> serving_;
  std::chrono::milliseconds io_timeout_;
  int listen_fd_ = -1;
  int wake_pipe_[2] = {-1, -1};
  int port_ = 0;
  std::atomic<bool> stopping_{false};
  std::thread thread_;
};

}  // namespace tubepick::server

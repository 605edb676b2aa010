#pragma once
// Shared helpers of the service tests: a real PlannerServer on 127.0.0.1:0 and real gRPC clients.

#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/common/types.h"
#include "server/planner_server.h"
#include "server/server_config.h"
#include "tubepick/v1/service.grpc.pb.h"

namespace tubepick::service_test {

/// Loopback config for tests: gRPC and metrics on 127.0.0.1:0, `workers` workers, queue `queue`,
/// warnings only in the log.
server::ServerConfig TestConfig(std::uint32_t workers = 2, std::uint32_t queue = 8);

/// A started PlannerServer with a plaintext channel and stub to it; shuts down in the destructor.
class TestServer {
 public:
  explicit TestServer(server::ServerConfig config = TestConfig());
  ~TestServer();
  server::PlannerServer& server() { return *server_; }
  const server::ServerConfig& config() const { return config_; }
  int metrics_port() const { return server_->metrics_port(); }
  /// "127.0.0.1:PORT".
  std::string target() const;
  std::shared_ptr<grpc::Channel> channel() const { return channel_; }
  v1::PickPlannerService::Stub& stub() { return *stub_; }
  /// A new channel + stub (a separate client connection).
  std::unique_ptr<v1::PickPlannerService::Stub> NewStub() const;

 private:
  server::ServerConfig config_;
  std::unique_ptr<server::PlannerServer> server_;
  std::shared_ptr<grpc::Channel> channel_;
  std::unique_ptr<v1::PickPlannerService::Stub> stub_;
};

/// Packed little-endian float32 xyz, as PointCloud.xyz carries it.
std::string PackCloud(const Points& points);

/// Three separate straight tubes (0.30, 0.26 and 0.22 m) lying on the bin floor, seen by the default
/// sensor (no floor points, 1 mm pixels): about 20 k points. Cached.
const std::string& ThreeTubeCloud();
/// The empty bin: the floor only, seen by the default sensor (2.2 mm pixels): about 100 k points.
/// Cached.
const std::string& EmptyBinCloud();
/// A generated bin of 8 tubes (physics drop + virtual scan, default cell), about 1 M points: the
/// "slow" request of the cancellation and admission tests (thesis profile, simulation on). Cached.
const std::string& BusyBinCloud();

v1::ModelTubesRequest ModelRequest(const std::string& xyz);
v1::PlanPickRequest PlanRequest(const std::string& xyz, bool simulate = false);
/// A PlanPick that keeps a worker busy for seconds (BusyBinCloud, thesis profile, simulation).
v1::PlanPickRequest SlowPlanRequest();

/// Sets a deadline `timeout` from now.
void SetTimeout(grpc::ClientContext* context, std::chrono::milliseconds timeout);

/// Raw message bytes <-> gRPC byte buffers (for GenericStub calls).
grpc::ByteBuffer ToByteBuffer(const std::string& bytes);
std::string FromByteBuffer(const grpc::ByteBuffer& buffer);
/// grpc.health.v1 HealthCheckRequest{service} and HealthCheckResponse.status, hand-encoded.
std::string EncodeHealthCheckRequest(const std::string& service);
int DecodeServingStatus(const std::string& response);

/// grpc.health.v1.Health/Check through a GenericStub with hand-encoded messages. Returns the
/// ServingStatus number (1 SERVING, 2 NOT_SERVING, 3 SERVICE_UNKNOWN) or the call's error.
struct HealthResult {
  grpc::Status status;
  int serving = 0;
};
HealthResult CheckHealth(const std::shared_ptr<grpc::Channel>& channel, const std::string& service);

/// Names the server lists through grpc.reflection.v1alpha ServerReflectionInfo (list_services).
std::vector<std::string> ReflectionListServices(const std::shared_ptr<grpc::Channel>& channel);
/// The FileDescriptorProto names and the service methods reflection returns for a symbol
/// (file_containing_symbol), as "file" and "Service.Method" strings.
std::vector<std::string> ReflectionDescribe(const std::shared_ptr<grpc::Channel>& channel,
                                            const std::string& symbol);

/// Sends raw bytes to 127.0.0.1:port and returns everything the server answers until it closes.
std::string HttpExchange(int port, const std::string& request);
/// GET /metrics body (throws unless 200).
std::string ScrapeMetrics(int port);
/// The value of one sample line (`name{labels} value`), nullopt when absent.
std::optional<double> MetricValue(const std::string& exposition, const std::string& series);

/// Runs `predicate` every millisecond until it holds or `timeout` passes; the elapsed time when it
/// held, nullopt on timeout.
template <class Predicate>
std::optional<std::chrono::duration<double, std::milli>> WaitFor(Predicate predicate,
                                                                 std::chrono::milliseconds timeout) {
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    if (predicate()) return std::chrono::steady_clock::now() - start;
    if (std::chrono::steady_clock::now() - start > timeout) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

}  // namespace tubepick::service_test

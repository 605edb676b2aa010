#pragma once

#include <chrono>
#include <string>

#include <CLI/CLI.hpp>

#include "clients/cli/remote/channel.h"

namespace tubepick::cli {

/// grpc.health.v1.HealthCheckResponse.ServingStatus.
enum class ServingStatus { kUnknown = 0, kServing = 1, kNotServing = 2, kServiceUnknown = 3 };

/// "UNKNOWN", "SERVING", "NOT_SERVING", "SERVICE_UNKNOWN".
std::string ToString(ServingStatus status);

/// The answer of one grpc.health.v1.Health/Check call.
struct HealthAnswer {
  /// gRPC status of the call (OK when the server answered).
  int grpc_code = 0;
  std::string grpc_message;
  /// Meaningful when grpc_code == 0.
  ServingStatus status = ServingStatus::kUnknown;
};

/// Calls grpc.health.v1.Health/Check for `service` ("" = the whole server) with a deadline of
/// `timeout`. Never throws for an unreachable or failing server: the answer says what happened.
HealthAnswer CheckHealth(const ChannelOptions& channel, const std::string& service,
                         std::chrono::milliseconds timeout);

/// `tubepick health --target HOST:PORT [--service NAME] [--timeout S] [--tls-ca FILE ...]`: exits 0
/// when the server (or the service) is SERVING, 1 otherwise, printing one line (Docker HEALTHCHECK).
void AddHealthCommand(CLI::App& app);

}  // namespace tubepick::cli

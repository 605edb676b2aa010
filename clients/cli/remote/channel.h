#pragma once

#include <memory>
#include <string>

#include <grpcpp/channel.h>
#include <grpcpp/support/status.h>
#include <CLI/CLI.hpp>

#include "wire/status_names.h"

namespace tubepick::cli {

/// Where and how a client command reaches a tubepick-server (shared by `load` and `health`).
struct ChannelOptions {
  /// HOST:PORT of the server (or any gRPC target URI, e.g. dns:///planner:50051).
  std::string target = "127.0.0.1:50051";
  /// PEM CA bundle that the server certificate must chain to; empty = plaintext.
  std::string tls_ca_file;
  /// PEM client certificate chain and key, for servers that require mutual TLS.
  std::string tls_cert_file;
  std::string tls_key_file;
  /// Overrides the host name checked against the server certificate (SNI / SAN).
  std::string tls_server_name;
  /// gRPC load-balancing policy ("pick_first", "round_robin"); empty = gRPC's default.
  std::string lb_policy;
};

/// Registers --target, --tls-ca, --tls-cert, --tls-key, --tls-server-name and --lb-policy.
void AddChannelOptions(CLI::App* cmd, ChannelOptions& options);

/// A channel with unlimited message sizes (the server enforces its own limit).
/// @throws InvalidArgument when a TLS file cannot be read or TLS options are inconsistent.
std::shared_ptr<grpc::Channel> MakeChannel(const ChannelOptions& options);

}  // namespace tubepick::cli

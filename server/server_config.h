#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>

#include "core/common/cell_config.h"
#include "core/params.h"
#include "physics/trajectory_simulator.h"

namespace tubepick::server {

/// TLS of the gRPC port. Off when cert_file is empty.
struct TlsConfig {
  /// PEM server certificate chain and private key.
  std::string cert_file;
  std::string key_file;
  /// PEM CA bundle that client certificates must chain to (mutual TLS); empty = no client certs.
  std::string client_ca_file;
  /// Mutual TLS: reject clients without a valid certificate (needs client_ca_file).
  bool require_client_cert = false;
  bool enabled() const { return !cert_file.empty(); }
};

/// The shipped profiles by name: "fast" and "thesis" (ProfileParams).
std::map<std::string, Params> DefaultProfiles();

/// What the server falls back to for fields a request leaves out, and the limits of a request.
struct PlanningDefaults {
  /// The cell used when a request carries no CellDescription.
  CellConfig cell;
  /// Profile used when a request names none.
  std::string profile = "fast";
  /// Seed used when a request gives none.
  std::uint64_t seed = 1;
  /// Parameters by profile name: "fast" and "thesis" always; `params_file` replaces the default
  /// profile's entry.
  std::map<std::string, Params> profiles = DefaultProfiles();
  /// Largest cloud accepted, points (12 bytes each).
  std::uint64_t max_cloud_points = 10'000'000;
  /// Threads each PlanPick simulates its trajectories on (RunPlanPick's `simulation_threads`);
  /// 0 = hardware threads. Requests already run in parallel on the worker pool, so 1 keeps
  /// workers × threads at the core count; raise it when few calls arrive at once and latency matters.
  std::uint32_t simulation_threads = 1;
  /// Trajectory simulation (bin, tube mass and disp_max are filled per request from the cell and
  /// the profile's planning.cost.max_displacement; `threads` is replaced by simulation_threads).
  physics::TrajectorySimParams simulation;
};

/// The whole server configuration (`tubepick-server --config FILE`; EmbeddedServerConfigYaml() is the
/// default). Every key is optional; unknown keys are errors.
struct ServerConfig {
  /// gRPC listen address, HOST:PORT (port 0 = any free port). Loopback by default: a plant network
  /// is reached only when the deployment says so (the Docker image passes 0.0.0.0).
  std::string address = "127.0.0.1:50051";
  /// Planning worker threads; 0 = hardware threads.
  std::uint32_t workers = 0;
  /// Admitted requests that may wait for a worker; beyond that RESOURCE_EXHAUSTED.
  std::uint32_t queue_capacity = 8;
  /// Largest gRPC message received or sent, bytes.
  std::uint64_t max_message_bytes = 64ull << 20;
  /// Largest cloud a PlanPickStream may announce, bytes.
  std::uint64_t max_stream_bytes = 512ull << 20;
  /// SIGTERM: in-flight calls get this long to finish, then are cancelled, seconds.
  double shutdown_grace = 10.0;
  /// Prometheus text metrics over HTTP at HOST:PORT/metrics; empty = off. Loopback by default.
  std::string metrics_address = "127.0.0.1:9464";
  /// gRPC server reflection (what `buf curl` and grpcurl list and describe); off in production
  /// profiles that publish no schema.
  bool reflection = true;
  /// spdlog level name: trace, debug, info, warn, error, critical, off.
  std::string log_level = "info";
  /// "text" or "json" (one JSON object per line).
  std::string log_format = "text";
  TlsConfig tls;
  PlanningDefaults planning;

  /// @throws InvalidArgument naming the first bad field and its value.
  void Validate() const;
};

/// Checks a HOST:PORT address (host name, IPv4, or [IPv6]; port 0..65535).
/// @throws InvalidArgument naming `key` and the address.
void ValidateHostPort(const std::string& address, const std::string& key);

/// The built-in default configuration as YAML (every key, with comments): the dump of a
/// default-constructed ServerConfig, written from the same field declarations the parser reads.
std::string_view EmbeddedServerConfigYaml();

/// Parses a server YAML strictly on top of the defaults. Sections: `server` (address, workers, ...,
/// tls), `planning` (profile, seed, params_file, max_cloud_points, simulation: {...}), `cell` (the
/// cell YAML schema) or `cell_file`. Relative file paths are relative to `base_dir`.
/// @throws InvalidArgument with the key path and the reason.
ServerConfig ParseServerConfig(const std::string& yaml_text, const std::string& base_dir = ".");
ServerConfig LoadServerConfig(const std::string& path);

}  // namespace tubepick::server

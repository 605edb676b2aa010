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
  /// Trajectory simulation (bin, tube mass and disp_max are filled per request from the cell and
  /// the profile's planning.cost.max_displacement; `threads` by the server's threads per call).
  physics::TrajectorySimParams simulation;
};

/// What a connection may do and how long it may live (gRPC channel arguments of the server).
struct ConnectionLimits {
  /// The server pings a connection after this long without activity, seconds (finds dead peers).
  double keepalive_time = 30.0;
  /// A ping not answered within this long closes the connection, seconds.
  double keepalive_timeout = 10.0;
  /// A client may ping at most this often (and may ping without calls in flight); faster pings
  /// get a GOAWAY (too_many_pings), seconds.
  double min_client_ping_interval = 10.0;
  /// A connection without calls for this long is closed with a GOAWAY (clients reconnect), seconds.
  double max_idle = 600.0;
  /// Any connection is closed after this long so that clients rebalance, seconds; calls in flight
  /// get max_age_grace more to finish.
  double max_age = 3600.0;
  double max_age_grace = 300.0;
  /// Calls in flight at once on one connection (HTTP/2 SETTINGS_MAX_CONCURRENT_STREAMS); more wait
  /// at the client.
  std::uint32_t max_concurrent_streams = 32;
};

/// What the server keeps of its last planning calls for the viewer on its HTTP port (/debug/calls,
/// docs/VIEWER.md): the thinned cloud, the response or error. Off by default.
struct DebugConfig {
  /// Planning calls kept, newest first; 0 = none (and /debug/calls answers 404).
  std::uint32_t keep_last = 0;
  /// Cloud points kept per call (every k-th point, bin frame).
  std::uint32_t max_points = 200'000;
};

/// The whole server configuration (`tubepick-server --config FILE`; EmbeddedServerConfigYaml() is the
/// default). Every key is optional; unknown keys are errors.
struct ServerConfig {
  /// gRPC listen address, HOST:PORT (port 0 = any free port). Loopback by default: a plant network
  /// is reached only when the deployment says so (the Docker image passes 0.0.0.0).
  std::string address = "127.0.0.1:50051";
  /// Planning worker threads; 0 = the cores the process may use (CoresAvailable: affinity, cgroup).
  std::uint32_t workers = 0;
  /// Threads one planning call may run on: every parallel region of modeling (OpenMP) and the
  /// trajectory simulation (Bullet worlds), whatever OMP_NUM_THREADS or a profile's
  /// modeling.threads says. 0 = the cores the process may use ÷ workers, at least 1, so that
  /// workers × threads_per_call stays within the cores.
  std::uint32_t threads_per_call = 0;
  /// Admitted requests that may wait for a worker; beyond that RESOURCE_EXHAUSTED.
  std::uint32_t queue_capacity = 8;
  /// Largest gRPC message received or sent, bytes.
  std::uint64_t max_message_bytes = 64ull << 20;
  /// Largest cloud a PlanPickStream may announce, bytes.
  std::uint64_t max_stream_bytes = 512ull << 20;
  /// PlanPickStream uploads in progress at once (header received, cloud incomplete); more are
  /// answered RESOURCE_EXHAUSTED. Apart from planning admission: uploads never hold a worker slot.
  std::uint32_t max_uploads = 16;
  /// An upload that sends no message for this long is ended with DEADLINE_EXCEEDED, seconds.
  double stream_idle_timeout = 10.0;
  /// The deadline of a call that carries none, seconds: its work stops there with DEADLINE_EXCEEDED.
  double max_call_time = 120.0;
  /// gRPC's buffer memory for all connections (grpc::ResourceQuota), bytes; ≥ max_message_bytes.
  std::uint64_t resource_quota_bytes = 1ull << 30;
  ConnectionLimits connection;
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
  DebugConfig debug;
  PlanningDefaults planning;

  /// @throws InvalidArgument naming the first bad field and its value.
  void Validate() const;
};

/// Planning worker threads: `workers`, or CoresAvailable() for 0.
std::uint32_t WorkerCount(const ServerConfig& config);
/// Threads per planning call: `threads_per_call`, or CoresAvailable() ÷ WorkerCount() (≥ 1) for 0.
std::uint32_t ThreadsPerCall(const ServerConfig& config);

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

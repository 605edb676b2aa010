#include "server/server_config.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include <fmt/format.h>

#include "core/common/cell_config_fields.h"
#include "core/common/config_fields.h"
#include "core/common/errors.h"
#include "core/common/require.h"
#include "core/common/thread_budget.h"

namespace tubepick::server {

template <typename Visit>
void DescribeFields(Visit& v, ConnectionLimits& c) {
  v("keepalive_time", c.keepalive_time, "Ping a connection after this long without activity, s.");
  v("keepalive_timeout", c.keepalive_timeout, "Close it when the ping is not answered within, s.");
  v("min_client_ping_interval", c.min_client_ping_interval,
    "Clients may ping this often (also without calls); faster = GOAWAY too_many_pings, s.");
  v("max_idle", c.max_idle, "Close a connection without calls after this long (GOAWAY), s.");
  v("max_age", c.max_age, "Close every connection after this long so clients rebalance, s;");
  v("max_age_grace", c.max_age_grace, "calls in flight then get this long to finish, s.");
  v("max_concurrent_streams", c.max_concurrent_streams, "Calls in flight at once on one connection.");
}

// The `server.tls` section (in the namespace of TlsConfig, where the config visitors look for it).
template <typename Visit>
void DescribeFields(Visit& v, TlsConfig& tls) {
  v("cert_file", tls.cert_file,
    "PEM certificate chain and private key of the server; both empty = plaintext.");
  v("key_file", tls.key_file);
  v("client_ca_file", tls.client_ca_file,
    "PEM CA bundle client certificates are verified against (mutual TLS); \"\" = none requested.");
  v("require_client_cert", tls.require_client_cert,
    "Reject clients without a valid certificate (needs client_ca_file).");
}

// The `debug` section (beside DebugConfig, where the config visitors look for it).
template <typename Visit>
void DescribeFields(Visit& v, DebugConfig& d) {
  v("keep_last", d.keep_last,
    "Keep the last N planning calls (cloud thinned, response or error) and show them in the 3-D\n"
    "viewer at http://METRICS_ADDRESS/debug/calls; 0 = off. Needs server.metrics_address.");
  v("max_points", d.max_points, "Cloud points kept per call (every k-th point).");
}

namespace {

constexpr std::uint64_t kMiB = 1ull << 20;
constexpr std::uint64_t kGiB = 1ull << 30;

std::string ResolvePath(const std::string& path, const std::string& base_dir) {
  if (path.empty()) return path;
  const std::filesystem::path p(path);
  if (p.is_absolute()) return path;
  return (std::filesystem::path(base_dir) / p).lexically_normal().string();
}

std::string JoinNames(const std::map<std::string, Params>& profiles) {
  std::string names;
  for (const auto& [name, params] : profiles) names += (names.empty() ? "" : ", ") + name;
  return names;
}

// @throws InvalidArgument when planning.profile names none of the profiles.
void RequireKnownProfile(const PlanningDefaults& p) {
  if (!p.profiles.count(p.profile)) {
    throw InvalidArgument("planning.profile: unknown profile '" + p.profile +
                          "' (known: " + JoinNames(p.profiles) + ")");
  }
}

// Rewrites an error of the cell schema (paths relative to the cell document) into the server
// config's key paths: "tube.radius: ..." → "cell.tube.radius: ...",
// "unknown key(s): tube.colour" → "unknown key(s): cell.tube.colour".
std::string PrefixCellError(const std::string& message) {
  const std::string unknown = "unknown key(s): ";
  if (message.rfind(unknown, 0) == 0) {
    std::string out = unknown;
    std::istringstream keys(message.substr(unknown.size()));
    std::string key;
    bool first = true;
    while (std::getline(keys, key, ',')) {
      const auto begin = key.find_first_not_of(' ');
      out += (first ? "" : ", ") + std::string("cell.") + key.substr(begin == std::string::npos ? 0 : begin);
      first = false;
    }
    return out;
  }
  return "cell." + message;
}

// ---- the server YAML: field declarations (core/common/config_fields.h) ---------------------------

constexpr std::string_view kHeader =
    "tubepick-server configuration: every key with its default (tubepick-server --config FILE).\n"
    "Every key is optional; unknown keys are errors. Units: metres, kilograms, seconds.\n"
    "Relative file paths are relative to the directory of this file.";

/// The server YAML document: the ServerConfig fields plus the keys that name files to load.
struct ServerFile {
  ServerConfig config;
  /// planning.params_file: a params YAML over the default profile; "" = none.
  std::string params_file;
  /// A cell YAML, or the `cell` section (nullopt: absent or null); at most one of the two.
  std::string cell_file;
  std::optional<CellConfig> cell;
};

/// The `server` section: ServerConfig without its planning defaults.
struct ServerSection {
  ServerConfig& config;
};

/// The `planning` section: PlanningDefaults and params_file.
struct PlanningSection {
  PlanningDefaults& defaults;
  std::string& params_file;
};

/// The `planning.simulation` section: the TrajectorySimParams an operator sets (the bin, tube mass,
/// disp_max and threads are filled per request).
struct SimulationSection {
  physics::TrajectorySimParams& s;
};

template <typename Visit>
void DescribeFields(Visit& v, ServerSection& section) {
  ServerConfig& c = section.config;
  v("address", c.address,
    "gRPC listen address, HOST:PORT (port 0 = any, IPv6 \"[::]:50051\"); \"0.0.0.0:50051\" = all "
    "interfaces.");
  v("workers", c.workers, "Planning worker threads; 0 = the cores the process may use (affinity, cgroup).");
  v("threads_per_call", c.threads_per_call,
    "Threads one planning call runs on (modeling's OpenMP regions, the trajectory simulation),\n"
    "whatever OMP_NUM_THREADS says; 0 = cores / workers, at least 1.");
  v("queue_capacity", c.queue_capacity,
    "Admitted calls that may wait for a free worker; more are answered RESOURCE_EXHAUSTED. >= 1.");
  v("max_message_bytes", c.max_message_bytes,
    "Largest gRPC message received or sent, bytes, in [1 MiB, 2 GiB): 64 MiB.");
  v("max_stream_bytes", c.max_stream_bytes,
    "Largest cloud a PlanPickStream header may announce, bytes: 512 MiB.");
  v("max_uploads", c.max_uploads,
    "PlanPickStream uploads in progress at once; more are RESOURCE_EXHAUSTED. Uploads hold no\n"
    "planning slot.");
  v("stream_idle_timeout", c.stream_idle_timeout,
    "An upload that sends nothing for this long ends with DEADLINE_EXCEEDED, seconds.");
  v("max_call_time", c.max_call_time, "The deadline of a call that sets none, seconds.");
  v("resource_quota_bytes", c.resource_quota_bytes,
    "gRPC's buffer memory for all connections, bytes: 1 GiB.");
  v("shutdown_grace", c.shutdown_grace,
    "On SIGTERM, in-flight calls get this long to finish before they are cancelled, seconds.");
  v("metrics_address", c.metrics_address,
    "Prometheus text metrics at http://HOST:PORT/metrics; \"\" = off. Bind an internal address only.");
  v("reflection", c.reflection, "gRPC server reflection (buf curl, grpcurl); false publishes no schema.");
  v("log_level", c.log_level, "trace, debug, info, warn, error, critical or off.");
  v("log_format", c.log_format, "text, or json (one JSON object per line).");
  v.Section("connection", c.connection, "HTTP/2 connection limits (keepalive, idle, age, streams).");
  v.Section("tls", c.tls);
}

template <typename Visit>
void DescribeFields(Visit& v, SimulationSection& section) {
  physics::TrajectorySimParams& s = section.s;
  v("gripper_speed", s.gripper_speed, "Speed of the grasped tube along its waypoints, m/s.");
  v("time_step", s.time_step, "Fixed simulation step, s (1/120).");
  v("solver_iterations", s.solver_iterations, "Sequential-impulse solver iterations per step.");
  v("settle_time", s.settle_time, "Longest settling under gravity before the snapshot, s.");
  v("rest_time", s.rest_time,
    "Settling ends once every tube has stayed below the rest velocities this long, s.");
  v("linear_rest_velocity", s.linear_rest_velocity, "Rest velocities, m/s and rad/s.");
  v("angular_rest_velocity", s.angular_rest_velocity);
  v("post_motion_time", s.post_motion_time,
    "The grasped tube is held still at its last waypoint this long before measuring, s.");
  v("tube_friction", s.tube_friction,
    "Friction coefficients of tubes and bin; rolling friction of tubes, m.");
  v("bin_friction", s.bin_friction);
  v("tube_rolling_friction", s.tube_rolling_friction);
  v("tube_restitution", s.tube_restitution, "Restitution of tubes and bin.");
  v("bin_restitution", s.bin_restitution);
  v("linear_damping", s.linear_damping, "Velocity damping of tubes, fraction lost per second.");
  v("angular_damping", s.angular_damping);
  v("collision_margin", s.collision_margin, "Collision margin of flat tube ends and bin walls, m.");
  v("joint_min_length", s.joint_min_length,
    "Consecutive cylinders farther apart than this are linked by a joint cylinder, m.");
  v("sleep_linear_velocity", s.sleep_linear_velocity,
    "Sleep thresholds of a tube woken during a trajectory, m/s and rad/s; 0 disables sleeping.");
  v("sleep_angular_velocity", s.sleep_angular_velocity);
  v("wall_thickness", s.wall_thickness, "Simulated bin wall thickness, m.");
}

template <typename Visit>
void DescribeFields(Visit& v, PlanningSection& section) {
  PlanningDefaults& p = section.defaults;
  v("profile", p.profile, "Parameter profile of requests that name none: fast or thesis.");
  v("seed", p.seed, "Seed of requests that give none.");
  v("params_file", section.params_file,
    "A `tubepick params --dump` YAML (complete or partial) that replaces the parameters of the\n"
    "profile above; \"\" = the compiled-in profile.");
  v("max_cloud_points", p.max_cloud_points, "Largest cloud accepted, points (12 bytes each).");
  SimulationSection simulation{p.simulation};
  v.Section("simulation", simulation,
            "Trajectory simulation (Bullet). The bin and the tube mass come from the request's cell, the\n"
            "displacement limit from the profile's planning.cost.max_displacement.");
}

template <typename Visit>
void DescribeFields(Visit& v, ServerFile& file) {
  ServerSection server{file.config};
  v.Section("server", server);
  v.Section("debug", file.config.debug, "The viewer of recent calls on the HTTP port (off by default).");
  PlanningSection planning{file.config.planning, file.params_file};
  v.Section("planning", planning);
  v.Heading(
      "The cell of requests that carry no CellDescription (the schema of `tubepick --cell FILE`).\n"
      "Alternatively cell_file names such a file; give one of the two.");
  v("cell_file", file.cell_file);
  v.OptionalSection("cell", file.cell);
}

// ---- the server YAML: behaviour after reading ---------------------------------------------------

void ResolveTlsPaths(TlsConfig& tls, const std::string& base_dir) {
  tls.cert_file = ResolvePath(tls.cert_file, base_dir);
  tls.key_file = ResolvePath(tls.key_file, base_dir);
  tls.client_ca_file = ResolvePath(tls.client_ca_file, base_dir);
}

// Replaces the default profile's params with `params_file` read over them.
void ApplyParamsFile(const std::string& params_file, const std::string& base_dir, PlanningDefaults& p) {
  RequireKnownProfile(p);
  if (params_file.empty()) return;
  const std::string path = ResolvePath(params_file, base_dir);
  try {
    p.profiles[p.profile] = LoadParams(path, p.profiles.at(p.profile));
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("planning.params_file: " + std::string(e.what()));
  }
}

// The cell of the `cell` section or of `cell_file` (relative to base_dir); the default without either.
void ApplyCell(const ServerFile& file, const std::string& base_dir, CellConfig& cell) {
  if (file.cell && !file.cell_file.empty()) {
    throw InvalidArgument("cell_file: '" + file.cell_file + "' and a cell section: give one of the two");
  }
  if (file.cell) {
    cell = *file.cell;  // validated with the config (PrefixCellError)
  } else if (!file.cell_file.empty()) {
    try {
      cell = LoadCellConfig(ResolvePath(file.cell_file, base_dir));
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(std::string("cell_file: ") + e.what());
    }
  }
}

bool ValidHost(const std::string& host) {
  if (host.empty()) return false;
  if (host.front() == '[') {  // IPv6 literal
    if (host.size() < 3 || host.back() != ']') return false;
    for (std::size_t i = 1; i + 1 < host.size(); ++i) {
      const char ch = host[i];
      if (!(std::isxdigit(static_cast<unsigned char>(ch)) || ch == ':' || ch == '.' || ch == '%'))
        return false;
    }
    return true;
  }
  for (const char ch : host) {
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '.' || ch == '-' || ch == '_')) return false;
  }
  return true;
}

void RequireCount(std::uint64_t value, std::uint64_t lo, std::uint64_t hi, const std::string& key) {
  if (value < lo || value > hi) {
    throw InvalidArgument(fmt::format("{}: {} is out of range [{}, {}]", key, value, lo, hi));
  }
}

// The limits of threads, uploads, call time, gRPC memory and connections.
void ValidateCallLimits(const ServerConfig& c) {
  RequireCount(c.threads_per_call, 0, 1024, "server.threads_per_call");
  RequireCount(c.max_uploads, 1, 100'000, "server.max_uploads");
  RequireInRange(c.stream_idle_timeout, 0.01, 3600.0, "server.stream_idle_timeout");
  RequireInRange(c.max_call_time, 0.01, 86400.0, "server.max_call_time");
  if (c.resource_quota_bytes < c.max_message_bytes) {
    throw InvalidArgument(fmt::format(
        "server.resource_quota_bytes: {} is less than server.max_message_bytes ({}): a largest message must "
        "fit in gRPC's buffer memory",
        c.resource_quota_bytes, c.max_message_bytes));
  }
  const ConnectionLimits& k = c.connection;
  RequireInRange(k.keepalive_time, 0.01, 86400.0, "server.connection.keepalive_time");
  RequireInRange(k.keepalive_timeout, 0.01, 3600.0, "server.connection.keepalive_timeout");
  RequireInRange(k.min_client_ping_interval, 0.0, 86400.0, "server.connection.min_client_ping_interval");
  RequireInRange(k.max_idle, 0.01, 30.0 * 86400.0, "server.connection.max_idle");
  RequireInRange(k.max_age, 0.01, 30.0 * 86400.0, "server.connection.max_age");
  RequireInRange(k.max_age_grace, 0.0, 86400.0, "server.connection.max_age_grace");
  RequireCount(k.max_concurrent_streams, 1, 1'000'000, "server.connection.max_concurrent_streams");
}

void RequireReadableFile(const std::string& path, const std::string& key) {
  std::ifstream in(path);
  if (!in) throw InvalidArgument(key + ": cannot read '" + path + "'");
}

}  // namespace

std::map<std::string, Params> DefaultProfiles() {
  std::map<std::string, Params> profiles;
  for (const std::string& name : ProfileNames()) profiles.emplace(name, ProfileParams(name));
  return profiles;
}

std::uint32_t WorkerCount(const ServerConfig& config) {
  return config.workers > 0 ? config.workers : static_cast<std::uint32_t>(CoresAvailable());
}

std::uint32_t ThreadsPerCall(const ServerConfig& config) {
  if (config.threads_per_call > 0) return config.threads_per_call;
  return std::max<std::uint32_t>(1, static_cast<std::uint32_t>(CoresAvailable()) / WorkerCount(config));
}

void ValidateHostPort(const std::string& address, const std::string& key) {
  const auto colon = address.rfind(':');
  const std::string expected = " (expected HOST:PORT, e.g. 0.0.0.0:50051 or [::1]:50051)";
  if (colon == std::string::npos) throw InvalidArgument(key + ": '" + address + "' has no port" + expected);
  const std::string host = address.substr(0, colon);
  const std::string port = address.substr(colon + 1);
  if (!ValidHost(host)) throw InvalidArgument(key + ": '" + address + "' has an invalid host" + expected);
  if (port.empty() || port.size() > 5 || port.find_first_not_of("0123456789") != std::string::npos ||
      std::stoul(port) > 65535) {
    throw InvalidArgument(key + ": '" + address + "': port '" + port + "' is not in 0..65535" + expected);
  }
}

void ServerConfig::Validate() const {
  ValidateHostPort(address, "server.address");
  if (!metrics_address.empty()) ValidateHostPort(metrics_address, "server.metrics_address");
  if (debug.keep_last > 1000) {
    throw InvalidArgument(fmt::format("debug.keep_last: {} is out of range [0, 1000]", debug.keep_last));
  }
  if (debug.keep_last > 0 && metrics_address.empty()) {
    throw InvalidArgument(fmt::format(
        "debug.keep_last: {} needs server.metrics_address (its HTTP port serves /debug/calls), which is off",
        debug.keep_last));
  }
  if (debug.max_points < 1000 || debug.max_points > 5'000'000) {
    throw InvalidArgument(
        fmt::format("debug.max_points: {} is out of range [1000, 5000000]", debug.max_points));
  }
  if (workers > 1024) {
    throw InvalidArgument("server.workers: " + std::to_string(workers) + " is out of range [0, 1024]");
  }
  if (queue_capacity < 1 || queue_capacity > 1'000'000) {
    throw InvalidArgument("server.queue_capacity: " + std::to_string(queue_capacity) +
                          " is out of range [1, 1000000]");
  }
  if (max_message_bytes < kMiB || max_message_bytes >= 2 * kGiB) {
    throw InvalidArgument("server.max_message_bytes: " + std::to_string(max_message_bytes) +
                          " is out of range [1 MiB = 1048576, 2 GiB = 2147483648)");
  }
  if (max_stream_bytes < 12 || max_stream_bytes > 1024 * kGiB) {
    throw InvalidArgument("server.max_stream_bytes: " + std::to_string(max_stream_bytes) +
                          " is out of range [12, 1 TiB]");
  }
  RequireInRange(shutdown_grace, 0.0, 3600.0, "server.shutdown_grace");
  ValidateCallLimits(*this);
  static const char* const kLevels[] = {"trace", "debug", "info", "warn", "error", "critical", "off"};
  if (std::find(std::begin(kLevels), std::end(kLevels), log_level) == std::end(kLevels)) {
    throw InvalidArgument("server.log_level: unknown level '" + log_level +
                          "' (expected trace, debug, info, warn, error, critical or off)");
  }
  if (log_format != "text" && log_format != "json") {
    throw InvalidArgument("server.log_format: unknown format '" + log_format + "' (expected text or json)");
  }

  if (tls.cert_file.empty() != tls.key_file.empty()) {
    throw InvalidArgument(tls.cert_file.empty() ? "server.tls.cert_file: missing; server.tls.key_file '" +
                                                      tls.key_file + "' needs a certificate"
                                                : "server.tls.key_file: missing; server.tls.cert_file '" +
                                                      tls.cert_file + "' needs its private key");
  }
  if (!tls.client_ca_file.empty() && tls.cert_file.empty()) {
    throw InvalidArgument("server.tls.client_ca_file: '" + tls.client_ca_file +
                          "' needs TLS (server.tls.cert_file and key_file)");
  }
  if (tls.require_client_cert && tls.client_ca_file.empty()) {
    throw InvalidArgument("server.tls.require_client_cert: true needs server.tls.client_ca_file");
  }
  if (!tls.cert_file.empty()) RequireReadableFile(tls.cert_file, "server.tls.cert_file");
  if (!tls.key_file.empty()) RequireReadableFile(tls.key_file, "server.tls.key_file");
  if (!tls.client_ca_file.empty()) RequireReadableFile(tls.client_ca_file, "server.tls.client_ca_file");

  for (const std::string& name : ProfileNames()) {
    if (!planning.profiles.count(name)) {
      throw InvalidArgument("planning.profiles: the shipped profile '" + name + "' is missing");
    }
  }
  RequireKnownProfile(planning);
  for (const auto& [name, params] : planning.profiles) {
    try {
      params.Validate();
    } catch (const InvalidArgument& e) {
      throw InvalidArgument("planning.profiles." + name + ": " + e.what());
    }
  }
  if (planning.max_cloud_points < 1) throw InvalidArgument("planning.max_cloud_points: must be >= 1, got 0");
  try {
    planning.simulation.Validate();
  } catch (const InvalidArgument& e) {
    // "trajectory simulation: time_step = 0: expected ..." → "planning.simulation.time_step = 0: ..."
    std::string message = e.what();
    const std::string prefix = "trajectory simulation: ";
    if (message.rfind(prefix, 0) == 0) message = message.substr(prefix.size());
    throw InvalidArgument("planning.simulation." + message);
  }
  try {
    planning.cell.Validate();
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(PrefixCellError(e.what()));
  }
}

std::string_view EmbeddedServerConfigYaml() {
  static const std::string yaml = [] {
    ServerFile defaults;
    defaults.cell = CellConfig{};
    return DumpFields(defaults, kHeader);
  }();
  return yaml;
}

ServerConfig ParseServerConfig(const std::string& yaml_text, const std::string& base_dir) {
  ServerFile file;
  ParseFields(yaml_text, "server config", file);
  ServerConfig config = std::move(file.config);
  ResolveTlsPaths(config.tls, base_dir);
  ApplyParamsFile(file.params_file, base_dir, config.planning);
  ApplyCell(file, base_dir, config.planning.cell);
  config.Validate();
  return config;
}

ServerConfig LoadServerConfig(const std::string& path) {
  std::string text;
  try {
    text = ReadTextFile(path);
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("server config: " + std::string(e.what()));
  }
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  try {
    return ParseServerConfig(text, parent.empty() ? "." : parent.string());
  } catch (const InvalidArgument& e) {
    throw InvalidArgument("server config '" + path + "': " + e.what());
  }
}

}  // namespace tubepick::server

#include "server/server_config.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "core/common/errors.h"
#include "core/common/require.h"
#include "core/common/yaml_reader.h"

namespace tubepick::server {
namespace {

constexpr std::uint64_t kMiB = 1ull << 20;
constexpr std::uint64_t kGiB = 1ull << 30;

// The defaults of every key, documented. Keep in sync with the structs: server_config_test parses
// it and compares every field with a default-constructed ServerConfig.
constexpr std::string_view kEmbeddedYaml =
    R"yaml(# tubepick-server configuration: every key with its default (tubepick-server --config FILE).
# Every key is optional; unknown keys are errors. Units: metres, kilograms, seconds.
# Relative file paths are relative to the directory of this file.

server:
  # gRPC listen address, HOST:PORT; port 0 = any free port; IPv6 as "[::]:50051".
  address: "0.0.0.0:50051"
  # Planning worker threads; 0 = one per hardware thread.
  workers: 0
  # Admitted calls that may wait for a free worker; more are answered RESOURCE_EXHAUSTED. >= 1.
  queue_capacity: 8
  # Largest gRPC message received or sent, bytes, in [1 MiB, 2 GiB): 64 MiB.
  max_message_bytes: 67108864
  # Largest cloud a PlanPickStream header may announce, bytes: 512 MiB.
  max_stream_bytes: 536870912
  # On SIGTERM, in-flight calls get this long to finish before they are cancelled, seconds.
  shutdown_grace: 10.0
  # Prometheus text metrics at http://HOST:PORT/metrics; "" = off.
  metrics_address: "0.0.0.0:9464"
  # trace, debug, info, warn, error, critical or off.
  log_level: info
  # text, or json (one JSON object per line).
  log_format: text
  tls:
    # PEM certificate chain and private key of the server; both empty = plaintext.
    cert_file: ""
    key_file: ""
    # PEM CA bundle client certificates are verified against (mutual TLS); "" = none requested.
    client_ca_file: ""
    # Reject clients without a valid certificate (needs client_ca_file).
    require_client_cert: false

planning:
  # Parameter profile of requests that name none: fast or thesis.
  profile: fast
  # Seed of requests that give none.
  seed: 1
  # A `tubepick params --dump` YAML (complete or partial) that replaces the parameters of the
  # profile above; "" = the compiled-in profile.
  params_file: ""
  # Largest cloud accepted, points (12 bytes each).
  max_cloud_points: 10000000
  # Threads one PlanPick simulates its trajectories on; 0 = one per hardware thread. Calls already
  # run in parallel on the workers, so 1 keeps workers x threads at the core count.
  simulation_threads: 1
  # Trajectory simulation (Bullet). The bin and the tube mass come from the request's cell, the
  # displacement limit from the profile's planning.cost.max_displacement.
  simulation:
    # Speed of the grasped tube along its waypoints, m/s.
    gripper_speed: 0.1
    # Fixed simulation step, s (1/120).
    time_step: 0.008333333333333333
    # Sequential-impulse solver iterations per step.
    solver_iterations: 10
    # Longest settling under gravity before the snapshot, s.
    settle_time: 2.0
    # Settling ends once every tube has stayed below the rest velocities this long, s.
    rest_time: 0.1
    # Rest velocities, m/s and rad/s.
    linear_rest_velocity: 0.01
    angular_rest_velocity: 0.1
    # The grasped tube is held still at its last waypoint this long before measuring, s.
    post_motion_time: 0.5
    # Friction coefficients of tubes and bin; rolling friction of tubes, m.
    tube_friction: 0.7
    bin_friction: 0.7
    tube_rolling_friction: 0.001
    # Restitution of tubes and bin.
    tube_restitution: 0.2
    bin_restitution: 0.5
    # Velocity damping of tubes, fraction lost per second.
    linear_damping: 0.05
    angular_damping: 0.2
    # Collision margin of flat tube ends and bin walls, m.
    collision_margin: 0.001
    # Consecutive cylinders farther apart than this are linked by a joint cylinder, m.
    joint_min_length: 0.001
    # Sleep thresholds of a tube woken during a trajectory, m/s and rad/s; 0 disables sleeping.
    sleep_linear_velocity: 0.02
    sleep_angular_velocity: 0.2
    # Simulated bin wall thickness, m.
    wall_thickness: 0.05

# The cell of requests that carry no CellDescription (the schema of `tubepick --cell FILE`).
# Alternatively cell_file names such a file; give one of the two.
cell_file: ""
cell:
  bin:
    # Inner length (x), width (y) and wall height (z), m.
    inner_size: [0.8, 0.6, 0.2]
  sensor:
    # X_BinSensor: the optical frame (x right, y down, z forward) in the bin frame;
    # 1.1 m above the floor centre looking straight down.
    pose_in_bin:
      position: [0.0, 0.0, 1.1]
      orientation_xyzw: [1.0, 0.0, 0.0, 0.0]
    # Unit of the sensor's clouds (requests with LENGTH_UNIT_UNSPECIFIED): m or mm.
    unit: m
  tube:
    # Radius, curve length (0 = unknown) and mass of one tube, m and kg.
    radius: 0.0125
    length: 0.5
    mass: 0.055
  place:
    # X_BinPlace: the frame a placed tube's PCA frame is aligned with, bin frame.
    pose_in_bin:
      position: [0.0, 0.8, 0.1]
      orientation_xyzw: [0.0, 0.0, 0.0, 1.0]
)yaml";

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

void ReadSimulation(YamlMap& m, physics::TrajectorySimParams& s) {
  m.Read("gripper_speed", s.gripper_speed);
  m.Read("time_step", s.time_step);
  std::uint32_t iterations = static_cast<std::uint32_t>(s.solver_iterations);
  m.Read("solver_iterations", iterations);
  if (iterations > 1000) {
    throw InvalidArgument(m.PathOf("solver_iterations") + ": " + std::to_string(iterations) +
                          " is out of range [1, 1000]");
  }
  s.solver_iterations = static_cast<int>(iterations);
  m.Read("settle_time", s.settle_time);
  m.Read("rest_time", s.rest_time);
  m.Read("linear_rest_velocity", s.linear_rest_velocity);
  m.Read("angular_rest_velocity", s.angular_rest_velocity);
  m.Read("post_motion_time", s.post_motion_time);
  m.Read("tube_friction", s.tube_friction);
  m.Read("bin_friction", s.bin_friction);
  m.Read("tube_rolling_friction", s.tube_rolling_friction);
  m.Read("tube_restitution", s.tube_restitution);
  m.Read("bin_restitution", s.bin_restitution);
  m.Read("linear_damping", s.linear_damping);
  m.Read("angular_damping", s.angular_damping);
  m.Read("collision_margin", s.collision_margin);
  m.Read("joint_min_length", s.joint_min_length);
  m.Read("sleep_linear_velocity", s.sleep_linear_velocity);
  m.Read("sleep_angular_velocity", s.sleep_angular_velocity);
  m.Read("wall_thickness", s.wall_thickness);
  m.RejectUnknown();
}

void ReadServer(YamlMap& m, ServerConfig& c, const std::string& base_dir) {
  m.Read("address", c.address);
  m.Read("workers", c.workers);
  m.Read("queue_capacity", c.queue_capacity);
  m.Read("max_message_bytes", c.max_message_bytes);
  m.Read("max_stream_bytes", c.max_stream_bytes);
  m.Read("shutdown_grace", c.shutdown_grace);
  m.Read("metrics_address", c.metrics_address);
  m.Read("log_level", c.log_level);
  m.Read("log_format", c.log_format);
  {
    YamlMap tls(m.Child("tls"), m.PathOf("tls"));
    tls.Read("cert_file", c.tls.cert_file);
    tls.Read("key_file", c.tls.key_file);
    tls.Read("client_ca_file", c.tls.client_ca_file);
    tls.Read("require_client_cert", c.tls.require_client_cert);
    tls.RejectUnknown();
    c.tls.cert_file = ResolvePath(c.tls.cert_file, base_dir);
    c.tls.key_file = ResolvePath(c.tls.key_file, base_dir);
    c.tls.client_ca_file = ResolvePath(c.tls.client_ca_file, base_dir);
  }
  m.RejectUnknown();
}

void ReadPlanning(YamlMap& m, PlanningDefaults& p, const std::string& base_dir) {
  m.Read("profile", p.profile);
  if (!p.profiles.count(p.profile)) {
    throw InvalidArgument(m.PathOf("profile") + ": unknown profile '" + p.profile +
                          "' (known: " + JoinNames(p.profiles) + ")");
  }
  m.Read("seed", p.seed);
  std::string params_file;
  m.Read("params_file", params_file);
  if (!params_file.empty()) {
    const std::string path = ResolvePath(params_file, base_dir);
    try {
      p.profiles[p.profile] = LoadParams(path, p.profiles.at(p.profile));
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(m.PathOf("params_file") + ": " + e.what());
    }
  }
  m.Read("max_cloud_points", p.max_cloud_points);
  m.Read("simulation_threads", p.simulation_threads);
  {
    YamlMap sim(m.Child("simulation"), m.PathOf("simulation"));
    ReadSimulation(sim, p.simulation);
  }
  m.RejectUnknown();
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
  if (!planning.profiles.count(planning.profile)) {
    throw InvalidArgument("planning.profile: unknown profile '" + planning.profile +
                          "' (known: " + JoinNames(planning.profiles) + ")");
  }
  for (const auto& [name, params] : planning.profiles) {
    try {
      params.Validate();
    } catch (const InvalidArgument& e) {
      throw InvalidArgument("planning.profiles." + name + ": " + e.what());
    }
  }
  if (planning.max_cloud_points < 1) throw InvalidArgument("planning.max_cloud_points: must be >= 1, got 0");
  if (planning.simulation_threads > 1024) {
    throw InvalidArgument("planning.simulation_threads: " + std::to_string(planning.simulation_threads) +
                          " is out of range [0, 1024]");
  }
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

std::string_view EmbeddedServerConfigYaml() { return kEmbeddedYaml; }

ServerConfig ParseServerConfig(const std::string& yaml_text, const std::string& base_dir) {
  const YAML::Node root = ParseYaml(yaml_text, "server config");
  YamlMap top(root, "");
  ServerConfig config;
  {
    YamlMap server(top.Child("server"), "server");
    ReadServer(server, config, base_dir);
  }
  {
    YamlMap planning(top.Child("planning"), "planning");
    ReadPlanning(planning, config.planning, base_dir);
  }
  std::string cell_file;
  top.Read("cell_file", cell_file);
  const bool has_cell = top.Has("cell") && !top.Child("cell").IsNull();
  if (has_cell && !cell_file.empty()) {
    throw InvalidArgument("cell_file: '" + cell_file + "' and a cell section: give one of the two");
  }
  if (has_cell) {
    const YAML::Node cell = top.Child("cell");
    if (!cell.IsMap()) throw InvalidArgument("cell: expected a mapping");
    try {
      config.planning.cell = ParseCellConfig(YAML::Dump(cell));
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(PrefixCellError(e.what()));
    }
  } else if (!cell_file.empty()) {
    try {
      config.planning.cell = LoadCellConfig(ResolvePath(cell_file, base_dir));
    } catch (const InvalidArgument& e) {
      throw InvalidArgument(std::string("cell_file: ") + e.what());
    }
  }
  top.RejectUnknown();
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

#include "server/server_config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/common/errors.h"
#include "core/common/thread_budget.h"
#include "core/testing/error_of.h"

namespace tubepick::server {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;
using tubepick::testing::ErrorOf;
namespace fs = std::filesystem;

std::string ParseError(const std::string& yaml) {
  return ErrorOf([&] { ParseServerConfig(yaml); });
}

// A fresh directory per test under the system temp dir.
fs::path TempDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path dir = fs::temp_directory_path() / (std::string("tubepick_server_config_") + info->name());
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void WriteFile(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path) << text;
}

void ExpectSameSimulation(const physics::TrajectorySimParams& a, const physics::TrajectorySimParams& b) {
  EXPECT_EQ(a.gripper_speed, b.gripper_speed);
  EXPECT_EQ(a.time_step, b.time_step);
  EXPECT_EQ(a.solver_iterations, b.solver_iterations);
  EXPECT_EQ(a.settle_time, b.settle_time);
  EXPECT_EQ(a.rest_time, b.rest_time);
  EXPECT_EQ(a.linear_rest_velocity, b.linear_rest_velocity);
  EXPECT_EQ(a.angular_rest_velocity, b.angular_rest_velocity);
  EXPECT_EQ(a.post_motion_time, b.post_motion_time);
  EXPECT_EQ(a.disp_max, b.disp_max);
  EXPECT_EQ(a.tube_mass, b.tube_mass);
  EXPECT_EQ(a.tube_friction, b.tube_friction);
  EXPECT_EQ(a.bin_friction, b.bin_friction);
  EXPECT_EQ(a.tube_rolling_friction, b.tube_rolling_friction);
  EXPECT_EQ(a.tube_restitution, b.tube_restitution);
  EXPECT_EQ(a.bin_restitution, b.bin_restitution);
  EXPECT_EQ(a.linear_damping, b.linear_damping);
  EXPECT_EQ(a.angular_damping, b.angular_damping);
  EXPECT_EQ(a.collision_margin, b.collision_margin);
  EXPECT_EQ(a.joint_min_length, b.joint_min_length);
  EXPECT_EQ(a.sleep_linear_velocity, b.sleep_linear_velocity);
  EXPECT_EQ(a.sleep_angular_velocity, b.sleep_angular_velocity);
  EXPECT_EQ(a.wall_thickness, b.wall_thickness);
  EXPECT_EQ(a.threads, b.threads);
  EXPECT_EQ(a.bin.inner_size, b.bin.inner_size);
}

void ExpectSameCell(const CellConfig& a, const CellConfig& b) {
  EXPECT_EQ(a.bin.inner_size, b.bin.inner_size);
  // The YAML's quaternion (1, 0, 0, 0) and AngleAxis(π, x) differ by cos(π) round-off.
  EXPECT_TRUE(a.sensor.X_BinSensor.matrix().isApprox(b.sensor.X_BinSensor.matrix(), 1e-12));
  EXPECT_EQ(a.sensor.unit, b.sensor.unit);
  EXPECT_EQ(a.tube.radius, b.tube.radius);
  EXPECT_EQ(a.tube.length, b.tube.length);
  EXPECT_EQ(a.tube.mass, b.tube.mass);
  EXPECT_TRUE(a.place.X_BinPlace.matrix().isApprox(b.place.X_BinPlace.matrix(), 1e-12));
}

void ExpectSameConfig(const ServerConfig& a, const ServerConfig& b) {
  EXPECT_EQ(a.address, b.address);
  EXPECT_EQ(a.workers, b.workers);
  EXPECT_EQ(a.queue_capacity, b.queue_capacity);
  EXPECT_EQ(a.max_message_bytes, b.max_message_bytes);
  EXPECT_EQ(a.max_stream_bytes, b.max_stream_bytes);
  EXPECT_EQ(a.shutdown_grace, b.shutdown_grace);
  EXPECT_EQ(a.metrics_address, b.metrics_address);
  EXPECT_EQ(a.log_level, b.log_level);
  EXPECT_EQ(a.log_format, b.log_format);
  EXPECT_EQ(a.tls.cert_file, b.tls.cert_file);
  EXPECT_EQ(a.tls.key_file, b.tls.key_file);
  EXPECT_EQ(a.tls.client_ca_file, b.tls.client_ca_file);
  EXPECT_EQ(a.tls.require_client_cert, b.tls.require_client_cert);
  EXPECT_EQ(a.planning.profile, b.planning.profile);
  EXPECT_EQ(a.planning.seed, b.planning.seed);
  EXPECT_EQ(a.planning.max_cloud_points, b.planning.max_cloud_points);
  EXPECT_EQ(a.threads_per_call, b.threads_per_call);
  EXPECT_EQ(a.max_uploads, b.max_uploads);
  EXPECT_EQ(a.stream_idle_timeout, b.stream_idle_timeout);
  EXPECT_EQ(a.max_call_time, b.max_call_time);
  EXPECT_EQ(a.resource_quota_bytes, b.resource_quota_bytes);
  EXPECT_EQ(a.connection.keepalive_time, b.connection.keepalive_time);
  EXPECT_EQ(a.connection.keepalive_timeout, b.connection.keepalive_timeout);
  EXPECT_EQ(a.connection.min_client_ping_interval, b.connection.min_client_ping_interval);
  EXPECT_EQ(a.connection.max_idle, b.connection.max_idle);
  EXPECT_EQ(a.connection.max_age, b.connection.max_age);
  EXPECT_EQ(a.connection.max_age_grace, b.connection.max_age_grace);
  EXPECT_EQ(a.connection.max_concurrent_streams, b.connection.max_concurrent_streams);
  ASSERT_EQ(a.planning.profiles.size(), b.planning.profiles.size());
  for (const auto& [name, params] : a.planning.profiles) {
    ASSERT_TRUE(b.planning.profiles.count(name)) << name;
    EXPECT_EQ(DumpParams(params), DumpParams(b.planning.profiles.at(name))) << name;
  }
  ExpectSameSimulation(a.planning.simulation, b.planning.simulation);
  ExpectSameCell(a.planning.cell, b.planning.cell);
}

TEST(ServerConfig, DefaultsHaveBothProfilesAndValidate) {
  const ServerConfig config;
  EXPECT_NO_THROW(config.Validate());
  ASSERT_EQ(config.planning.profiles.size(), 2u);
  EXPECT_EQ(DumpParams(config.planning.profiles.at("fast")), DumpParams(ProfileParams("fast")));
  EXPECT_EQ(DumpParams(config.planning.profiles.at("thesis")), DumpParams(ProfileParams("thesis")));
  EXPECT_EQ(config.max_message_bytes, 64u << 20);
}

TEST(ServerConfig, DefaultsListenOnLoopbackOnly) {
  // A server started with no config must not be reachable from the plant network by accident.
  const ServerConfig config;
  EXPECT_EQ(config.address, "127.0.0.1:50051");
  EXPECT_EQ(config.metrics_address, "127.0.0.1:9464");
  EXPECT_TRUE(config.reflection);
  const ServerConfig embedded = ParseServerConfig(std::string(EmbeddedServerConfigYaml()), ".");
  EXPECT_EQ(embedded.address, "127.0.0.1:50051");
  EXPECT_EQ(embedded.metrics_address, "127.0.0.1:9464");
}

TEST(ServerConfig, EmbeddedYamlParsesToExactlyTheDefaults) {
  const std::string yaml(EmbeddedServerConfigYaml());
  // Every section is spelled out (an operator copies it as a template).
  for (const char* key : {"server:", "tls:", "planning:", "simulation:", "cell:", "cell_file:",
                          "pose_in_bin:", "wall_thickness:", "require_client_cert:", "threads_per_call:",
                          "stream_idle_timeout:", "connection:", "keepalive_time:"}) {
    EXPECT_THAT(yaml, HasSubstr(key));
  }
  ExpectSameConfig(ParseServerConfig(yaml), ServerConfig{});
}

TEST(ServerConfig, EmptyDocumentGivesTheDefaults) {
  ExpectSameConfig(ParseServerConfig(""), ServerConfig{});
  ExpectSameConfig(ParseServerConfig("{}"), ServerConfig{});
}

TEST(ServerConfig, ReadsEveryServerKey) {
  const fs::path dir = TempDir();
  WriteFile(dir / "tls/server.pem", "cert");
  WriteFile(dir / "tls/server.key", "key");
  WriteFile(dir / "tls/ca.pem", "ca");
  const ServerConfig c = ParseServerConfig(R"(
server:
  address: "[::1]:6000"
  workers: 3
  queue_capacity: 2
  max_message_bytes: 2097152
  max_stream_bytes: 1200
  shutdown_grace: 2.5
  threads_per_call: 2
  max_uploads: 3
  stream_idle_timeout: 4.5
  max_call_time: 30
  resource_quota_bytes: 8388608
  connection: {keepalive_time: 20, max_idle: 60, max_concurrent_streams: 4}
  metrics_address: ""
  reflection: false
  log_level: debug
  log_format: json
  tls: {cert_file: tls/server.pem, key_file: tls/server.key, client_ca_file: tls/ca.pem,
        require_client_cert: true}
planning:
  profile: thesis
  seed: 99
  max_cloud_points: 1000
  simulation: {gripper_speed: 0.2, solver_iterations: 20, wall_thickness: 0.1}
)",
                                           dir.string());
  EXPECT_EQ(c.address, "[::1]:6000");
  EXPECT_FALSE(c.reflection);
  EXPECT_EQ(c.workers, 3u);
  EXPECT_EQ(c.queue_capacity, 2u);
  EXPECT_EQ(c.max_message_bytes, 2097152u);
  EXPECT_EQ(c.max_stream_bytes, 1200u);
  EXPECT_EQ(c.shutdown_grace, 2.5);
  EXPECT_EQ(c.metrics_address, "");
  EXPECT_EQ(c.log_level, "debug");
  EXPECT_EQ(c.log_format, "json");
  EXPECT_TRUE(c.tls.enabled());
  // Relative paths are resolved against the config's directory.
  EXPECT_EQ(fs::path(c.tls.cert_file), dir / "tls/server.pem");
  EXPECT_EQ(fs::path(c.tls.key_file), dir / "tls/server.key");
  EXPECT_EQ(fs::path(c.tls.client_ca_file), dir / "tls/ca.pem");
  EXPECT_TRUE(c.tls.require_client_cert);
  EXPECT_EQ(c.planning.profile, "thesis");
  EXPECT_EQ(c.planning.seed, 99u);
  EXPECT_EQ(c.planning.max_cloud_points, 1000u);
  EXPECT_EQ(c.threads_per_call, 2u);
  EXPECT_EQ(c.max_uploads, 3u);
  EXPECT_EQ(c.stream_idle_timeout, 4.5);
  EXPECT_EQ(c.max_call_time, 30.0);
  EXPECT_EQ(c.resource_quota_bytes, 8388608u);
  EXPECT_EQ(c.connection.keepalive_time, 20.0);
  EXPECT_EQ(c.connection.max_idle, 60.0);
  EXPECT_EQ(c.connection.max_concurrent_streams, 4u);
  EXPECT_EQ(c.connection.max_age, ConnectionLimits{}.max_age);
  EXPECT_EQ(c.planning.simulation.gripper_speed, 0.2);
  EXPECT_EQ(c.planning.simulation.solver_iterations, 20);
  EXPECT_EQ(c.planning.simulation.wall_thickness, 0.1);
  EXPECT_EQ(c.planning.simulation.time_step, physics::TrajectorySimParams{}.time_step);
}

TEST(ServerConfig, DebugKeepsNoCallsByDefaultAndNeedsTheHttpPort) {
  EXPECT_EQ(ServerConfig{}.debug.keep_last, 0u);
  EXPECT_THAT(std::string(EmbeddedServerConfigYaml()), HasSubstr("keep_last: 0"));
  const ServerConfig c = ParseServerConfig("debug: {keep_last: 20, max_points: 50000}\n");
  EXPECT_EQ(c.debug.keep_last, 20u);
  EXPECT_EQ(c.debug.max_points, 50000u);
  EXPECT_THAT(ParseError("debug: {keep_last: 5}\nserver: {metrics_address: \"\"}\n"),
              HasSubstr("debug.keep_last: 5 needs server.metrics_address"));
  EXPECT_THAT(ParseError("debug: {keep_last: 1001}"), HasSubstr("debug.keep_last: 1001 is out of range"));
  EXPECT_THAT(ParseError("debug: {max_points: 10}"), HasSubstr("debug.max_points: 10 is out of range"));
  EXPECT_THAT(ParseError("debug: {keep: 5}"), HasSubstr("debug.keep"));
}

TEST(ServerConfig, ThreadBudgetSplitsTheAvailableCoresAmongWorkers) {
  ServerConfig c;
  c.workers = 0;
  EXPECT_EQ(WorkerCount(c), static_cast<std::uint32_t>(CoresAvailable()));
  EXPECT_EQ(ThreadsPerCall(c), 1u);  // one worker per core, one thread each
  c.workers = 1;
  EXPECT_EQ(ThreadsPerCall(c), static_cast<std::uint32_t>(CoresAvailable()));
  c.workers = 4 * static_cast<std::uint32_t>(CoresAvailable());
  EXPECT_EQ(ThreadsPerCall(c), 1u);  // more workers than cores: never 0
  c.threads_per_call = 3;
  EXPECT_EQ(ThreadsPerCall(c), 3u);  // an explicit budget is kept
}

TEST(ServerConfig, UnknownKeysAreErrorsWithTheirPath) {
  EXPECT_THAT(ParseError("server: {adress: 'x:1'}"), HasSubstr("server.adress"));
  EXPECT_THAT(ParseError("server: {tls: {cert: a}}"), HasSubstr("server.tls.cert"));
  EXPECT_THAT(ParseError("planning: {simulation: {tube_mass: 1.0}}"),
              HasSubstr("planning.simulation.tube_mass"));
  EXPECT_THAT(ParseError("planning: {simulation: {bin: {}}}"), HasSubstr("planning.simulation.bin"));
  EXPECT_THAT(ParseError("planning: {simulation: {disp_max: 1}}"), HasSubstr("planning.simulation.disp_max"));
  EXPECT_THAT(ParseError("planning: {simulation: {threads: 2}}"), HasSubstr("planning.simulation.threads"));
  EXPECT_THAT(ParseError("planning: {profiles: {}}"), HasSubstr("planning.profiles"));
  EXPECT_THAT(ParseError("serverr: {}"), HasSubstr("serverr"));
  EXPECT_THAT(ParseError("cell: {tube: {colour: red}}"), HasSubstr("cell.tube.colour"));
}

TEST(ServerConfig, WrongTypesNameTheKey) {
  EXPECT_THAT(ParseError("server: {workers: many}"), AllOf(HasSubstr("server.workers"), HasSubstr("many")));
  EXPECT_THAT(ParseError("server: {queue_capacity: -1}"), HasSubstr("server.queue_capacity"));
  EXPECT_THAT(ParseError("server: {tls: {require_client_cert: maybe}}"),
              HasSubstr("server.tls.require_client_cert"));
  EXPECT_THAT(ParseError("planning: {simulation: {time_step: .nan}}"),
              HasSubstr("planning.simulation.time_step"));
  EXPECT_THAT(ParseError("server: [1, 2]"), HasSubstr("server: expected a mapping"));
  EXPECT_THAT(ParseError("server: {address: [1}"), HasSubstr("YAML syntax error"));
}

TEST(ServerConfig, AddressesAreHostPort) {
  for (const char* ok :
       {"0.0.0.0:50051", "localhost:0", "[::]:50051", "[::1]:1", "tubepick-server.local:65535"}) {
    ServerConfig c;
    c.address = ok;
    EXPECT_NO_THROW(c.Validate()) << ok;
  }
  for (const char* bad :
       {"localhost", ":50051", "host:", "host:65536", "host:12a", "a b:1", "[::1:5", "[]:1"}) {
    ServerConfig c;
    c.address = bad;
    EXPECT_THAT(ErrorOf([&] { c.Validate(); }), AllOf(HasSubstr("server.address"), HasSubstr(bad))) << bad;
  }
  EXPECT_THAT(ParseError("server: {metrics_address: 'nope'}"), HasSubstr("server.metrics_address"));
}

TEST(ServerConfig, RangeChecksNameTheKeyAndValue) {
  EXPECT_THAT(ParseError("server: {queue_capacity: 0}"),
              AllOf(HasSubstr("server.queue_capacity"), HasSubstr("0")));
  EXPECT_THAT(ParseError("server: {max_message_bytes: 1000}"),
              AllOf(HasSubstr("server.max_message_bytes"), HasSubstr("1000")));
  EXPECT_THAT(ParseError("server: {max_message_bytes: 2147483648}"),
              AllOf(HasSubstr("server.max_message_bytes"), HasSubstr("2147483648")));
  EXPECT_NO_THROW(ParseServerConfig("server: {max_message_bytes: 1048576}"));
  EXPECT_NO_THROW(
      ParseServerConfig("server: {max_message_bytes: 2147483647, resource_quota_bytes: 4294967296}"));
  EXPECT_THAT(ParseError("server: {max_stream_bytes: 11}"), HasSubstr("server.max_stream_bytes"));
  EXPECT_THAT(ParseError("server: {workers: 5000}"), HasSubstr("server.workers"));
  EXPECT_THAT(ParseError("server: {shutdown_grace: -1}"), HasSubstr("server.shutdown_grace"));
  EXPECT_THAT(ParseError("server: {log_level: verbose}"),
              AllOf(HasSubstr("server.log_level"), HasSubstr("verbose")));
  EXPECT_THAT(ParseError("server: {log_format: xml}"),
              AllOf(HasSubstr("server.log_format"), HasSubstr("xml")));
  EXPECT_THAT(ParseError("planning: {max_cloud_points: 0}"), HasSubstr("planning.max_cloud_points"));
  EXPECT_THAT(ParseError("server: {threads_per_call: 2000}"), HasSubstr("server.threads_per_call"));
  EXPECT_THAT(ParseError("server: {max_uploads: 0}"), HasSubstr("server.max_uploads"));
  EXPECT_THAT(ParseError("server: {stream_idle_timeout: 0}"), HasSubstr("server.stream_idle_timeout"));
  EXPECT_THAT(ParseError("server: {max_call_time: -1}"), HasSubstr("server.max_call_time"));
  EXPECT_THAT(ParseError("server: {resource_quota_bytes: 1048575}"),
              AllOf(HasSubstr("server.resource_quota_bytes"), HasSubstr("max_message_bytes")));
  EXPECT_THAT(ParseError("server: {connection: {keepalive_timeout: 0}}"),
              HasSubstr("server.connection.keepalive_timeout"));
  EXPECT_THAT(ParseError("server: {connection: {max_concurrent_streams: 0}}"),
              HasSubstr("server.connection.max_concurrent_streams"));
  EXPECT_THAT(ParseError("server: {connection: {keepalive: 1}}"), HasSubstr("server.connection.keepalive"));
  // The per-call thread budget replaced planning.simulation_threads.
  EXPECT_THAT(ParseError("planning: {simulation_threads: 2}"), HasSubstr("planning.simulation_threads"));
  EXPECT_THAT(ParseError("planning: {simulation: {time_step: 0}}"),
              AllOf(HasSubstr("planning.simulation.time_step"), HasSubstr("0")));
  EXPECT_THAT(ParseError("planning: {simulation: {solver_iterations: 0}}"),
              HasSubstr("planning.simulation.solver_iterations"));
  EXPECT_THAT(ParseError("planning: {simulation: {solver_iterations: 5000}}"),
              HasSubstr("planning.simulation.solver_iterations"));
}

TEST(ServerConfig, TlsNeedsCertAndKeyAndMutualTlsNeedsACa) {
  const fs::path dir = TempDir();
  WriteFile(dir / "a.pem", "x");
  const std::string pem = (dir / "a.pem").string();
  EXPECT_THAT(ParseError("server: {tls: {cert_file: " + pem + "}}"), HasSubstr("server.tls.key_file"));
  EXPECT_THAT(ParseError("server: {tls: {key_file: " + pem + "}}"), HasSubstr("server.tls.cert_file"));
  EXPECT_THAT(ParseError("server: {tls: {client_ca_file: " + pem + "}}"),
              HasSubstr("server.tls.client_ca_file"));
  EXPECT_THAT(
      ParseError("server: {tls: {cert_file: " + pem + ", key_file: " + pem + ", require_client_cert: true}}"),
      HasSubstr("server.tls.require_client_cert"));
  EXPECT_THAT(ParseError("server: {tls: {cert_file: " + pem + ", key_file: missing.key}}"),
              AllOf(HasSubstr("server.tls.key_file"), HasSubstr("missing.key")));
  const ServerConfig c = ParseServerConfig("server: {tls: {cert_file: " + pem + ", key_file: " + pem +
                                           ", client_ca_file: " + pem + "}}");
  EXPECT_TRUE(c.tls.enabled());
  EXPECT_FALSE(c.tls.require_client_cert);
}

TEST(ServerConfig, UnknownProfileListsTheKnownOnes) {
  EXPECT_THAT(ParseError("planning: {profile: slow}"),
              AllOf(HasSubstr("planning.profile"), HasSubstr("'slow'"), HasSubstr("fast, thesis")));
  ServerConfig c;
  c.planning.profile = "slow";
  EXPECT_THAT(ErrorOf([&] { c.Validate(); }), HasSubstr("planning.profile"));
  c = ServerConfig{};
  c.planning.profiles.erase("thesis");
  EXPECT_THAT(ErrorOf([&] { c.Validate(); }), AllOf(HasSubstr("planning.profiles"), HasSubstr("thesis")));
}

TEST(ServerConfig, ParamsFileReplacesTheDefaultProfile) {
  const fs::path dir = TempDir();
  Params params = ProfileParams("thesis");
  params.planning.max_plans = 7;
  params.wrench.force_tolerance = 0.3;
  WriteFile(dir / "params/thesis.yaml", DumpParams(params));
  WriteFile(dir / "partial.yaml", "planning: {max_plans: 3}\n");

  const ServerConfig thesis =
      ParseServerConfig("planning: {profile: thesis, params_file: params/thesis.yaml}", dir.string());
  EXPECT_EQ(DumpParams(thesis.planning.profiles.at("thesis")), DumpParams(params));
  EXPECT_EQ(DumpParams(thesis.planning.profiles.at("fast")), DumpParams(ProfileParams("fast")));

  // A partial file overrides the named profile's compiled-in values.
  const ServerConfig fast = ParseServerConfig("planning: {params_file: partial.yaml}", dir.string());
  Params expected = ProfileParams("fast");
  expected.planning.max_plans = 3;
  EXPECT_EQ(DumpParams(fast.planning.profiles.at("fast")), DumpParams(expected));

  WriteFile(dir / "bad.yaml", "planning: {grasps: {spacing: -1}}\n");
  EXPECT_THAT(ErrorOf([&] { ParseServerConfig("planning: {params_file: bad.yaml}", dir.string()); }),
              AllOf(HasSubstr("planning.params_file"), HasSubstr("planning.grasps.spacing")));
  EXPECT_THAT(ErrorOf([&] { ParseServerConfig("planning: {params_file: none.yaml}", dir.string()); }),
              AllOf(HasSubstr("planning.params_file"), HasSubstr("none.yaml")));
}

TEST(ServerConfig, CellSectionUsesTheCellSchema) {
  const ServerConfig c = ParseServerConfig(R"(
cell:
  bin: {inner_size: [0.6, 0.4, 0.3]}
  sensor: {unit: mm}
  tube: {radius: 0.01, length: 0.3, mass: 0.04}
)");
  EXPECT_EQ(c.planning.cell.bin.inner_size, Eigen::Vector3d(0.6, 0.4, 0.3));
  EXPECT_EQ(c.planning.cell.sensor.unit, LengthUnit::kMillimetre);
  EXPECT_EQ(c.planning.cell.tube.radius, 0.01);
  EXPECT_EQ(c.planning.cell.tube.length, 0.3);
  EXPECT_EQ(c.planning.cell.tube.mass, 0.04);
  EXPECT_THAT(ParseError("cell: {tube: {radius: -0.01}}"), HasSubstr("cell.tube.radius"));
  EXPECT_THAT(ParseError("cell: {sensor: {unit: inch}}"),
              AllOf(HasSubstr("cell.sensor.unit"), HasSubstr("inch")));
  EXPECT_THAT(ParseError("cell: {sensor: {pose_in_bin: {orientation_xyzw: [0, 0, 0, 0]}}}"),
              HasSubstr("cell.sensor.pose_in_bin.orientation_xyzw"));
  EXPECT_THAT(ParseError("cell: 3"), HasSubstr("cell"));
}

TEST(ServerConfig, CellFileIsRelativeToTheConfigAndExcludesTheSection) {
  const fs::path dir = TempDir();
  WriteFile(dir / "cells/small.yaml", "tube: {radius: 0.008, mass: 0.02}\n");
  WriteFile(dir / "server.yaml", "cell_file: cells/small.yaml\nserver: {address: 'localhost:0'}\n");
  const ServerConfig c = LoadServerConfig((dir / "server.yaml").string());
  EXPECT_EQ(c.address, "localhost:0");
  EXPECT_EQ(c.planning.cell.tube.radius, 0.008);
  EXPECT_EQ(c.planning.cell.tube.mass, 0.02);

  WriteFile(dir / "both.yaml", "cell_file: cells/small.yaml\ncell: {tube: {radius: 0.01}}\n");
  EXPECT_THAT(ErrorOf([&] { LoadServerConfig((dir / "both.yaml").string()); }),
              AllOf(HasSubstr("both.yaml"), HasSubstr("cell_file"), HasSubstr("one of the two")));
  WriteFile(dir / "bad_cell.yaml", "tube: {radius: 5}\n");
  EXPECT_THAT(ErrorOf([&] { ParseServerConfig("cell_file: bad_cell.yaml", dir.string()); }),
              AllOf(HasSubstr("cell_file"), HasSubstr("tube.radius")));
  EXPECT_THAT(ErrorOf([&] { LoadServerConfig((dir / "absent.yaml").string()); }), HasSubstr("absent.yaml"));
}

TEST(ServerConfig, LoadedEmbeddedYamlEqualsTheDefaults) {
  const fs::path dir = TempDir();
  WriteFile(dir / "server.yaml", std::string(EmbeddedServerConfigYaml()));
  ExpectSameConfig(LoadServerConfig((dir / "server.yaml").string()), ServerConfig{});
}

}  // namespace
}  // namespace tubepick::server

#include "clients/cli/remote/request_command.h"

#include <fmt/core.h>

#include <memory>
#include <optional>

#include "clients/cli/inputs/builtin_scene.h"
#include "clients/cli/inputs/cli_inputs.h"
#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"
#include "tubepick/v1/requests.pb.h"
#include "tubepick/v1/wrench.pb.h"
#include "wire/cloud_stream.h"
#include "wire/packed_cloud.h"
#include "wire/proto_convert.h"

namespace tubepick::cli {
namespace {

struct RequestOptions {
  std::string kind;
  std::string cloud_path;
  std::string unit;
  std::string cell_path;
  std::uint32_t tubes = 10;
  std::uint32_t every = 1;
  std::uint64_t seed = 0;
  bool seed_given = false;
  std::string profile;
  bool no_sim = false;
  std::uint32_t max_plans = 0;
  std::uint32_t held = 2;
  std::size_t chunk_kib = 1024;
  std::optional<double> tube_mass;
  std::string variant;
  std::string out_path;
};

/// Fills the cloud, cell and options shared by ModelTubesRequest and PlanPickRequest.
template <typename Request>
std::string FillPlanningRequest(const RequestOptions& o, const CellConfig& cell, Request* request) {
  Points points;
  v1::LengthUnit unit = v1::LENGTH_UNIT_UNSPECIFIED;
  std::string source;
  if (o.cloud_path.empty()) {
    BuiltInScene scene = MakeBuiltInScene(cell, o.tubes, o.seed);
    points = std::move(scene.points_Sensor);
    unit = v1::LENGTH_UNIT_METRE;  // the virtual scanner works in metres
    source = scene.description;
  } else {
    CloudFile file = ReadCloudFile(o.cloud_path);
    points = std::move(file.points);
    if (!o.unit.empty())
      unit = ParseLengthUnit(o.unit, "--unit") == LengthUnit::kMillimetre ? v1::LENGTH_UNIT_MILLIMETRE
                                                                          : v1::LENGTH_UNIT_METRE;
    source = o.cloud_path;
  }
  if (o.every > 1) {  // deterministic thinning: keep every K-th scanner return
    Points kept;
    kept.reserve(points.size() / o.every + 1);
    for (std::size_t i = 0; i < points.size(); i += o.every) kept.push_back(points[i]);
    points = std::move(kept);
  }
  request->mutable_cloud()->set_xyz(PackXyz(points));
  request->mutable_cloud()->set_unit(unit);
  if (!o.cell_path.empty()) *request->mutable_cell() = ToCellDescription(cell, cell.sensor.X_BinSensor);
  v1::PlanningOptions* options = request->mutable_options();
  options->set_profile(o.profile);
  if (o.seed_given) options->set_seed(o.seed);
  options->set_disable_simulation(o.no_sim);
  options->set_max_plans(o.max_plans);
  return fmt::format("{} points from {}", points.size(), source);
}

v1::AnalyzeWrenchRequest MakeWrenchRequest(const RequestOptions& o, const CellConfig& cell) {
  // Readings in the TCP-aligned sensor frame with +z up at lift time (WrenchParams::up_Tcp
  // default): holding weight lowers F_z by mass·g per tube; two or more tubes hanging from
  // one grasp also pull the torque sideways.
  constexpr double kGravity = 9.81;
  constexpr double kReferenceFz = 4.0;  // N, the empty gripper's reading (sensor bias)
  const double mass = o.tube_mass.value_or(cell.tube.mass);
  v1::AnalyzeWrenchRequest r;
  r.mutable_reference()->mutable_force()->set_z(kReferenceFz);
  r.mutable_current()->mutable_force()->set_z(kReferenceFz - o.held * mass * kGravity);
  if (o.held >= 2) {
    r.mutable_current()->mutable_torque()->set_x(0.012 * (o.held - 1));
    r.mutable_current()->mutable_torque()->set_y(-0.008 * (o.held - 1));
  }
  if (o.tube_mass) r.set_tube_mass(*o.tube_mass);
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
  X_BinTcp.translation() = Eigen::Vector3d(0.05, -0.02, 0.45);
  *r.mutable_tcp_pose() = ToProto(X_BinTcp);
  if (!o.variant.empty()) {
    v1::ResolutionVariant variant = v1::RESOLUTION_VARIANT_UNSPECIFIED;
    if (!v1::ResolutionVariant_Parse("RESOLUTION_VARIANT_" + o.variant, &variant))
      throw InvalidArgument("--variant: unknown '" + o.variant + "'");
    r.set_variant(variant);
  }
  return r;
}

void Run(const RequestOptions& o) {
  const CellConfig cell = o.cell_path.empty() ? CellConfig{} : LoadCellConfig(o.cell_path);
  std::string json;
  std::string what;
  if (o.kind == "model") {
    v1::ModelTubesRequest request;
    what = FillPlanningRequest(o, cell, &request);
    json = ToJson(request, /*pretty=*/false);
  } else if (o.kind == "plan") {
    v1::PlanPickRequest request;
    what = FillPlanningRequest(o, cell, &request);
    json = ToJson(request, /*pretty=*/false);
  } else if (o.kind == "plan-stream") {
    // The PlanPickStream messages one JSON document a line: the header (the request without its
    // cloud bytes, the size, the chunk count, the CRC-32C), then the chunks in index order.
    v1::PlanPickRequest request;
    what = FillPlanningRequest(o, cell, &request);
    const std::string xyz = std::move(*request.mutable_cloud()->mutable_xyz());
    const std::vector<v1::PlanPickStreamRequest> messages =
        SplitCloudStream(request, xyz, o.chunk_kib * 1024);
    for (const v1::PlanPickStreamRequest& message : messages)
      json += (json.empty() ? "" : "\n") + ToJson(message, /*pretty=*/false);
    const std::size_t chunks = messages.size() - 1;
    what += fmt::format(", {} chunks", chunks);
  } else {
    const v1::AnalyzeWrenchRequest request = MakeWrenchRequest(o, cell);
    what = fmt::format("{} tube(s) held", o.held);
    json = ToJson(request, /*pretty=*/true);
  }
  WriteTextFile(o.out_path, json + "\n");
  fmt::print("wrote {} request ({}) to {}\n", o.kind, what, o.out_path);
}

}  // namespace

void AddRequestCommand(CLI::App& app) {
  auto o = std::make_shared<RequestOptions>();
  CLI::App* cmd =
      app.add_subcommand("request", "Write a PickPlannerService request as proto3 JSON (for buf curl)");
  cmd->add_option("kind", o->kind,
                  "model (ModelTubes), plan (PlanPick), plan-stream (PlanPickStream messages) or wrench "
                  "(AnalyzeWrench)")
      ->required()
      ->check(CLI::IsMember({"model", "plan", "plan-stream", "wrench"}));
  cmd->add_option("--out", o->out_path, "JSON file to write")->required();
  cmd->add_option("--cloud", o->cloud_path, "PLY or PCD cloud (default: the built-in scene)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--unit", o->unit,
                  "PointCloud.unit of --cloud (default: unspecified = the server's cell unit)")
      ->check(CLI::IsMember({"m", "mm"}));
  cmd->add_option("--tubes", o->tubes, "Tubes in the built-in scene")
      ->check(CLI::Range(1, 30))
      ->capture_default_str();
  cmd->add_option("--every", o->every, "Keep every K-th point only (smaller requests for examples)")
      ->check(CLI::Range(1, 1000))
      ->capture_default_str();
  auto* seed = cmd->add_option("--seed", o->seed, "Seed of the built-in scene and PlanningOptions.seed");
  cmd->add_option("--profile", o->profile, "PlanningOptions.profile (default: the server's)")
      ->check(CLI::IsMember({"fast", "thesis"}));
  cmd->add_flag("--no-sim", o->no_sim, "PlanningOptions.disable_simulation");
  cmd->add_option("--max-plans", o->max_plans, "PlanningOptions.max_plans (0 = all)");
  cmd->add_option("--cell", o->cell_path, "Cell YAML: sent as the request's CellDescription")
      ->check(CLI::ExistingFile);
  cmd->add_option("--chunk-kib", o->chunk_kib, "plan-stream: chunk size, KiB")
      ->check(CLI::Range(1, 65536))
      ->capture_default_str();
  cmd->add_option("--held", o->held, "wrench: tubes held after the lift (0 = none)")
      ->check(CLI::Range(0, 10))
      ->capture_default_str();
  cmd->add_option_function<double>(
      "--tube-mass", [o](double m) { o->tube_mass = m; },
      "wrench: AnalyzeWrenchRequest.tube_mass, kg (default: the server's cell)");
  cmd->add_option("--variant", o->variant, "wrench: resolution variant")
      ->check(CLI::IsMember({"TORQUE_AXIS", "TORQUE_AXIS_NEGATIVE", "PERPENDICULAR", "JOINT_SAFE",
                             "TORQUE_AXIS_THEN_PERPENDICULAR"}));
  cmd->callback([o, seed] {
    o->seed_given = seed->count() > 0;
    Run(*o);
  });
}

}  // namespace tubepick::cli

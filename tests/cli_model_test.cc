// End-to-end: the `tubepick` binary on files, as an integrator would run it.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "tests/cli_test_support.h"

#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/modeling/cloud_io.h"
#include "core/testing/synthetic_cloud.h"

namespace tubepick {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

using testing::CliRun;
using testing::ReadJson;
using testing::ReadText;
using testing::RunCli;
using testing::TempDir;

TEST(CliModel, ModelsAPlyFileAndWritesProtoJson) {
  const fs::path dir = TempDir("ply");
  const auto cloud =
      testing::RenderSyntheticCloud({testing::FloorTube({{-0.2, 0.0}, {0.2, 0.0}}),
                                     testing::FloorTube({{0.0, -0.18}, {0.0, 0.18}}, 0.0125, 0.025)},
                                    {});
  WritePly((dir / "scene.ply").string(), cloud.points_Sensor);
  const CliRun run = RunCli("model --cloud " + (dir / "scene.ply").string() + " --cell " +
                            TUBEPICK_SOURCE_DIR + "/deploy/cell.example.yaml --seed 3 --json " +
                            (dir / "out.json").string() + " --dump-stages " + (dir / "stages").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json j = ReadJson(dir / "out.json");
  ASSERT_EQ(j["tubes"].size(), 2u) << run.output;
  EXPECT_EQ(j["profile"], "fast");
  EXPECT_EQ(j["seed"], "3");  // proto3 JSON writes uint64 as a string
  EXPECT_EQ(j["tubes"][0]["occlusion"], "OCCLUSION_UNSPECIFIED");
  EXPECT_GT(j["tubes"][0]["length"].get<double>(), 0.3);
  EXPECT_EQ(j["stageTimings"].size(), 6u);
  EXPECT_EQ(j["stepCounts"][0]["step"], "input");
  EXPECT_TRUE(fs::exists(dir / "stages" / "2_segments.ply"));
  EXPECT_TRUE(fs::exists(dir / "stages" / "3_tubes.ply"));
  fs::remove_all(dir);
}

TEST(CliModel, MillimetrePcdGivesSameTubesAsMetrePly) {
  const fs::path dir = TempDir("mm");
  auto cloud =
      testing::RenderSyntheticCloud({testing::FloorTube({{-0.2, -0.05}, {0.0, 0.0}, {0.2, 0.05}})}, {});
  WritePly((dir / "m.ply").string(), cloud.points_Sensor);
  for (auto& p : cloud.points_Sensor) p *= 1000.0f;
  WritePcd((dir / "mm.pcd").string(), cloud.points_Sensor, true);
  ASSERT_EQ(
      RunCli("model --cloud " + (dir / "m.ply").string() + " --json " + (dir / "m.json").string()).exit_code,
      0);
  ASSERT_EQ(
      RunCli("model --cloud " + (dir / "mm.pcd").string() + " --unit mm --json " + (dir / "mm.json").string())
          .exit_code,
      0);
  const auto a = ReadJson(dir / "m.json"), b = ReadJson(dir / "mm.json");
  ASSERT_EQ(a["tubes"].size(), 1u);
  ASSERT_EQ(b["tubes"].size(), 1u);
  EXPECT_NEAR(a["tubes"][0]["length"].get<double>(), b["tubes"][0]["length"].get<double>(), 1e-3);
  fs::remove_all(dir);
}

TEST(CliModel, BadInputsGiveClearErrors) {
  const fs::path dir = TempDir("bad");
  { std::ofstream(dir / "junk.ply") << "this is not a cloud\n"; }
  CliRun run = RunCli("model --cloud " + (dir / "junk.ply").string());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, HasSubstr("junk.ply"));
  { std::ofstream(dir / "params.yaml") << "modeling:\n  cylinders:\n    min_radius: 0.5\n"; }
  run = RunCli("params --params " + (dir / "params.yaml").string() + " --dump");
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_THAT(run.output, HasSubstr("modeling.cylinders.min_radius"));
  run = RunCli("model --profile turbo");
  EXPECT_NE(run.exit_code, 0);
  fs::remove_all(dir);
}

TEST(CliModel, ViewRefusesAJsonThatIsNotAResponseOfItsCloud) {
  const fs::path dir = TempDir("view");
  { std::ofstream(dir / "bad.json") << "{\"plans\": 3}\n"; }
  CliRun run =
      RunCli("view --tubes 2 --plan " + (dir / "bad.json").string() + " --out " + (dir / "p.html").string());
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("bad.json is not a PlanPickResponse in proto3 JSON"));
  // A model of one cloud over another: refused, naming both sizes.
  ASSERT_EQ(RunCli("model --tubes 2 --seed 1 --json " + (dir / "m.json").string()).exit_code, 0);
  run = RunCli("view --tubes 2 --seed 2 --model " + (dir / "m.json").string() + " --out " +
               (dir / "p.html").string());
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_THAT(run.output, HasSubstr("m.json was made from a cloud of"));
  EXPECT_FALSE(fs::exists(dir / "p.html"));
  fs::remove_all(dir);
}

TEST(CliModel, ACloudThatMissesTheBinIsExitCode4NeverBinEmpty) {
  const fs::path dir = TempDir("misfit");
  const auto cloud =
      testing::RenderSyntheticCloud({testing::FloorTube({{-0.2, 0.0}, {0.2, 0.0}})}, {.pixel_angle = 0.002});
  WritePly((dir / "m.ply").string(), cloud.points_Sensor);  // metres
  for (const std::string command : {"model", "plan"}) {
    // Metres read as millimetres: the cloud shrinks to 1 mm at the sensor.
    CliRun run = RunCli(command + " --cloud " + (dir / "m.ply").string() + " --unit mm");
    EXPECT_EQ(run.exit_code, 4) << run.output;
    EXPECT_THAT(run.output, HasSubstr("error: cloud does not fit the cell: 0 of "));
    EXPECT_THAT(run.output, HasSubstr("is the unit m rather than mm (cloud.unit / --unit)?"));
    EXPECT_THAT(run.output, ::testing::Not(HasSubstr("BIN EMPTY")));
  }
  // A cell whose sensor pose is 0.5 m too high.
  {
    std::ofstream(dir / "cell.yaml") << "sensor:\n  pose_in_bin:\n    position: [0, 0, 1.6]\n"
                                        "    orientation_xyzw: [1, 0, 0, 0]\n";
  }
  CliRun run = RunCli("plan --cloud " + (dir / "m.ply").string() + " --cell " + (dir / "cell.yaml").string());
  EXPECT_EQ(run.exit_code, 4) << run.output;
  EXPECT_THAT(run.output, HasSubstr("is the sensor pose right (sensor.pose_in_bin, X_BinSensor)?"));
  // The right unit and cell: models normally.
  run = RunCli("model --cloud " + (dir / "m.ply").string() + " --unit m");
  EXPECT_EQ(run.exit_code, 0) << run.output;
  fs::remove_all(dir);
}

TEST(CliModel, ACellWhoseBinIsLargerThanTheScannedOneIsExitCode4NotWallsModeledAsTubes) {
  // The built-in scene's bin is 0.8 x 0.6 m; a cell that says 1.0 x 0.8 m would put the real walls
  // inside its bin, where their faces and rims look like tubes.
  const fs::path dir = TempDir("bigbin");
  { std::ofstream(dir / "cell.yaml") << "bin:\n  inner_size: [1.0, 0.8, 0.2]\n"; }
  ASSERT_EQ(RunCli("scene --tubes 4 --seed 1 --out " + (dir / "scene").string()).exit_code, 0);
  for (const std::string command : {"model", "plan"}) {
    const CliRun run = RunCli(command + " --cloud " + (dir / "scene" / "cloud.ply").string() + " --cell " +
                              (dir / "cell.yaml").string());
    EXPECT_EQ(run.exit_code, 4) << run.output;
    EXPECT_THAT(run.output, HasSubstr("error: cloud does not fit the cell's bin: the -x wall at x = -0.400 m "
                                      "(the cell: -0.500 m)"));
    EXPECT_THAT(run.output, HasSubstr("Set larger than the bin, the walls would be modeled as tubes"));
  }
  EXPECT_EQ(RunCli("model --cloud " + (dir / "scene" / "cloud.ply").string()).exit_code, 0);
  fs::remove_all(dir);
}

TEST(CliPlan, PlansTheBuiltInSceneAndWritesPlanPickResponse) {
  const fs::path dir = TempDir("plan");
  const CliRun run = RunCli("plan --tubes 4 --seed 2 --json " + (dir / "plan.json").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const nlohmann::json j = ReadJson(dir / "plan.json");
  ASSERT_GE(j["plans"].size(), 1u) << run.output;
  EXPECT_FALSE(j["binEmpty"].get<bool>());
  EXPECT_GE(j["tubes"].size(), 3u);
  EXPECT_NE(j["tubes"][0]["occlusion"], "OCCLUSION_UNSPECIFIED");
  const auto& best = j["plans"][0];
  EXPECT_EQ(best["waypoints"][0]["z"].get<double>(), 0.0);
  EXPECT_LE(best["cost"]["total"].get<double>(), 1.0);
  EXPECT_TRUE(best.contains("placeTcpPose"));
  EXPECT_EQ(best["grasp"]["approach"]["z"].get<double>(), -1.0);
  fs::remove_all(dir);
}

TEST(CliBenchService, RejectsAnUnknownProfileOrConcurrencyBeforeStartingAServer) {
  CliRun run = RunCli("bench service --profiles fast,turbo");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_THAT(run.output, HasSubstr("turbo"));
  EXPECT_THAT(run.output, Not(HasSubstr("tubepick-server pid")));
  run = RunCli("bench service --concurrency 1,0");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_THAT(run.output, HasSubstr("--concurrency"));
}

TEST(CliParams, DumpsBothProfiles) {
  CliRun fast = RunCli("params --profile fast --dump");
  CliRun thesis = RunCli("params --profile thesis --dump");
  ASSERT_EQ(fast.exit_code, 0);
  ASSERT_EQ(thesis.exit_code, 0);
  EXPECT_THAT(thesis.output, HasSubstr("statistical_outlier"));
  EXPECT_THAT(thesis.output, HasSubstr("neighbours: 77"));
  EXPECT_THAT(fast.output, HasSubstr("crop_box"));
}

}  // namespace
}  // namespace tubepick

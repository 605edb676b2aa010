#include "core/common/cell_config.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;
constexpr double kTol = 1e-12;

TEST(CellConfig, ParsesArchitectureExample) {
  const CellConfig cell = ParseCellConfig(R"(
bin:
  inner_size: [0.80, 0.60, 0.20]
sensor:
  pose_in_bin:
    position: [0.0, 0.0, 1.1]
    orientation_xyzw: [1.0, 0.0, 0.0, 0.0]
  unit: mm
tube:
  radius: 0.0125
  length: 0.50
  mass: 0.055
)");
  EXPECT_NEAR(cell.bin.inner_size.x(), 0.80, kTol);
  EXPECT_EQ(cell.sensor.unit, LengthUnit::kMillimetre);
  // Optical z looks down the bin's −z.
  const Eigen::Vector3d z_Bin = cell.sensor.X_BinSensor.linear() * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(z_Bin.z(), -1.0, kTol);
  EXPECT_NEAR(cell.sensor.X_BinSensor.translation().z(), 1.1, kTol);
  EXPECT_NEAR(cell.tube.mass, 0.055, kTol);
}

TEST(CellConfig, DefaultsMatchDefaultPose) {
  const CellConfig cell = ParseCellConfig("{}");
  EXPECT_TRUE(cell.sensor.X_BinSensor.isApprox(SensorConfig::DefaultX_BinSensor()));
}

TEST(CellConfig, RejectsUnknownKeyNamingIt) {
  try {
    ParseCellConfig("tube:\n  radius: 0.01\n  colour: red\n");
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("tube.colour"));
  }
}

TEST(CellConfig, ReadsTheTopologyAndRejectsAnUnknownOneNamingIt) {
  EXPECT_EQ(ParseCellConfig("{}").tube.topology, TubeTopology::kLinear);
  EXPECT_EQ(ParseCellConfig("tube:\n  topology: branched\n").tube.topology, TubeTopology::kBranched);
  EXPECT_EQ(ParseCellConfig("tube:\n  topology: auto\n").tube.topology, TubeTopology::kAuto);
  try {
    ParseCellConfig("tube:\n  topology: tree\n");
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("tube.topology"));
    EXPECT_THAT(e.what(), HasSubstr("'tree'"));
  }
}

TEST(CellConfig, ReadsTheJunctionShapeAndRejectsAnUnknownOneNamingIt) {
  EXPECT_EQ(ParseCellConfig("{}").tube.junction_shape, JunctionShape::kAny);
  EXPECT_EQ(ParseCellConfig("tube:\n  junction_shape: wye\n").tube.junction_shape, JunctionShape::kWye);
  EXPECT_EQ(ParseCellConfig("tube:\n  junction_shape: tee\n").tube.junction_shape, JunctionShape::kTee);
  EXPECT_EQ(
      ParseCellConfig(DumpCellConfig(ParseCellConfig("tube:\n  junction_shape: tee\n"))).tube.junction_shape,
      JunctionShape::kTee);
  try {
    ParseCellConfig("tube:\n  junction_shape: y\n");
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(),
                HasSubstr("tube.junction_shape: unknown junction shape 'y' (expected any, wye or tee)"));
  }
}

TEST(CellConfig, ReadsTheJunctionLayoutAndRejectsARunLongerThanTheTube) {
  EXPECT_FALSE(ParseCellConfig("{}").tube.layout.known());
  const CellConfig cell = ParseCellConfig(
      "tube:\n  length: 0.75\n  junctions: 2\n  junction_spacing: 0.30\n  branch_length: 0.15\n");
  EXPECT_EQ(cell.tube.layout.junctions, 2u);
  EXPECT_DOUBLE_EQ(cell.tube.layout.junction_spacing, 0.30);
  EXPECT_DOUBLE_EQ(cell.tube.layout.branch_length, 0.15);
  EXPECT_EQ(ParseCellConfig(DumpCellConfig(cell)).tube.layout.junction_spacing, 0.30);
  EXPECT_THAT([] { ParseCellConfig("tube:\n  length: 0.75\n  junction_spacing: 0.80\n"); },
              ::testing::ThrowsMessage<InvalidArgument>(
                  HasSubstr("tube.junction_spacing: 0.8 m is not shorter than the tube (0.75 m)")));
  EXPECT_THAT([] { ParseCellConfig("tube:\n  branch_length: -0.1\n"); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("tube.branch_length")));
  EXPECT_THAT([] { ParseCellConfig("tube:\n  junctions: 65\n"); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("tube.junctions: 65 is above 64")));
}

TEST(CellConfig, RejectsOutOfRangeRadius) {
  try {
    ParseCellConfig("tube:\n  radius: -0.01\n");
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("tube.radius"));
  }
}

TEST(CellConfig, RejectsNonUnitQuaternionAndUnknownUnit) {
  EXPECT_THROW(ParseCellConfig("sensor:\n  pose_in_bin:\n    orientation_xyzw: [1, 1, 0, 0]\n"),
               InvalidArgument);
  try {
    ParseCellConfig("sensor:\n  unit: inch\n");
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("sensor.unit"));
    EXPECT_THAT(e.what(), HasSubstr("inch"));
  }
}

TEST(CellConfig, ReportsYamlSyntaxErrorWithLine) {
  try {
    ParseCellConfig("bin: [1, 2\n");
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("line"));
  }
}

TEST(CellConfig, DumpReadsBackToTheSameCell) {
  CellConfig cell;
  cell.bin.inner_size = Eigen::Vector3d(0.6, 0.4, 1.0 / 3.0);
  cell.sensor.X_BinSensor.linear() =
      Eigen::AngleAxisd(2.5, Eigen::Vector3d(1.0, 0.2, -0.3).normalized()).toRotationMatrix();
  cell.sensor.unit = LengthUnit::kMillimetre;
  cell.tube = {.radius = 0.011, .length = 0.0, .mass = 0.04, .layout = {3, 0.2, 0.1}};
  cell.place.X_BinPlace.translation() = Eigen::Vector3d(0.1, -0.7, 0.05);
  for (const CellConfig& expected : {CellConfig{}, cell}) {
    const std::string yaml = DumpCellConfig(expected);
    const CellConfig back = ParseCellConfig(yaml);
    EXPECT_EQ(back.bin.inner_size, expected.bin.inner_size) << yaml;
    EXPECT_TRUE(back.sensor.X_BinSensor.isApprox(expected.sensor.X_BinSensor, kTol)) << yaml;
    EXPECT_EQ(back.sensor.unit, expected.sensor.unit);
    EXPECT_EQ(back.tube.radius, expected.tube.radius);
    EXPECT_EQ(back.tube.length, expected.tube.length);
    EXPECT_EQ(back.tube.mass, expected.tube.mass);
    EXPECT_EQ(back.tube.layout.junctions, expected.tube.layout.junctions);
    EXPECT_EQ(back.tube.layout.junction_spacing, expected.tube.layout.junction_spacing);
    EXPECT_EQ(back.tube.layout.branch_length, expected.tube.layout.branch_length);
    EXPECT_TRUE(back.place.X_BinPlace.isApprox(expected.place.X_BinPlace, kTol)) << yaml;
  }
}

}  // namespace
}  // namespace tubepick

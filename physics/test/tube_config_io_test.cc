#include "physics/tube_config_io.h"

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/modeling/cloud_io.h"
#include "physics/random_tubes.h"
#include "physics/scan_io.h"

namespace tubepick::physics {
namespace {

using ::testing::HasSubstr;
constexpr double kRoundTripTol = 1e-6;

std::string TempPath(const std::string& name) {
  return (std::filesystem::path(::testing::TempDir()) / ("physics_io_" + name)).string();
}

void ExpectNear(const std::vector<TubeGeometry>& a, const std::vector<TubeGeometry>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].id, b[i].id);
    ASSERT_EQ(a[i].nodes.size(), b[i].nodes.size());
    ASSERT_EQ(a[i].edges.size(), b[i].edges.size());
    for (std::size_t k = 0; k < a[i].nodes.size(); ++k) {
      EXPECT_EQ(a[i].nodes[k].id, b[i].nodes[k].id);
      EXPECT_LT((a[i].nodes[k].centre - b[i].nodes[k].centre).norm(), kRoundTripTol);
      EXPECT_NEAR(a[i].nodes[k].radius, b[i].nodes[k].radius, kRoundTripTol);
    }
    for (std::size_t k = 0; k < a[i].edges.size(); ++k) {
      const TubeEdge &e = a[i].edges[k], &f = b[i].edges[k];
      EXPECT_EQ(e.name, f.name);
      EXPECT_EQ(e.node1, f.node1);
      EXPECT_EQ(e.node2, f.node2);
      EXPECT_EQ(e.order, f.order);
      EXPECT_NEAR(e.radius, f.radius, kRoundTripTol);
      EXPECT_LT((e.centre - f.centre).norm(), kRoundTripTol);
      EXPECT_LT((e.orientation.coeffs() - f.orientation.coeffs()).norm(), kRoundTripTol);
      EXPECT_NEAR(e.length, f.length, kRoundTripTol);
    }
  }
}

TEST(TubeConfigIo, RoundTrips) {
  std::vector<TubeGeometry> tubes = GenerateRandomTubes(3, RandomTubeParams::SetA(), 1);
  tubes.push_back(GenerateRandomTubes(1, RandomTubeParams::SetC(), 2).front());
  tubes.back().id = 4;
  ExpectNear(ParseTubeConfigurations(FormatTubeConfigurations(tubes)), tubes);
  const std::string path = TempPath("round_trip.txt");
  WriteTubeConfigurations(path, tubes);
  ExpectNear(ReadTubeConfigurations(path), tubes);
}

TEST(TubeConfigIo, ReadsPublishedSampleWithScalarFirstQuaternions) {
  const std::vector<TubeGeometry> tubes =
      ReadTubeConfigurations(std::string(TUBEPICK_PHYSICS_TEST_DATA) + "/A3_1_tube_configurations.txt");
  ASSERT_EQ(tubes.size(), 3u);
  EXPECT_EQ(tubes[0].id, 1);
  EXPECT_EQ(tubes[0].nodes.size(), 11u);
  EXPECT_EQ(tubes[0].edges.size(), 10u);
  EXPECT_EQ(tubes[0].edges[0].name, "e_1_4");
  EXPECT_EQ(tubes[0].edges[9].order, 10);
  for (const TubeGeometry& tube : tubes) {
    EXPECT_TRUE(tube.IsLinear());
    EXPECT_NEAR(tube.Length(), 0.50, 1e-4);
    for (const TubeEdge& e : tube.edges) {
      const Eigen::Vector3d a = tube.Node(e.node1).centre, b = tube.Node(e.node2).centre;
      // (w, x, y, z): the cylinder's local z is its axis node1 → node2.
      EXPECT_GT((e.orientation * Eigen::Vector3d::UnitZ()).dot((b - a).normalized()), 0.9999) << e.name;
      EXPECT_LT((e.centre - 0.5 * (a + b)).norm(), 1e-5);
      EXPECT_NEAR(e.length, (b - a).norm(), 1e-5);
    }
  }
  // The centreline runs from end node 1 to end node 2.
  const auto line = tubes[0].Centreline();
  EXPECT_TRUE(line.front().isApprox(tubes[0].Node(1).centre));
  EXPECT_TRUE(line.back().isApprox(tubes[0].Node(2).centre));
}

/// The InvalidArgument message of parsing `text`.
std::string ParseError(const std::string& text) {
  try {
    ParseTubeConfigurations(text, "bad.txt");
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(TubeConfigIo, MalformedFilesNameTheLine) {
  const std::string head = "1\n1 2 1\n1 0 0 0 0.0125\n";
  const std::string edge = "e_1_2 1 2 1 0.0125 0 0 0.05 1 0 0 0 0.1\n";
  EXPECT_EQ(ParseTubeConfigurations(head + "2 0 0 0.1 0.0125\n" + edge).size(), 1u);
  EXPECT_THAT(
      ParseError(head + "2 0 0 0.1\n" + edge),
      HasSubstr(
          "bad.txt:4: expected 5 fields in a node line '<id> x y z radius' (node 2 of 2 of tube 1), got 4"));
  EXPECT_THAT(ParseError(head + "2 0 abc 0.1 0.0125\n" + edge),
              HasSubstr("bad.txt:4: y: expected a finite number, got 'abc'"));
  EXPECT_THAT(ParseError(head + "2 0 0 0.1 0.0125\n"),
              HasSubstr("bad.txt:5: unexpected end of file, expected an edge line"));
  EXPECT_THAT(ParseError(head + "2 0 0 0.1 0.0125\ne_1_3 1 3 1 0.0125 0 0 0.05 1 0 0 0 0.1\n"),
              HasSubstr("bad.txt:5: edge e_1_3 refers to node 3"));
  EXPECT_THAT(ParseError(head + "1 0 0 0.1 0.0125\n" + edge), HasSubstr("bad.txt:4: duplicate node id 1"));
  EXPECT_THAT(ParseError(head + "2 0 0 0.1 0.0125\n" + edge + "\n7\n"),
              HasSubstr("bad.txt:7: unexpected content"));
  EXPECT_THAT(ParseError(head + "2 0 0 0.1 0.0125\ne_1_2 1 2 1 0.0125 0 0 0.05 0 0 0 0 0.1\n"),
              HasSubstr("bad.txt:5: edge e_1_2: zero quaternion"));
  EXPECT_THAT(ParseError("x\n"), HasSubstr("bad.txt:1: number of tubes: expected an integer, got 'x'"));
  EXPECT_THAT(ParseError(""), HasSubstr("bad.txt:1: unexpected end of file"));
  try {
    ReadTubeConfigurations(TempPath("does_not_exist.txt"));
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("cannot open"));
  }
}

TEST(ScanIo, LabelsRoundTripAndBadLinesAreNamed) {
  const std::vector<std::int32_t> labels{0, 3, -1, -2, 12};
  const std::string path = TempPath("labels.txt");
  WriteLabels(path, labels);
  EXPECT_EQ(ReadLabels(path), labels);
  {
    std::ofstream file(path);
    file << "1\n2\nx\n";
  }
  try {
    ReadLabels(path);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr(path + ":3: expected one integer label, got 'x'"));
  }
}

TEST(ScanIo, WritesPlyAndLabels) {
  ScanResult scan;
  scan.points_Sensor = {{0.1f, 0.2f, 1.0f}, {0.0f, 0.0f, 1.1f}, {-0.1f, 0.05f, 0.9f}};
  scan.labels = {0, -1, -2};
  const std::string ply = TempPath("scan.ply"), labels = TempPath("scan.labels.txt");
  WriteScan(ply, labels, scan);
  const CloudFile cloud = ReadCloudFile(ply);
  ASSERT_EQ(cloud.points.size(), 3u);
  EXPECT_TRUE(cloud.points[2].isApprox(scan.points_Sensor[2]));
  EXPECT_EQ(ReadLabels(labels), scan.labels);
  scan.labels.pop_back();
  EXPECT_THROW(WriteScan(ply, labels, scan), InvalidArgument);
}

}  // namespace
}  // namespace tubepick::physics

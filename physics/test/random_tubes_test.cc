#include "physics/random_tubes.h"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"

namespace tubepick::physics {
namespace {

using ::testing::HasSubstr;
constexpr double kLengthTol = 1e-9;
constexpr double kAngleTol = 1e-6;
constexpr double kDeg = M_PI / 180.0;

double Angle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

/// Node centres of the chain of cylinders from graph node `from` to graph node `to`, through
/// joints (degree-2 nodes) only; empty when there is none.
std::vector<Eigen::Vector3d> Chain(const TubeGeometry& tube, int from, int to) {
  auto other_end = [](const TubeEdge& e, int node) { return e.node1 == node ? e.node2 : e.node1; };
  for (const TubeEdge& first : tube.edges) {
    if (first.node1 != from && first.node2 != from) continue;
    std::vector<Eigen::Vector3d> points{tube.Node(from).centre};
    const TubeEdge* edge = &first;
    int current = from;
    while (true) {
      current = other_end(*edge, current);
      points.push_back(tube.Node(current).centre);
      if (current == to) return points;
      if (tube.Degree(current) != 2) break;
      const TubeEdge* next = nullptr;
      for (const TubeEdge& e : tube.edges) {
        if (&e != edge && (e.node1 == current || e.node2 == current)) next = &e;
      }
      edge = next;
    }
  }
  return {};
}

/// Checks Algorithm 2's guarantees on one chain of cylinders.
void ExpectChain(const std::vector<Eigen::Vector3d>& points, const TubeBranchSpec& spec, double resolution) {
  ASSERT_GE(points.size(), 2u);
  const int cylinders = static_cast<int>(points.size()) - 1;
  EXPECT_GE(cylinders, spec.min_cylinders);
  EXPECT_LE(cylinders, spec.max_cylinders);
  double sum = 0.0;
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    const double length = (points[i + 1] - points[i]).norm();
    sum += length;
    EXPECT_GE(length, 0.02 - kLengthTol);
    if (resolution > 0.0) {
      EXPECT_NEAR(length / resolution, std::round(length / resolution), 1e-7);
    }
    if (i > 0) {
      const double angle = Angle(points[i] - points[i - 1], points[i + 1] - points[i]);
      EXPECT_GE(angle, spec.min_angle - kAngleTol);
      EXPECT_LE(angle, spec.max_angle + kAngleTol);
    }
  }
  EXPECT_NEAR(sum, spec.length, kLengthTol);
}

TEST(RandomTubes, SetAFollowsAlgorithm2) {
  const RandomTubeParams params = RandomTubeParams::SetA();
  const std::vector<TubeGeometry> tubes = GenerateRandomTubes(40, params, 11);
  ASSERT_EQ(tubes.size(), 40u);
  for (const TubeGeometry& tube : tubes) {
    SCOPED_TRACE("tube " + std::to_string(tube.id));
    ASSERT_TRUE(tube.IsLinear());
    EXPECT_NEAR(tube.Length(), 0.50, kLengthTol);
    ExpectChain(tube.Centreline(), params.branches[0], params.length_resolution);
    EXPECT_GE(SelfClearance(tube), 0.0);
    // Published numbering: ends 1 and 2, joints from 4; every radius R.
    EXPECT_EQ(tube.Degree(1), 1);
    EXPECT_EQ(tube.Degree(2), 1);
    EXPECT_LT(tube.FindNode(3), 0);
    for (const TubeNode& n : tube.nodes) EXPECT_EQ(n.radius, 0.0125);
    EXPECT_EQ(tube.edges.front().name, "e_1_4");
  }
  EXPECT_EQ(tubes.front().id, 1);
  EXPECT_EQ(tubes.back().id, 40);
}

TEST(RandomTubes, SetBAnglesUpTo45Degrees) {
  const RandomTubeParams params = RandomTubeParams::SetB();
  double max_angle = 0.0;
  for (const TubeGeometry& tube : GenerateRandomTubes(40, params, 5)) {
    const std::vector<Eigen::Vector3d> line = tube.Centreline();
    ExpectChain(line, params.branches[0], params.length_resolution);
    for (std::size_t i = 1; i + 1 < line.size(); ++i) {
      max_angle = std::max(max_angle, Angle(line[i] - line[i - 1], line[i + 1] - line[i]));
    }
  }
  EXPECT_GT(max_angle, 30.0 * kDeg);  // the wider range is used
}

TEST(RandomTubes, SetCYIsBranchedWithYPieces) {
  const RandomTubeParams params = RandomTubeParams::SetCY();
  for (const TubeGeometry& tube : GenerateRandomTubes(20, params, 3)) {
    SCOPED_TRACE("tube " + std::to_string(tube.id));
    EXPECT_FALSE(tube.IsLinear());
    EXPECT_EQ(tube.Degree(1), 3);
    EXPECT_EQ(tube.Degree(2), 3);
    for (int leaf : {3, 4, 5, 6}) EXPECT_EQ(tube.Degree(leaf), 1);
    EXPECT_NEAR(tube.Length(), 0.30 + 0.10 + 0.10 + 0.10 + 0.15, kLengthTol);
    EXPECT_GE(SelfClearance(tube), 0.0);
    for (const TubeBranchSpec& spec : params.branches) {
      SCOPED_TRACE("branch " + std::to_string(spec.from_node) + "-" + std::to_string(spec.to_node));
      ExpectChain(Chain(tube, spec.from_node, spec.to_node), spec, params.length_resolution);
    }
    // Branches leave their split node at 120° from the trunk, siblings 120° apart.
    const auto trunk = Chain(tube, 1, 2);
    const auto b13 = Chain(tube, 1, 3), b14 = Chain(tube, 1, 4), b25 = Chain(tube, 2, 5);
    EXPECT_NEAR(Angle(trunk[1] - trunk[0], b13[1] - b13[0]), 120.0 * kDeg, kAngleTol);
    EXPECT_NEAR(Angle(b13[1] - b13[0], b14[1] - b14[0]), 120.0 * kDeg, kAngleTol);
    const auto n = trunk.size();
    EXPECT_NEAR(Angle(trunk[n - 2] - trunk[n - 1], b25[1] - b25[0]), 120.0 * kDeg, kAngleTol);
  }
}

TEST(RandomTubes, SetCBranchesLeaveInRandomDirectionsAsPublished) {
  const RandomTubeParams params = RandomTubeParams::SetC();
  double low = M_PI, high = 0.0, sibling_low = M_PI, sibling_high = 0.0;
  for (const TubeGeometry& tube : GenerateRandomTubes(20, params, 3)) {
    SCOPED_TRACE("tube " + std::to_string(tube.id));
    EXPECT_EQ(tube.Degree(1), 3);
    EXPECT_EQ(tube.Degree(2), 3);
    EXPECT_NEAR(tube.Length(), 0.75, kLengthTol);
    EXPECT_GE(SelfClearance(tube), 0.0);
    for (const TubeBranchSpec& spec : params.branches) {
      ExpectChain(Chain(tube, spec.from_node, spec.to_node), spec, params.length_resolution);
    }
    const auto trunk = Chain(tube, 1, 2);
    const auto b13 = Chain(tube, 1, 3), b14 = Chain(tube, 1, 4);
    // The trunk's continuation through node 1 (pointing away from the trunk).
    const Eigen::Vector3d continuation = trunk[0] - trunk[1];
    for (const auto* b : {&b13, &b14}) {
      const double a = Angle(continuation, (*b)[1] - (*b)[0]);
      low = std::min(low, a);
      high = std::max(high, a);
    }
    const double sibling = Angle(b13[1] - b13[0], b14[1] - b14[0]);
    sibling_low = std::min(sibling_low, sibling);
    sibling_high = std::max(sibling_high, sibling);
  }
  // The published C1, C3 and C5 files spread over 0°–165° and 0°–180°; 40 draws cover most of it.
  EXPECT_LT(low, 30.0 * kDeg);
  EXPECT_GT(high, 110.0 * kDeg);
  EXPECT_LT(sibling_low, 60.0 * kDeg);
  EXPECT_GT(sibling_high, 140.0 * kDeg);
}

TEST(RandomTubes, PresetsByName) {
  EXPECT_TRUE(RandomTubeParams::Preset("C").branches[1].split_random);
  EXPECT_FALSE(RandomTubeParams::Preset("CY").branches[1].split_random);
  EXPECT_EQ(RandomTubeParams::Preset("CY").branches.size(), 5u);
  try {
    RandomTubeParams::Preset("D");
    FAIL() << "no throw";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("'D' (expected A, B, C or CY)"), std::string::npos) << e.what();
  }
}

TEST(RandomTubes, SameSeedSameTubesDifferentSeedDifferent) {
  const RandomTubeParams params = RandomTubeParams::SetA();
  const auto a = GenerateRandomTubes(5, params, 42);
  const auto b = GenerateRandomTubes(5, params, 42);
  const auto c = GenerateRandomTubes(5, params, 43);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].nodes.size(), b[i].nodes.size());
    for (std::size_t k = 0; k < a[i].nodes.size(); ++k) EXPECT_EQ(a[i].nodes[k].centre, b[i].nodes[k].centre);
  }
  EXPECT_NE(a[0].nodes[1].centre, c[0].nodes[1].centre);
}

TEST(RandomTubes, RealLengthsWithZeroResolution) {
  RandomTubeParams params = RandomTubeParams::SetA();
  params.length_resolution = 0.0;
  bool off_grid = false;
  for (const TubeGeometry& tube : GenerateRandomTubes(10, params, 8)) {
    ExpectChain(tube.Centreline(), params.branches[0], 0.0);
    const double first = tube.edges.front().length;
    off_grid |= std::abs(first * 100.0 - std::round(first * 100.0)) > 1e-3;
  }
  EXPECT_TRUE(off_grid);
}

TEST(RandomTubes, TubeIsCentred) {
  const TubeGeometry tube = GenerateRandomTubes(1, RandomTubeParams::SetA(), 1).front();
  Eigen::Vector3d lo = tube.nodes.front().centre, hi = lo;
  for (const TubeNode& n : tube.nodes) {
    lo = lo.cwiseMin(n.centre);
    hi = hi.cwiseMax(n.centre);
  }
  EXPECT_LT((lo + hi).norm(), 1e-12);
}

TEST(RandomTubes, SelfClearanceDetectsFoldedTube) {
  // A hairpin: out 10 cm, 3 cm across, back 10 cm; the two long legs are 3 cm < 2R = 4 cm apart.
  TubeGeometry tube;
  const std::vector<Eigen::Vector3d> p{{0, 0, 0}, {0.1, 0, 0}, {0.1, 0.03, 0}, {0, 0.03, 0}};
  for (int i = 0; i < 4; ++i) tube.nodes.push_back({i + 1, p[i], 0.02});
  for (int i = 0; i < 3; ++i) {
    TubeEdge e;
    e.node1 = i + 1;
    e.node2 = i + 2;
    e.radius = 0.02;
    tube.edges.push_back(e);
  }
  // The legs are only 3 cm apart along the tube, so they count as neighbours: no clearance check.
  EXPECT_TRUE(std::isinf(SelfClearance(tube)));
  tube.nodes[2].centre.y() = 0.05;
  tube.nodes[3].centre.y() = 0.05;
  EXPECT_NEAR(SelfClearance(tube), 0.05 - 0.04, 1e-12);
  tube.nodes[3].centre = Eigen::Vector3d(0.0, 0.01, 0.0);  // leg folds back onto the first
  EXPECT_LT(SelfClearance(tube), 0.0);
}

TEST(RandomTubes, InvalidParamsAreNamed) {
  RandomTubeParams params = RandomTubeParams::SetA();
  params.branches[0].max_cylinders = 30;
  try {
    GenerateRandomTubes(1, params, 1);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("branches[0].max_cylinders = 30"));
  }
  params = RandomTubeParams::SetA();
  params.branches[0].length = 0.505;
  EXPECT_THROW(params.Validate(), InvalidArgument);
  try {
    RandomTubeParams::Preset("D");
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("'D'"));
  }
}

}  // namespace
}  // namespace tubepick::physics

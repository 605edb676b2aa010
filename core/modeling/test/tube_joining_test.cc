#include "core/modeling/tube_joining.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/cell_config.h"
#include "core/common/errors.h"
#include "core/common/stop_token.h"
#include "core/testing/synthetic_cloud.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;
constexpr double kTol = 1e-9;
constexpr double kPi = 3.14159265358979323846;
constexpr double kR = 0.0125;        // tube radius, metres
constexpr double kFloorCut = 0.004;  // bin-frame z below which rendered points are floor

Cylinder MakeCylinder(const Eigen::Vector3d& start, const Eigen::Vector3d& end, std::uint32_t id,
                      double radius = kR) {
  Cylinder c;
  c.start = start;
  c.end = end;
  c.radius = radius;
  c.segment_id = id;
  return c;
}

// A cylinder on the floor (axis at z = kR) from (x0, y0) to (x1, y1).
Cylinder FloorCylinder(double x0, double y0, double x1, double y1, std::uint32_t id) {
  return MakeCylinder({x0, y0, kR}, {x1, y1, kR}, id);
}

JoiningParams NoVisibility(JoiningStrategy strategy = JoiningStrategy::kGreedy) {
  JoiningParams params;
  params.visibility_check = false;
  params.strategy = strategy;
  return params;
}

// The segment ids of each tube's cylinders, in tube order.
std::vector<std::vector<std::uint32_t>> Ids(const std::vector<Tube>& tubes) {
  std::vector<std::vector<std::uint32_t>> ids;
  for (const Tube& t : tubes) {
    ids.emplace_back();
    for (const Cylinder& c : t.cylinders) ids.back().push_back(c.segment_id);
  }
  return ids;
}

// Each tube's segment ids as a set, tubes in output order.
std::vector<std::set<std::uint32_t>> IdSets(const std::vector<Tube>& tubes) {
  std::vector<std::set<std::uint32_t>> sets;
  for (const auto& ids : Ids(tubes)) sets.emplace_back(ids.begin(), ids.end());
  return sets;
}

void ExpectIdsAreSequential(const std::vector<Tube>& tubes) {
  for (std::size_t i = 0; i < tubes.size(); ++i) EXPECT_EQ(tubes[i].id, i);
  for (std::size_t i = 1; i < tubes.size(); ++i) EXPECT_GE(tubes[i - 1].length(), tubes[i].length());
}

// Renders tubes as the default sensor sees them and returns the non-floor points in the bin frame.
Points RenderBinPoints(const std::vector<testing::SyntheticTube>& tubes) {
  testing::SyntheticCloudParams cloud_params;
  cloud_params.half_fov_x = 0.3;
  cloud_params.half_fov_y = 0.3;
  const testing::SyntheticCloud cloud = testing::RenderSyntheticCloud(tubes, cloud_params);
  Points points_Bin;
  for (const Eigen::Vector3f& p_Sensor : cloud.points_Sensor) {
    const Eigen::Vector3d p_Bin = cloud_params.X_BinSensor * p_Sensor.cast<double>();
    if (p_Bin.z() >= kFloorCut) points_Bin.push_back(p_Bin.cast<float>());
  }
  return points_Bin;
}

TEST(EndpointDistance, MatchesHandCalculation) {
  const JoiningParams params;  // c_Δθ = 0.001 m/° = 0.0572958 m/rad
  const Eigen::Vector3d a(0.0, 0.0, 0.0), b(0.03, 0.03, 0.0);
  // a→b is at 45° to a's outward +x; b→a is at 45° to b's outward −x: α + β = 90°.
  const JoinDistance d =
      EndpointDistance(a, Eigen::Vector3d::UnitX(), b, -Eigen::Vector3d::UnitX(), kR, params);
  EXPECT_NEAR(d.euclidean, 0.03 * std::sqrt(2.0), kTol);
  EXPECT_NEAR(d.angular, kPi / 2.0, kTol);
  EXPECT_NEAR(d.combined, 0.03 * std::sqrt(2.0) + 0.09, kTol);  // 90° · 0.001 m/°

  // b's outward +y: b→a = (−1, −1)/√2 is at 135° to it; α + β = 180°. Outward axes need not be unit.
  const JoinDistance d2 =
      EndpointDistance(a, 2.0 * Eigen::Vector3d::UnitX(), b, Eigen::Vector3d::UnitY(), kR, params);
  EXPECT_NEAR(d2.angular, kPi, kTol);
  EXPECT_NEAR(d2.combined, 0.03 * std::sqrt(2.0) + 0.18, kTol);

  // Collinear ends facing each other: no angular term.
  const JoinDistance d3 =
      EndpointDistance(a, Eigen::Vector3d::UnitX(), {0.05, 0.0, 0.0}, -Eigen::Vector3d::UnitX(), kR, params);
  EXPECT_NEAR(d3.angular, 0.0, kTol);
  EXPECT_NEAR(d3.combined, 0.05, kTol);
}

TEST(EndpointDistance, RadiusShortcutZeroesTheAngle) {
  const JoiningParams params;
  const Eigen::Vector3d a(0.0, 0.0, 0.0), b(0.006, 0.008, 0.0);  // 1 cm apart
  const JoinDistance below =
      EndpointDistance(a, Eigen::Vector3d::UnitY(), b, Eigen::Vector3d::UnitY(), 0.0125, params);
  EXPECT_NEAR(below.euclidean, 0.01, kTol);
  EXPECT_EQ(below.angular, 0.0);
  EXPECT_NEAR(below.combined, 0.01, kTol);
  const JoinDistance above =
      EndpointDistance(a, Eigen::Vector3d::UnitY(), b, Eigen::Vector3d::UnitY(), 0.005, params);
  EXPECT_GT(above.angular, 0.5);
  EXPECT_NEAR(above.combined, 0.01 + params.angular_weight * above.angular, kTol);
}

TEST(JoinTubes, EmptyAndSingleCylinder) {
  EXPECT_TRUE(JoinTubes({}, NoVisibility(), nullptr).empty());
  const Cylinder c = FloorCylinder(0.0, 0.0, 0.2, 0.0, 7);
  const std::vector<Tube> tubes = JoinTubes({c}, NoVisibility(), nullptr);
  ASSERT_EQ(tubes.size(), 1u);
  EXPECT_EQ(tubes[0].id, 0u);
  ASSERT_EQ(tubes[0].cylinders.size(), 1u);
  EXPECT_EQ(tubes[0].cylinders[0].segment_id, 7u);
  EXPECT_TRUE(tubes[0].cylinders[0].start.isApprox(c.start));
}

TEST(JoinTubes, BentTubeFromShuffledFlippedCylinders) {
  // Centreline with two 30° bends; each cylinder is shortened by 1 cm at both ends, so the
  // joints are ~1.9 cm gaps with α + β = 30°.
  const std::vector<Eigen::Vector3d> vertex = {
      {-0.20, -0.05, kR},
      {-0.05, -0.05, kR},
      {-0.05 + 0.15 * std::cos(kPi / 6), -0.05 + 0.15 * std::sin(kPi / 6), kR},
      {-0.05 + 0.15 * std::cos(kPi / 6) + 0.15 * std::cos(kPi / 3),
       -0.05 + 0.15 * std::sin(kPi / 6) + 0.15 * std::sin(kPi / 3), kR}};
  constexpr double kShrink = 0.01;
  std::vector<Cylinder> ordered;
  for (std::uint32_t i = 0; i < 3; ++i) {
    const Eigen::Vector3d d = (vertex[i + 1] - vertex[i]).normalized();
    ordered.push_back(MakeCylinder(vertex[i] + kShrink * d, vertex[i + 1] - kShrink * d, i));
  }
  double expected_length = 0.0;
  for (std::size_t i = 0; i < 3; ++i) {
    expected_length += ordered[i].length();
    if (i < 2) expected_length += (ordered[i + 1].start - ordered[i].end).norm();
  }

  for (const JoiningStrategy strategy : {JoiningStrategy::kGreedy, JoiningStrategy::kGlobal}) {
    for (std::uint32_t seed = 1; seed <= 8; ++seed) {
      SCOPED_TRACE(::testing::Message() << "strategy " << static_cast<int>(strategy) << " seed " << seed);
      std::mt19937 rng(seed);
      std::vector<Cylinder> input = ordered;
      for (std::size_t i = input.size(); i > 1; --i) std::swap(input[i - 1], input[rng() % i]);
      for (Cylinder& c : input) {
        if (rng() % 2 == 1) std::swap(c.start, c.end);
      }

      const std::vector<Tube> tubes = JoinTubes(input, NoVisibility(strategy), nullptr);
      ASSERT_EQ(tubes.size(), 1u);
      const Tube& tube = tubes[0];
      ASSERT_EQ(tube.cylinders.size(), 3u);
      EXPECT_NEAR(tube.length(), expected_length, kTol);
      // Either direction along the tube; every cylinder oriented the same way.
      const bool forward = tube.cylinders[0].segment_id == 0;
      for (std::size_t k = 0; k < 3; ++k) {
        const Cylinder& original = ordered[forward ? k : 2 - k];
        const Cylinder& got = tube.cylinders[k];
        EXPECT_EQ(got.segment_id, original.segment_id);
        EXPECT_TRUE(got.start.isApprox(forward ? original.start : original.end));
        EXPECT_TRUE(got.end.isApprox(forward ? original.end : original.start));
      }
    }
  }
}

// Crossing: a floor tube along x, hidden at |x| < ~1.3 cm by a tube lying across it along y,
// is seen as two cylinders ending at x = ±3 cm (a 6 cm gap), plus the upper tube's cylinder.
struct Crossing {
  std::vector<Cylinder> cylinders = {FloorCylinder(-0.25, 0.0, -0.03, 0.0, 0),
                                     FloorCylinder(0.03, 0.0, 0.25, 0.0, 1),
                                     MakeCylinder({0.0, -0.2, 3 * kR}, {0.0, 0.2, 3 * kR}, 2)};
  testing::SyntheticTube lower = testing::FloorTube({{-0.25, 0.0}, {0.25, 0.0}}, kR);
  testing::SyntheticTube upper = testing::StraightTube({0.0, -0.2, 3 * kR}, {0.0, 0.2, 3 * kR}, kR);
  // The same visible parts as two separate tubes with nothing above the gap.
  testing::SyntheticTube left = testing::FloorTube({{-0.25, 0.0}, {-0.03, 0.0}}, kR);
  testing::SyntheticTube right = testing::FloorTube({{0.03, 0.0}, {0.25, 0.0}}, kR);
};

TEST(JoinTubes, CrossingJoinsTheLowerTubeUnderTheUpperOne) {
  const Crossing scene;
  JoiningParams params;
  const RangeImage visibility(RenderBinPoints({scene.lower, scene.upper}), SensorConfig::DefaultX_BinSensor(),
                              params.visibility_pixel_angle);
  for (const JoiningStrategy strategy : {JoiningStrategy::kGreedy, JoiningStrategy::kGlobal}) {
    params.strategy = strategy;
    const std::vector<Tube> tubes = JoinTubes(scene.cylinders, params, &visibility);
    ASSERT_EQ(tubes.size(), 2u);
    EXPECT_EQ(Ids(tubes)[0], (std::vector<std::uint32_t>{0, 1}));  // 0.50 m: longest first
    EXPECT_EQ(Ids(tubes)[1], (std::vector<std::uint32_t>{2}));     // upper tube alone
    EXPECT_NEAR(tubes[0].length(), 0.50, kTol);
    EXPECT_TRUE(tubes[0].cylinders[0].end.isApprox(Eigen::Vector3d(-0.03, 0.0, kR)));
    EXPECT_TRUE(tubes[0].cylinders[1].start.isApprox(Eigen::Vector3d(0.03, 0.0, kR)));
    ExpectIdsAreSequential(tubes);
  }
}

TEST(JoinTubes, VisibilityConstraintKeepsAnUncoveredGapOpen) {
  const Crossing scene;
  JoiningParams params;
  const RangeImage visibility(RenderBinPoints({scene.left, scene.right, scene.upper}),
                              SensorConfig::DefaultX_BinSensor(), params.visibility_pixel_angle);
  const RangeImage open_gap(RenderBinPoints({scene.left, scene.right}), SensorConfig::DefaultX_BinSensor(),
                            params.visibility_pixel_angle);
  const std::vector<Cylinder> lower(scene.cylinders.begin(), scene.cylinders.begin() + 2);
  for (const JoiningStrategy strategy : {JoiningStrategy::kGreedy, JoiningStrategy::kGlobal}) {
    params.strategy = strategy;
    EXPECT_EQ(JoinTubes(lower, params, &open_gap).size(), 2u);
    // Something above the gap (here the upper tube) lets it join.
    EXPECT_EQ(JoinTubes(lower, params, &visibility).size(), 1u);
    // Without the check, or for gaps shorter than visibility_min_gap, the open gap joins.
    JoiningParams unchecked = params;
    unchecked.visibility_check = false;
    EXPECT_EQ(JoinTubes(lower, unchecked, &open_gap).size(), 1u);
    EXPECT_EQ(JoinTubes(lower, params, nullptr).size(), 1u);
    JoiningParams short_gaps = params;
    short_gaps.visibility_min_gap = 0.07;
    EXPECT_EQ(JoinTubes(lower, short_gaps, &open_gap).size(), 1u);
  }
}

TEST(JoinTubes, LengthConstraint) {
  const std::vector<Cylinder> cylinders = {FloorCylinder(-0.355, 0.0, -0.005, 0.0, 0),
                                           FloorCylinder(0.005, 0.0, 0.355, 0.0, 1)};
  for (const JoiningStrategy strategy : {JoiningStrategy::kGreedy, JoiningStrategy::kGlobal}) {
    JoiningParams params = NoVisibility(strategy);
    params.max_tube_length = 0.6;
    EXPECT_EQ(JoinTubes(cylinders, params, nullptr).size(), 2u);
    params.max_tube_length = 0.8;
    const std::vector<Tube> joined = JoinTubes(cylinders, params, nullptr);
    ASSERT_EQ(joined.size(), 1u);
    EXPECT_NEAR(joined[0].length(), 0.71, kTol);
    params.max_tube_length = 0.0;  // disabled
    EXPECT_EQ(JoinTubes(cylinders, params, nullptr).size(), 1u);
  }
}

TEST(JoinTubes, MaxJoinedLengthIsTheSmallerOfTheAbsoluteAndTheCellsShare) {
  JoiningParams params;
  params.max_tube_length = 0.6;
  EXPECT_DOUBLE_EQ(MaxJoinedLength(params, 0.5), 0.6);  // share off (the thesis)
  params.max_length_share = 1.04;
  EXPECT_DOUBLE_EQ(MaxJoinedLength(params, 0.5), 0.52);
  EXPECT_DOUBLE_EQ(MaxJoinedLength(params, 0.0), 0.6);  // tube length unknown
  EXPECT_DOUBLE_EQ(MaxJoinedLength(params, 0.8), 0.6);  // the absolute limit still holds
  params.max_tube_length = 0.0;
  EXPECT_DOUBLE_EQ(MaxJoinedLength(params, 0.8), 0.8 * 1.04);
  EXPECT_DOUBLE_EQ(MaxJoinedLength(params, 0.0), 0.0);  // no limit at all
  params.max_length_share = -1.0;
  EXPECT_THAT([&] { JoinTubes({}, params, nullptr); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("joining.max_length_share")));
}

// Two whole 0.50 m tubes and two collinear pieces, 0.30 and 0.29 m with a 1 cm gap: one tube of
// 0.60 m if joined, within max_tube_length (0.8 here).
std::vector<Cylinder> TwoWholeTubesAndTwoPieces() {
  return {FloorCylinder(-0.25, -0.2, 0.25, -0.2, 0), FloorCylinder(-0.25, 0.2, 0.25, 0.2, 1),
          FloorCylinder(-0.30, 0.0, 0.0, 0.0, 2), FloorCylinder(0.01, 0.0, 0.30, 0.0, 3)};
}

TEST(JoinTubesOfLength, NoTubeLongerThanTheShareOfTheCellsTubeLength) {
  JoiningParams params = NoVisibility(JoiningStrategy::kGlobal);
  params.max_tube_length = 0.8;
  params.max_length_share = 1.04;
  const std::vector<Cylinder> cylinders = TwoWholeTubesAndTwoPieces();
  std::optional<double> disagrees = 1.0;
  // Joined without the share: the whole tubes are 0.50 m (median of 0.50, 0.50, 0.60).
  EXPECT_NEAR(WholeTubeLength(JoinTubes(cylinders, params, nullptr), 0.5), 0.5, kTol);
  EXPECT_EQ(JoinTubesOfLength(cylinders, params, 0.5, nullptr, nullptr, &disagrees).size(), 4u);  // ≤ 0.52 m
  EXPECT_FALSE(disagrees.has_value());
  EXPECT_EQ(JoinTubesOfLength(cylinders, params, 0.0, nullptr, nullptr, &disagrees).size(), 3u);  // unknown
  EXPECT_EQ(JoinTubesOfLength(cylinders, params, 0.6, nullptr, nullptr, &disagrees).size(), 3u);  // ≤ 0.624 m
  params.max_length_share = 0.0;
  EXPECT_EQ(JoinTubesOfLength(cylinders, params, 0.5, nullptr, nullptr, &disagrees).size(), 3u);
}

TEST(JoinTubesOfLength, ACellThatStatesItsTubesShorterThanTheScanShowsThemIsToldAndNotBelieved) {
  JoiningParams params = NoVisibility(JoiningStrategy::kGlobal);
  params.max_tube_length = 0.8;
  params.max_length_share = 1.04;
  // The same pieces with their tubes 0.60 m long, in a cell that says 0.45 m: the whole tubes the
  // scan shows are 0.60 m, so joining bounds them by 1.04 · 0.60 m and says so.
  std::vector<Cylinder> cylinders = TwoWholeTubesAndTwoPieces();
  cylinders[0] = FloorCylinder(-0.30, -0.2, 0.30, -0.2, 0);
  cylinders[1] = FloorCylinder(-0.30, 0.2, 0.30, 0.2, 1);
  std::optional<double> disagrees;
  const std::vector<Tube> tubes = JoinTubesOfLength(cylinders, params, 0.45, nullptr, nullptr, &disagrees);
  ASSERT_TRUE(disagrees.has_value());
  EXPECT_NEAR(*disagrees, 0.6, 0.011);
  ASSERT_EQ(tubes.size(), 3u);
  for (const Tube& tube : tubes) EXPECT_NEAR(tube.length(), 0.6, 0.011);
}

TEST(JoinTubes, LengthConstraintAppliesToTheWholeChain) {
  // Three collinear 0.25 m cylinders with 1 cm gaps: any two fit 0.6 m, all three (0.77 m) do not.
  const std::vector<Cylinder> cylinders = {FloorCylinder(-0.385, 0.0, -0.135, 0.0, 0),
                                           FloorCylinder(-0.125, 0.0, 0.125, 0.0, 1),
                                           FloorCylinder(0.135, 0.0, 0.385, 0.0, 2)};
  for (const JoiningStrategy strategy : {JoiningStrategy::kGreedy, JoiningStrategy::kGlobal}) {
    const std::vector<Tube> tubes = JoinTubes(cylinders, NoVisibility(strategy), nullptr);
    ASSERT_EQ(tubes.size(), 2u);
    EXPECT_NEAR(tubes[0].length(), 0.51, kTol);
    EXPECT_NEAR(tubes[1].length(), 0.25, kTol);
  }
}

TEST(JoinTubes, NoCyclesAndEachEndpointUsedOnce) {
  // Four cylinders on the sides of a square with 2 cm corner gaps: joining all four corners
  // would close a ring, so one corner must stay open.
  const std::vector<Cylinder> cylinders = {
      FloorCylinder(-0.08, -0.1, 0.08, -0.1, 0), FloorCylinder(0.1, -0.08, 0.1, 0.08, 1),
      FloorCylinder(0.08, 0.1, -0.08, 0.1, 2), FloorCylinder(-0.1, 0.08, -0.1, -0.08, 3)};
  for (const JoiningStrategy strategy : {JoiningStrategy::kGreedy, JoiningStrategy::kGlobal}) {
    JoiningParams params = NoVisibility(strategy);
    params.max_tube_length = 0.0;
    params.max_angle = kPi;  // corners are 90° turns
    const std::vector<Tube> tubes = JoinTubes(cylinders, params, nullptr);
    ASSERT_EQ(tubes.size(), 1u);
    ASSERT_EQ(tubes[0].cylinders.size(), 4u);
    for (std::size_t i = 0; i + 1 < 4; ++i) {
      EXPECT_NEAR((tubes[0].cylinders[i + 1].start - tubes[0].cylinders[i].end).norm(), 0.02 * std::sqrt(2.0),
                  kTol);
    }
  }
}

// Four cylinders around a crossing point. b (B's end) touches a (A's end): 1.1 cm, below the
// radius shortcut, so it is the cheapest pair (0.011). The straight continuations a–c (A→C)
// and b–e (B→E) cost 0.04 each. Greedy takes a–b first and blocks both; the global strategy
// prefers the two joins (benefit 2·(B − 0.04) > B − 0.011).
struct GreedyTrap {
  std::vector<Cylinder> cylinders = {FloorCylinder(-0.3, 0.0, 0.0, 0.0, 0),         // A, a = end
                                     FloorCylinder(0.005, 0.3, 0.005, 0.01, 1),     // B, b = end
                                     FloorCylinder(0.04, 0.0, 0.28, 0.0, 2),        // C, c = start
                                     FloorCylinder(0.005, -0.03, 0.005, -0.3, 3)};  // E, e = start
  JoiningParams Params(JoiningStrategy strategy) const {
    JoiningParams params = NoVisibility(strategy);
    params.max_angle = kPi / 3.0;  // 60°: the skew pairs (≥ 74°) are no candidates
    params.max_tube_length = 0.8;
    return params;
  }
};

TEST(JoinTubes, GreedyTrapPremise) {
  const GreedyTrap trap;
  const JoiningParams params = trap.Params(JoiningStrategy::kGreedy);
  const auto& c = trap.cylinders;
  const JoinDistance ab = EndpointDistance(c[0].end, c[0].axis(), c[1].end, c[1].axis(), kR, params);
  const JoinDistance ac = EndpointDistance(c[0].end, c[0].axis(), c[2].start, -c[2].axis(), kR, params);
  const JoinDistance be = EndpointDistance(c[1].end, c[1].axis(), c[3].start, -c[3].axis(), kR, params);
  EXPECT_EQ(ab.angular, 0.0);
  EXPECT_NEAR(ab.combined, std::hypot(0.005, 0.01), kTol);
  EXPECT_NEAR(ac.combined, 0.04, kTol);
  EXPECT_NEAR(be.combined, 0.04, kTol);
  const JoinDistance ce = EndpointDistance(c[2].start, -c[2].axis(), c[3].start, -c[3].axis(), kR, params);
  EXPECT_GT(ce.angular, params.max_angle);
}

TEST(JoinTubes, GreedyMisJoinsWhereGlobalDoesNot) {
  const GreedyTrap trap;
  const std::vector<Tube> greedy = JoinTubes(trap.cylinders, trap.Params(JoiningStrategy::kGreedy), nullptr);
  ASSERT_EQ(greedy.size(), 3u);
  EXPECT_EQ(IdSets(greedy)[0], (std::set<std::uint32_t>{0, 1}));  // the mis-join, 0.61 m
  EXPECT_EQ(Ids(greedy)[1], (std::vector<std::uint32_t>{3}));
  EXPECT_EQ(Ids(greedy)[2], (std::vector<std::uint32_t>{2}));
  ExpectIdsAreSequential(greedy);

  const std::vector<Tube> global = JoinTubes(trap.cylinders, trap.Params(JoiningStrategy::kGlobal), nullptr);
  ASSERT_EQ(global.size(), 2u);
  EXPECT_EQ(Ids(global)[0], (std::vector<std::uint32_t>{1, 3}));  // B→E, 0.60 m
  EXPECT_EQ(Ids(global)[1], (std::vector<std::uint32_t>{0, 2}));  // A→C, 0.58 m
  EXPECT_NEAR(global[0].length(), 0.60, kTol);
  EXPECT_NEAR(global[1].length(), 0.58, kTol);
  ExpectIdsAreSequential(global);
}

TEST(JoinTubes, DeterministicOutputs) {
  const GreedyTrap trap;
  for (const JoiningStrategy strategy : {JoiningStrategy::kGreedy, JoiningStrategy::kGlobal}) {
    const std::vector<Tube> first = JoinTubes(trap.cylinders, trap.Params(strategy), nullptr);
    const std::vector<Tube> second = JoinTubes(trap.cylinders, trap.Params(strategy), nullptr);
    ASSERT_EQ(first.size(), second.size());
    for (std::size_t t = 0; t < first.size(); ++t) {
      EXPECT_EQ(first[t].id, second[t].id);
      ASSERT_EQ(first[t].cylinders.size(), second[t].cylinders.size());
      for (std::size_t k = 0; k < first[t].cylinders.size(); ++k) {
        EXPECT_EQ(first[t].cylinders[k].start, second[t].cylinders[k].start);
        EXPECT_EQ(first[t].cylinders[k].end, second[t].cylinders[k].end);
      }
    }
    // The input order does not change which cylinders form a tube (no ties here).
    std::vector<Cylinder> reversed(trap.cylinders.rbegin(), trap.cylinders.rend());
    EXPECT_EQ(IdSets(JoinTubes(reversed, trap.Params(strategy), nullptr)), IdSets(first));
  }
}

// Random bins of 20 bent tubes, each seen as three cylinders: both strategies keep every
// constraint, and the global objective Σ(B − combined) is never below the greedy one.
TEST(JoinTubes, GlobalNeverWorseThanGreedyOnRandomBins) {
  for (std::uint32_t seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE(::testing::Message() << "seed " << seed);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::vector<Cylinder> cylinders;
    for (std::uint32_t t = 0; t < 20; ++t) {
      Eigen::Vector3d p(-0.3 + 0.6 * unit(rng), -0.2 + 0.4 * unit(rng), kR + 0.1 * unit(rng));
      double heading = 2.0 * kPi * unit(rng);
      for (int k = 0; k < 3; ++k) {
        const Eigen::Vector3d d(std::cos(heading), std::sin(heading), 0.0);
        const Eigen::Vector3d q = p + 0.15 * d;
        Cylinder c = MakeCylinder(p + 0.01 * d, q - 0.01 * d, static_cast<std::uint32_t>(cylinders.size()));
        if (unit(rng) < 0.5) std::swap(c.start, c.end);
        cylinders.push_back(c);
        p = q;
        heading += (unit(rng) - 0.5) * kPi / 3.0;
      }
    }
    JoiningParams params = NoVisibility();
    const double max_cost = params.max_distance + params.angular_weight * params.max_angle;
    double objective[2] = {0.0, 0.0};
    for (const JoiningStrategy strategy : {JoiningStrategy::kGreedy, JoiningStrategy::kGlobal}) {
      params.strategy = strategy;
      const std::vector<Tube> tubes = JoinTubes(cylinders, params, nullptr);
      ExpectIdsAreSequential(tubes);
      std::size_t count = 0;
      for (const Tube& tube : tubes) {
        count += tube.cylinders.size();
        if (tube.cylinders.size() > 1) {
          EXPECT_LE(tube.length(), params.max_tube_length + kTol);
        }
        for (std::size_t i = 0; i + 1 < tube.cylinders.size(); ++i) {
          const Cylinder& c0 = tube.cylinders[i];
          const Cylinder& c1 = tube.cylinders[i + 1];
          const JoinDistance d = EndpointDistance(c0.end, c0.axis(), c1.start, -c1.axis(), kR, params);
          EXPECT_LE(d.euclidean, params.max_distance);
          EXPECT_LE(d.angular, params.max_angle);
          objective[strategy == JoiningStrategy::kGlobal] += max_cost - d.combined;
        }
      }
      EXPECT_EQ(count, cylinders.size());
    }
    // (The library's B exceeds max_cost by a hair, hence the tolerance.)
    EXPECT_GE(objective[1], objective[0] - 1e-6);
  }
}

TEST(JoinTubes, RejectsInvalidParamsNamingTheKey) {
  const std::vector<Cylinder> cylinders = {FloorCylinder(0.0, 0.0, 0.2, 0.0, 0)};
  struct Case {
    const char* key;
    void (*set)(JoiningParams*);
    const char* value;
  };
  const Case cases[] = {
      {"joining.max_distance", [](JoiningParams* p) { p->max_distance = -0.1; }, "-0.1"},
      {"joining.max_angle", [](JoiningParams* p) { p->max_angle = 7.0; }, "7"},
      {"joining.angular_weight", [](JoiningParams* p) { p->angular_weight = std::nan(""); }, "nan"},
      {"joining.max_tube_length", [](JoiningParams* p) { p->max_tube_length = -1.0; }, "-1"},
      {"joining.radius_shortcut", [](JoiningParams* p) { p->radius_shortcut = -0.01; }, "-0.01"},
      {"joining.visibility_pixel_angle", [](JoiningParams* p) { p->visibility_pixel_angle = 0.0; }, "0"},
      {"joining.visibility_min_gap", [](JoiningParams* p) { p->visibility_min_gap = -0.5; }, "-0.5"},
      {"joining.visibility_window", [](JoiningParams* p) { p->visibility_window = 5000; }, "5000"},
  };
  for (const Case& c : cases) {
    JoiningParams params;
    c.set(&params);
    try {
      JoinTubes(cylinders, params, nullptr);
      ADD_FAILURE() << "expected InvalidArgument for " << c.key;
    } catch (const InvalidArgument& e) {
      EXPECT_THAT(e.what(), HasSubstr(c.key));
      EXPECT_THAT(e.what(), HasSubstr(c.value));
    }
  }
}

TEST(JoinTubes, RejectsNonFiniteCylinderNamingIt) {
  std::vector<Cylinder> cylinders = {FloorCylinder(0.0, 0.0, 0.2, 0.0, 0),
                                     FloorCylinder(0.3, 0.0, 0.5, 0.0, 1)};
  cylinders[1].end.x() = std::numeric_limits<double>::quiet_NaN();
  try {
    JoinTubes(cylinders, NoVisibility(), nullptr);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("cylinders[1]"));
  }
}

TEST(JoinTubes, StopsWhenCancelled) {
  StopToken stop;
  stop.RequestStop();
  const GreedyTrap trap;
  try {
    JoinTubes(trap.cylinders, trap.Params(JoiningStrategy::kGlobal), nullptr, &stop);
    FAIL() << "expected Cancelled";
  } catch (const Cancelled& e) {
    EXPECT_THAT(e.what(), HasSubstr("joining"));
    EXPECT_FALSE(e.deadline_exceeded());
  }
}

}  // namespace
}  // namespace tubepick

#include "core/planning/trajectory_synthesis.h"

#include <cmath>
#include <limits>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/planning/classification.h"
#include "core/planning/test/planning_test_util.h"

namespace tubepick {
namespace {

using namespace testing_planning;  // NOLINT
constexpr double kTol = 1e-12;

// A zone too large to shorten anything.
SafetyZone HugeZone() {
  BinConfig bin;
  bin.inner_size = Eigen::Vector3d(4.0, 4.0, 0.2);
  return MakeSafetyZone(bin, 0.0);
}

// A tube along x split at x ∈ [−0.02, 0.02]: first section two cylinders (−0.20, 0.05) →
// (−0.10, 0) → (−0.02, 0), second (0.02, 0) → (0.12, 0).
Tube WeakAlongX(double shift_x = 0.0) {
  return MakeTube(0, {FlatCylinder(-0.20 + shift_x, 0.05, -0.10 + shift_x, 0.0, 1),
                      FlatCylinder(-0.10 + shift_x, 0.0, -0.02 + shift_x, 0.0, 1),
                      FlatCylinder(0.02 + shift_x, 0.0, 0.12 + shift_x, 0.0, 2)});
}

void ExpectVec(const Eigen::Vector3d& actual, const Eigen::Vector3d& expected, double tol = kTol) {
  EXPECT_NEAR(actual.x(), expected.x(), tol);
  EXPECT_NEAR(actual.y(), expected.y(), tol);
  EXPECT_NEAR(actual.z(), expected.z(), tol);
}

TEST(TrajectorySynthesis, UpwardWaypoints) {
  const Tube tube = WeakAlongX();
  const Trajectory t = UpwardTrajectory(3, tube, TrajectoryParams{});
  EXPECT_EQ(t.tube_index, 3u);
  EXPECT_EQ(t.kind, TrajectoryKind::kUpward);
  ASSERT_EQ(t.waypoints.size(), 2u);
  ExpectVec(t.waypoints[0], Eigen::Vector3d::Zero());
  ExpectVec(t.waypoints[1], Eigen::Vector3d(0, 0, 0.40));
  EXPECT_EQ(t.section_begin, 0u);
  EXPECT_EQ(t.section_end, 3u);
}

TEST(TrajectorySynthesis, EscapeLineIsJointProjection) {
  // Joint from (0, 0, r) to (0.03, 0.04, 3r): the xy projection has direction (0.6, 0.8).
  const Tube tube = MakeTube(0, {MakeCylinder({-0.12, -0.01, kR}, {0, 0, kR}, 1),
                                 MakeCylinder({0.03, 0.04, 3 * kR}, {0.09, 0.12, 3 * kR}, 2)});
  const auto u = EscapeLineDirection(tube, 0);
  ASSERT_TRUE(u.has_value());
  ExpectVec(*u, Eigen::Vector3d(0.6, 0.8, 0.0));
}

TEST(TrajectorySynthesis, EscapeDistancesHandCalculation) {
  const Tube tube = MakeTube(0, {MakeCylinder({-0.12, -0.01, kR}, {0, 0, kR}, 1),
                                 MakeCylinder({0.03, 0.04, kR}, {0.09, 0.12, kR}, 2)});
  const double d_const = 0.0375;
  const auto c = EscapeCandidates(tube, 0, d_const, HugeZone());
  ASSERT_TRUE(c.has_value());
  // Towards the end (+u): the first section trails; occl = (0, 0); proj of (−0.12, −0.01) on
  // u = (0.6, 0.8) is −0.072 − 0.008 = −0.08 ⇒ d_var = 0.08.
  const EscapeCandidate& fwd = (*c)[0];
  EXPECT_TRUE(fwd.towards_end);
  ExpectVec(fwd.direction, Eigen::Vector3d(0.6, 0.8, 0));
  EXPECT_NEAR(fwd.variable_distance, 0.08, kTol);
  EXPECT_NEAR(fwd.escape_distance, 0.08 + d_const, kTol);
  EXPECT_NEAR(fwd.distance, 0.08 + d_const, kTol);
  EXPECT_EQ(fwd.trailing, (CylinderRange{0, 1}));
  EXPECT_EQ(fwd.leading, (CylinderRange{1, 2}));
  // Towards the start (−u): the second section trails; occl = (0.03, 0.04); (0.09, 0.12) −
  // (0.03, 0.04) = (0.06, 0.08) projects to 0.036 + 0.064 = 0.1.
  const EscapeCandidate& bwd = (*c)[1];
  EXPECT_FALSE(bwd.towards_end);
  ExpectVec(bwd.direction, Eigen::Vector3d(-0.6, -0.8, 0));
  EXPECT_NEAR(bwd.variable_distance, 0.10, kTol);
  EXPECT_NEAR(bwd.distance, 0.10 + d_const, kTol);
  EXPECT_EQ(bwd.trailing, (CylinderRange{1, 2}));
  EXPECT_EQ(bwd.leading, (CylinderRange{0, 1}));
}

TEST(TrajectorySynthesis, WeakTubeGetsUpwardAndTwoEscapes) {
  const Tube tube = WeakAlongX();
  const ClassificationResult cls = ClassifyTubes({tube}, 0.0, {});
  ASSERT_EQ(cls.classes[0].occlusion, Occlusion::kWeak);
  TrajectoryParams params;  // d_const = 3r = 0.0375
  const std::vector<Trajectory> ts = SynthesizeTrajectories(0, tube, cls.classes[0], kR, HugeZone(), params);
  ASSERT_EQ(ts.size(), 3u);
  EXPECT_EQ(ts[0].kind, TrajectoryKind::kUpward);

  // Towards +x: trailing cylinders 0–1, occl = (−0.02, 0): farthest endpoint x = −0.20 ⇒
  // d_var = 0.18, d_escape = 0.2175; grasps on the leading cylinder 2.
  const Trajectory& fwd = ts[1];
  EXPECT_EQ(fwd.kind, TrajectoryKind::kEscape);
  ExpectVec(fwd.escape_direction, Eigen::Vector3d(1, 0, 0));
  EXPECT_EQ(fwd.section_begin, 2u);
  EXPECT_EQ(fwd.section_end, 3u);
  ASSERT_EQ(fwd.waypoints.size(), 4u);
  ExpectVec(fwd.waypoints[0], Eigen::Vector3d::Zero());
  ExpectVec(fwd.waypoints[1], Eigen::Vector3d(0, 0, 0.02));
  ExpectVec(fwd.waypoints[2], Eigen::Vector3d(0.2175, 0, 0.02));
  ExpectVec(fwd.waypoints[3], Eigen::Vector3d(0.2175, 0, 0.42));

  // Towards −x: trailing cylinder 2, occl = (0.02, 0): farthest x = 0.12 ⇒ d_var = 0.10.
  const Trajectory& bwd = ts[2];
  ExpectVec(bwd.escape_direction, Eigen::Vector3d(-1, 0, 0));
  EXPECT_EQ(bwd.section_begin, 0u);
  EXPECT_EQ(bwd.section_end, 2u);
  ExpectVec(bwd.waypoints[2], Eigen::Vector3d(-0.1375, 0, 0.02));
  ExpectVec(bwd.waypoints[3], Eigen::Vector3d(-0.1375, 0, 0.42));
}

TEST(TrajectorySynthesis, ExplicitConstantDistance) {
  const Tube tube = WeakAlongX();
  const ClassificationResult cls = ClassifyTubes({tube}, 0.0, {});
  TrajectoryParams params;
  params.escape_constant = 0.05;
  const std::vector<Trajectory> ts = SynthesizeTrajectories(0, tube, cls.classes[0], kR, HugeZone(), params);
  ASSERT_EQ(ts.size(), 3u);
  EXPECT_NEAR(ts[1].waypoints[2].x(), 0.18 + 0.05, kTol);
}

TEST(TrajectorySynthesis, NonOccludedGetsOnlyUpward) {
  const Tube tube = MakeTube(0, {FlatCylinder(0, 0, 0.3, 0, 1)});
  const ClassificationResult cls = ClassifyTubes({tube}, 0.0, {});
  const std::vector<Trajectory> ts = SynthesizeTrajectories(0, tube, cls.classes[0], kR, HugeZone(), {});
  ASSERT_EQ(ts.size(), 1u);
  EXPECT_EQ(ts[0].kind, TrajectoryKind::kUpward);
}

TEST(TrajectorySynthesis, SafetyZoneZoneIsBinMinusMargin) {
  BinConfig bin;  // 0.80 × 0.60
  const SafetyZone zone = MakeSafetyZone(bin, 0.05);
  EXPECT_NEAR(zone.min.x(), -0.35, kTol);
  EXPECT_NEAR(zone.max.x(), 0.35, kTol);
  EXPECT_NEAR(zone.min.y(), -0.25, kTol);
  EXPECT_NEAR(zone.max.y(), 0.25, kTol);
}

TEST(TrajectorySynthesis, SafetyZoneShortensEscape) {
  // Shifted by +0.1: the xy bounding box spans x ∈ [−0.1125, 0.2325]. With the zone x ≤ 0.35
  // the +x escape (0.2175) is shortened to 0.35 − 0.2325 = 0.1175; the −x escape (0.1375) fits
  // (its limit is −0.35 − (−0.1125) over −1 = 0.2375).
  const Tube tube = WeakAlongX(0.1);
  BinConfig bin;
  const SafetyZone zone = MakeSafetyZone(bin, 0.05);
  const auto c = EscapeCandidates(tube, 1, 0.0375, zone);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR((*c)[0].escape_distance, 0.2175, kTol);
  EXPECT_NEAR((*c)[0].zone_limit, 0.1175, kTol);
  EXPECT_NEAR((*c)[0].distance, 0.1175, kTol);
  EXPECT_NEAR((*c)[1].zone_limit, 0.2375, kTol);
  EXPECT_NEAR((*c)[1].distance, 0.1375, kTol);

  const ClassificationResult cls = ClassifyTubes({tube}, 0.0, {});
  const std::vector<Trajectory> ts = SynthesizeTrajectories(0, tube, cls.classes[0], kR, zone, {});
  ASSERT_EQ(ts.size(), 3u);
  EXPECT_NEAR(ts[1].waypoints[3].x(), 0.1175, kTol);
  // The moved bounding box touches the zone edge.
  EXPECT_NEAR(TubeBoundingBoxXy(tube).max.x() + ts[1].waypoints[3].x(), zone.max.x(), kTol);
}

TEST(TrajectorySynthesis, SafetyZoneLimitDiagonal) {
  // Box x ∈ [−0.0125, 0.1125], y ∈ [−0.0125, 0.0125]; zone ±0.2. Along (0.6, 0.8):
  // x limit (0.2 − 0.1125)/0.6 = 0.14583…, y limit (0.2 − 0.0125)/0.8 = 0.234375 ⇒ x binds.
  // Along (−0.6, −0.8): x limit 0.1875/0.6 = 0.3125, y limit 0.1875/0.8 = 0.234375 ⇒ y binds.
  const Tube tube = MakeTube(0, {FlatCylinder(0, 0, 0.1, 0, 1)});
  SafetyZone zone;
  zone.min = Eigen::Vector2d(-0.2, -0.2);
  zone.max = Eigen::Vector2d(0.2, 0.2);
  EXPECT_NEAR(SafetyZoneLimit(tube, Eigen::Vector3d(0.6, 0.8, 0), zone), 0.0875 / 0.6, kTol);
  EXPECT_NEAR(SafetyZoneLimit(tube, Eigen::Vector3d(-0.6, -0.8, 0), zone), 0.1875 / 0.8, kTol);
  EXPECT_EQ(SafetyZoneLimit(tube, Eigen::Vector3d(0, 0, 1), zone), std::numeric_limits<double>::infinity());
}

TEST(TrajectorySynthesis, EscapeIntoWallIsDropped) {
  // The tube already pokes past the zone's +x side: the +x escape cannot move at all and is
  // dropped; the −x escape (away from the wall) is kept.
  const Tube tube = WeakAlongX(0.25);  // box max x = 0.3825 > 0.35
  const SafetyZone zone = MakeSafetyZone(BinConfig{}, 0.05);
  const auto c = EscapeCandidates(tube, 1, 0.0375, zone);
  ASSERT_TRUE(c.has_value());
  EXPECT_LT((*c)[0].zone_limit, 0.0);
  EXPECT_EQ((*c)[0].distance, 0.0);
  const ClassificationResult cls = ClassifyTubes({tube}, 0.0, {});
  const std::vector<Trajectory> ts = SynthesizeTrajectories(0, tube, cls.classes[0], kR, zone, {});
  ASSERT_EQ(ts.size(), 2u);
  EXPECT_EQ(ts[1].escape_direction.x(), -1.0);
}

TEST(TrajectorySynthesis, StrongOcclusionEscapes) {
  // Joints 0 (x −0.15 → −0.11) and 1 (x 0.05 → 0.09).
  const Tube tube = MakeTube(0, {FlatCylinder(-0.25, 0, -0.15, 0, 1), FlatCylinder(-0.11, 0, 0.05, 0, 2),
                                 FlatCylinder(0.09, 0, 0.25, 0, 3)});
  const ClassificationResult cls = ClassifyTubes({tube}, 0.0, {});
  ASSERT_EQ(cls.classes[0].occlusion, Occlusion::kStrong);
  const std::vector<Trajectory> ts = SynthesizeTrajectories(0, tube, cls.classes[0], kR, HugeZone(), {});
  ASSERT_EQ(ts.size(), 3u);
  EXPECT_EQ(ts[0].kind, TrajectoryKind::kUpward);
  // Joint 0: towards +x drags cylinder 0 (d_var 0.10) vs towards −x cylinders 1–2 (0.36): +x,
  // grasps beyond the last occluded joint: cylinder 2.
  EXPECT_EQ(ts[1].kind, TrajectoryKind::kOcclusionEscape);
  ExpectVec(ts[1].escape_direction, Eigen::Vector3d(1, 0, 0));
  EXPECT_NEAR(ts[1].waypoints[2].x(), 0.10 + 3 * kR, kTol);
  EXPECT_EQ(ts[1].section_begin, 2u);
  EXPECT_EQ(ts[1].section_end, 3u);
  // Joint 1: +x drags cylinders 0–1 (0.30) vs −x cylinder 2 (0.16): −x, grasps on cylinder 0.
  ExpectVec(ts[2].escape_direction, Eigen::Vector3d(-1, 0, 0));
  EXPECT_NEAR(ts[2].waypoints[2].x(), -(0.16 + 3 * kR), kTol);
  EXPECT_EQ(ts[2].section_begin, 0u);
  EXPECT_EQ(ts[2].section_end, 1u);

  TrajectoryParams off;
  off.occlusion_escapes = false;
  EXPECT_EQ(SynthesizeTrajectories(0, tube, cls.classes[0], kR, HugeZone(), off).size(), 1u);
}

TEST(TrajectorySynthesis, VerticalJointFallsBackToTubeDirection) {
  // Joint endpoints differ only in z: the escape line follows the cylinders' direction.
  const Tube tube = MakeTube(
      0, {MakeCylinder({-0.2, 0, kR}, {0, 0, kR}, 1), MakeCylinder({0, 0, 3 * kR}, {0.2, 0, 3 * kR}, 2)});
  const auto u = EscapeLineDirection(tube, 0);
  ASSERT_TRUE(u.has_value());
  ExpectVec(*u, Eigen::Vector3d(1, 0, 0));
}

}  // namespace
}  // namespace tubepick

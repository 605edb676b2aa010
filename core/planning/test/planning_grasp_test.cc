// Grasp synthesis, the three grasp filters and the cost / ranking (thesis §5.2.4).

#include <algorithm>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/planning/grasp_filters.h"
#include "core/planning/grasp_ranking.h"
#include "core/planning/grasp_synthesis.h"
#include "core/planning/test/planning_test_util.h"
#include "core/planning/trajectory_synthesis.h"

namespace tubepick {
namespace {

using namespace testing_planning;  // NOLINT
constexpr double kTol = 1e-12;
constexpr double kPi = 3.14159265358979323846;

// ---------------------------------------------------------------- synthesis

TEST(GraspSynthesis, PointsSpacedAndAwayFromBases) {
  // Length 0.10, m = 0.02, spacing 0.02: usable [0.02, 0.08] ⇒ 4 points at 0.02 … 0.08.
  const Tube tube = MakeTube(0, {FlatCylinder(0.0, 0.0, 0.10, 0.0, 1)});
  const std::vector<Grasp> grasps = SynthesizeGrasps(tube, GraspParams{});
  ASSERT_EQ(grasps.size(), 4u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(grasps[k].p_Bin_grasp.x(), 0.02 + 0.02 * k, kTol);
    EXPECT_NEAR(grasps[k].p_Bin_grasp.z(), kR, kTol);
    EXPECT_NEAR(grasps[k].curve_position, 0.02 + 0.02 * k, kTol);
    EXPECT_EQ(grasps[k].cylinder_index, 0u);
  }
}

TEST(GraspSynthesis, PointsCentredInUsableStretch) {
  // Length 0.11: usable 0.07 holds 4 points (0.06 apart end to end), centred: 0.025 … 0.085.
  const Tube tube = MakeTube(0, {FlatCylinder(0.0, 0.0, 0.11, 0.0, 1)});
  const std::vector<Grasp> grasps = SynthesizeGrasps(tube, GraspParams{});
  ASSERT_EQ(grasps.size(), 4u);
  EXPECT_NEAR(grasps.front().p_Bin_grasp.x(), 0.025, kTol);
  EXPECT_NEAR(grasps.back().p_Bin_grasp.x(), 0.085, kTol);
}

TEST(GraspSynthesis, ShortCylinderHasNoGrasp) {
  const Tube tube = MakeTube(0, {FlatCylinder(0.0, 0.0, 0.03, 0.0, 1)});
  EXPECT_TRUE(SynthesizeGrasps(tube, GraspParams{}).empty());
  // Exactly 2m long: one grasp in the middle.
  const Tube exact = MakeTube(0, {FlatCylinder(0.0, 0.0, 0.04, 0.0, 1)});
  const std::vector<Grasp> one = SynthesizeGrasps(exact, GraspParams{});
  ASSERT_EQ(one.size(), 1u);
  EXPECT_NEAR(one[0].p_Bin_grasp.x(), 0.02, kTol);
}

TEST(GraspSynthesis, CurvePositionIncludesJoints) {
  // Cylinder 1 starts after 0.10 + 0.04 (joint) of curve.
  const Tube tube =
      MakeTube(0, {FlatCylinder(0.0, 0.0, 0.10, 0.0, 1), FlatCylinder(0.14, 0.0, 0.24, 0.0, 2)});
  const std::vector<Grasp> grasps = SynthesizeGrasps(tube, GraspParams{});
  ASSERT_EQ(grasps.size(), 8u);
  EXPECT_EQ(grasps[4].cylinder_index, 1u);
  EXPECT_NEAR(grasps[4].curve_position, 0.16, kTol);
  EXPECT_NEAR(grasps[4].p_Bin_grasp.x(), 0.16, kTol);
}

TEST(GraspSynthesis, VerticalApproachFingersCloseAcrossTheTube) {
  // A cylinder along (−1, 1, 0.2)/|…|.
  const Tube tube = MakeTube(0, {MakeCylinder({0.1, -0.1, kR}, {-0.1, 0.1, kR + 0.04}, 1)});
  const std::vector<Grasp> grasps = SynthesizeGrasps(tube, GraspParams{});
  ASSERT_FALSE(grasps.empty());
  const Eigen::Vector3d axis = tube.cylinders[0].axis();
  for (const Grasp& g : grasps) {
    const Eigen::Matrix3d R = g.X_BinTcp.linear();
    EXPECT_NEAR((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 0.0, 1e-12);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12);
    // z_Tcp = approach = down.
    EXPECT_NEAR((R.col(2) - Eigen::Vector3d(0, 0, -1)).norm(), 0.0, 1e-12);
    EXPECT_NEAR((g.approach_Bin - Eigen::Vector3d(0, 0, -1)).norm(), 0.0, 1e-12);
    // Closing direction y_Tcp horizontal and ⟂ the axis' xy projection.
    EXPECT_NEAR(R.col(1).z(), 0.0, 1e-12);
    EXPECT_NEAR(R.col(1).dot(Eigen::Vector3d(axis.x(), axis.y(), 0.0)), 0.0, 1e-12);
    // Yaw normalised: x_Tcp·x_Bin > 0.
    EXPECT_GT(R.col(0).x(), 0.0);
    EXPECT_NEAR((g.X_BinTcp.translation() - g.p_Bin_grasp).norm(), 0.0, kTol);
    EXPECT_DOUBLE_EQ(g.opening_width, GraspParams{}.opening_width);
  }
}

TEST(GraspSynthesis, FrameAlongY) {
  const auto X = GraspFrame(Eigen::Vector3d(0, 0, 0.1), Eigen::Vector3d(0, -1, 0));
  ASSERT_TRUE(X.has_value());
  EXPECT_NEAR((X->linear().col(0) - Eigen::Vector3d(0, 1, 0)).norm(), 0.0, kTol);
  EXPECT_NEAR((X->linear().col(1) - Eigen::Vector3d(1, 0, 0)).norm(), 0.0, kTol);
  EXPECT_FALSE(GraspFrame(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1)).has_value());
}

TEST(GraspSynthesis, SteepCylinderSkipped) {
  // 70° above the horizontal, limit 60°.
  const double a = 70.0 * kPi / 180.0;
  const Tube tube =
      MakeTube(0, {MakeCylinder({0, 0, kR}, {0.2 * std::cos(a), 0, kR + 0.2 * std::sin(a)}, 1)});
  EXPECT_TRUE(SynthesizeGrasps(tube, GraspParams{}).empty());
  GraspParams steep;
  steep.max_axis_inclination = 80.0 * kPi / 180.0;
  EXPECT_FALSE(SynthesizeGrasps(tube, steep).empty());
}

// ---------------------------------------------------------------- (a) finger boxes

Grasp GraspOnXTube(double x) {
  const Tube tube = MakeTube(0, {FlatCylinder(-0.2, 0.0, 0.2, 0.0, 1)});
  for (const Grasp& g : SynthesizeGrasps(tube, GraspParams{})) {
    if (std::abs(g.p_Bin_grasp.x() - x) < 1e-9) return g;
  }
  ADD_FAILURE() << "no grasp at x = " << x;
  return Grasp{};
}

// The tube's own top surface (y within ±r, z = 2r) and a floor patch: never in the fingers.
Points TubeAndFloor() {
  Points pts;
  for (double x = -0.2; x <= 0.2; x += 0.002) {
    for (double y = -kR; y <= kR; y += 0.002) {
      pts.emplace_back(x, y, 2 * kR - (y * y) / (2 * kR) * 0.5);
    }
    for (double y = -0.1; y <= 0.1; y += 0.004) pts.emplace_back(x, y, 0.0005f);
  }
  return pts;
}

// `n` points in the +y finger's volume around the grasp at x (fingers at |y| ∈ [0.0225, 0.0325],
// z ∈ [0.0075, 0.0575]).
void AddFingerPoints(Points* pts, double x, int n) {
  for (int i = 0; i < n; ++i) pts->emplace_back(x - 0.005 + 0.0003 * i, 0.028, 0.03);
}

TEST(GraspFilters, FingerBoxesGeometry) {
  const Grasp g = GraspOnXTube(0.0);
  const auto boxes = FingerBoxes(g, GraspFilterParams{});
  // Centres at y = ±(0.045 + 0.01)/2, z = r + (0.05/2 − 0.005) (the TCP z points down).
  std::vector<double> ys = {boxes[0].X_BinBox.translation().y(), boxes[1].X_BinBox.translation().y()};
  std::sort(ys.begin(), ys.end());
  EXPECT_NEAR(ys[0], -0.0275, kTol);
  EXPECT_NEAR(ys[1], 0.0275, kTol);
  EXPECT_NEAR(boxes[0].X_BinBox.translation().z(), kR + 0.02, kTol);
  EXPECT_TRUE(boxes[0].Contains(boxes[0].X_BinBox.translation()));
  EXPECT_FALSE(boxes[0].Contains(g.p_Bin_grasp));
}

TEST(GraspFilters, FingersCollideWithNeighbourPoints) {
  const GraspFilterParams params;  // max 20 points
  Points pts = TubeAndFloor();
  AddFingerPoints(&pts, 0.0, 21);
  const RawCloudIndex raw(pts, params.grid_cell_size);
  EXPECT_TRUE(FingersCollide(GraspOnXTube(0.0), raw, params));
  // A grasp 10 cm away sees only the tube and the floor.
  EXPECT_FALSE(FingersCollide(GraspOnXTube(0.1), raw, params));
}

TEST(GraspFilters, FingersToleratePointsUpToTheThreshold) {
  const GraspFilterParams params;
  Points pts = TubeAndFloor();
  AddFingerPoints(&pts, 0.0, 20);
  const RawCloudIndex raw(pts, params.grid_cell_size);
  EXPECT_FALSE(FingersCollide(GraspOnXTube(0.0), raw, params));
  // Split over both fingers: 12 + 12 > 20.
  Points both = TubeAndFloor();
  for (int i = 0; i < 12; ++i) {
    both.emplace_back(-0.005 + 0.0005 * i, 0.028, 0.03);
    both.emplace_back(-0.005 + 0.0005 * i, -0.028, 0.03);
  }
  EXPECT_TRUE(FingersCollide(GraspOnXTube(0.0), RawCloudIndex(both, params.grid_cell_size), params));
}

// A horizontal patch of 30 points (a tube crossing higher up) centred at (x, y, z).
void AddPatch(Points* pts, double x, double y, double z) {
  for (int i = 0; i < 6; ++i) {
    for (int k = 0; k < 5; ++k) pts->emplace_back(x - 0.005 + 0.002 * i, y - 0.004 + 0.002 * k, z);
  }
}

TEST(GraspFilters, ApproachColumnsGeometry) {
  const Grasp g = GraspOnXTube(0.0);  // grasp point at z = r, opening 0.045
  const GraspFilterParams params;     // pads 0.05 high, tips 0.005 below the axis; columns 0.5
  const ToolParams tool;              // housing 0.06 × 0.13 × 0.09, 0.02 above pads 0.05 high
  const auto columns = ApproachColumns(g, params, tool);
  for (int i = 0; i < 2; ++i) {
    // Pads' columns: from the finger box's top (r + 0.045) to r + 0.5, over the finger's footprint.
    const OrientedBox& c = columns[i];
    EXPECT_NEAR(std::abs(c.X_BinBox.translation().y()), 0.0275, kTol);
    EXPECT_NEAR(c.X_BinBox.translation().z() - c.half_size.z(), kR + 0.045, kTol);
    EXPECT_NEAR(c.X_BinBox.translation().z() + c.half_size.z(), kR + 0.5, kTol);
  }
  // The housing's column: from r + 0.05 − 0.005 + 0.02 up, 0.06 along the tube, 0.13 across.
  EXPECT_NEAR(columns[2].X_BinBox.translation().z() - columns[2].half_size.z(), kR + 0.065, kTol);
  EXPECT_NEAR(2 * columns[2].half_size.x(), 0.06, kTol);
  EXPECT_NEAR(2 * columns[2].half_size.y(), 0.13, kTol);
  EXPECT_FALSE(columns[2].Contains(g.p_Bin_grasp));
}

TEST(GraspFilters, ApproachIsBlockedByWhatTheToolMeetsOnItsWayDown) {
  GraspFilterParams params;
  const ToolParams tool;
  Points pts = TubeAndFloor();
  // A tube crossing 8 cm above the grasp at x = 0 (over the housing's footprint, above the pads).
  AddPatch(&pts, 0.0, 0.0, kR + 0.08);
  const RawCloudIndex raw(pts, params.grid_cell_size);
  EXPECT_FALSE(FingersCollide(GraspOnXTube(0.0), raw, params));  // the thesis test sees nothing
  EXPECT_TRUE(ApproachBlocked(GraspOnXTube(0.0), raw, params, tool));
  EXPECT_FALSE(ApproachBlocked(GraspOnXTube(0.1), raw, params, tool));  // 10 cm away: clear
  // Over a pad, 6 cm up (above the finger box, below the housing's bottom).
  Points pad = TubeAndFloor();
  AddPatch(&pad, 0.0, 0.028, kR + 0.06);
  EXPECT_TRUE(ApproachBlocked(GraspOnXTube(0.0), RawCloudIndex(pad, params.grid_cell_size), params, tool));
  // Beyond the column's height, and up to the threshold: clear.
  params.approach_column_height = 0.07;
  EXPECT_FALSE(ApproachBlocked(GraspOnXTube(0.0), raw, params, tool));
  params = GraspFilterParams{};
  params.max_points_in_approach = 30;
  EXPECT_FALSE(ApproachBlocked(GraspOnXTube(0.0), raw, params, tool));
}

TEST(GraspFilters, RawCloudIndexMatchesBruteForce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> ux(-0.4f, 0.4f), uy(-0.3f, 0.3f), uz(0.0f, 0.2f);
  Points pts(20000);
  for (auto& p : pts) p = Eigen::Vector3f(ux(rng), uy(rng), uz(rng));
  pts.emplace_back(std::nanf(""), 0.0f, 0.0f);  // skipped
  const RawCloudIndex raw(pts, 0.01);
  EXPECT_EQ(raw.size(), 20000u);
  std::uniform_real_distribution<double> angle(-kPi, kPi), half(0.005, 0.06);
  for (int trial = 0; trial < 50; ++trial) {
    OrientedBox box;
    box.X_BinBox.linear() = (Eigen::AngleAxisd(angle(rng), Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(0.3 * angle(rng), Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
    box.X_BinBox.translation() = Eigen::Vector3d(ux(rng), uy(rng), uz(rng));
    box.half_size = Eigen::Vector3d(half(rng), half(rng), half(rng));
    std::size_t brute = 0;
    for (const auto& p : pts) {
      if (p.allFinite() && box.Contains(p.cast<double>())) ++brute;
    }
    EXPECT_EQ(raw.CountInBox(box, pts.size()), brute) << "trial " << trial;
  }
}

TEST(GraspFilters, RawCloudIndexEmptyAndWide) {
  const RawCloudIndex empty(Points{}, 0.01);
  OrientedBox box;
  box.half_size = Eigen::Vector3d::Constant(1.0);
  EXPECT_EQ(empty.CountInBox(box, 100), 0u);
  // A cloud spanning 1 km is binned in coarser cells (≤ 4 M) and still counted correctly.
  Points wide = {Eigen::Vector3f(-500, -500, 0), Eigen::Vector3f(500, 500, 0), Eigen::Vector3f(0.01f, 0, 0)};
  const RawCloudIndex raw(wide, 0.01);
  EXPECT_GT(raw.cell_size(), 0.01);
  box.half_size = Eigen::Vector3d(0.05, 0.05, 0.05);
  EXPECT_EQ(raw.CountInBox(box, 100), 1u);
}

TEST(GraspFilters, FingerBandDropsFloorAndKeepsVerdicts) {
  GraspFilterParams params;
  params.approach_check = false;
  const std::vector<Tube> tubes = {MakeTube(0, {FlatCylinder(-0.2, 0.0, 0.2, 0.0, 1)})};
  GraspParams vertical;
  vertical.max_tilt = 0.0;
  const auto [lo, hi] = FingerBandZ(tubes, params, vertical);
  EXPECT_NEAR(lo, kR - 0.005 - 0.001, kTol);
  EXPECT_NEAR(hi, kR - 0.005 + 0.05 + 0.001, kTol);
  // Tilted grasps (30° by default) reach lower and higher by sin 30° · (0.045 / 2 + 0.01).
  const auto [lo_tilted, hi_tilted] = FingerBandZ(tubes, params);
  EXPECT_NEAR(lo_tilted, lo - 0.01625, kTol);
  EXPECT_NEAR(hi_tilted, hi + 0.01625, kTol);
  // With the approach check the band reaches the approach columns' top.
  params.approach_check = true;
  const auto [lo_approach, hi_approach] = FingerBandZ(tubes, params, vertical);
  EXPECT_NEAR(lo_approach, lo, kTol);
  EXPECT_NEAR(hi_approach, kR + 0.5 + 0.001, kTol);
  Points pts = TubeAndFloor();
  AddFingerPoints(&pts, 0.0, 21);
  AddPatch(&pts, 0.1, 0.0, kR + 0.08);
  const RawCloudIndex all(pts, params.grid_cell_size);
  const RawCloudIndex banded(pts, params.grid_cell_size, lo_approach, hi_approach);
  EXPECT_LT(banded.size(), all.size());  // the floor patch is gone
  for (const Grasp& g : SynthesizeGrasps(tubes[0], GraspParams{})) {
    EXPECT_EQ(FingersCollide(g, banded, params), FingersCollide(g, all, params));
    EXPECT_EQ(ApproachBlocked(g, banded, params, ToolParams{}),
              ApproachBlocked(g, all, params, ToolParams{}));
    for (const OrientedBox& box : FingerBoxes(g, params)) {
      EXPECT_EQ(banded.CountInBox(box, pts.size()), all.CountInBox(box, pts.size()));
    }
  }
}

// ---------------------------------------------------------------- (b) workspace

TEST(GraspFilters, WorkspaceRejectsWaypointOutside) {
  const Grasp g = GraspOnXTube(0.1);
  const Tube tube = MakeTube(0, {FlatCylinder(-0.2, 0.0, 0.2, 0.0, 1)});
  GraspFilterParams params;  // z up to 1.0
  TrajectoryParams tp;
  const Trajectory up = UpwardTrajectory(0, tube, tp);
  EXPECT_TRUE(InsideWorkspace(g, up, params));
  params.workspace_max.z() = 0.3;  // r + 0.40 > 0.3
  EXPECT_FALSE(InsideWorkspace(g, up, params));

  // A lateral escape of 0.45 along +x takes the grasp point to x = 0.55 > 0.50.
  EscapeCandidate e;
  e.direction = Eigen::Vector3d(1, 0, 0);
  e.distance = 0.45;
  const Trajectory escape = EscapeTrajectory(0, e, TrajectoryKind::kEscape, CylinderRange{0, 1}, tp);
  EXPECT_FALSE(InsideWorkspace(g, escape, GraspFilterParams{}));
  e.distance = 0.35;
  EXPECT_TRUE(InsideWorkspace(g, EscapeTrajectory(0, e, TrajectoryKind::kEscape, CylinderRange{0, 1}, tp),
                              GraspFilterParams{}));
}

TEST(GraspFilters, WorkspaceRejectsGraspPointOutside) {
  Grasp g = GraspOnXTube(0.0);
  g.p_Bin_grasp = Eigen::Vector3d(0.0, 0.45, kR);  // y > 0.40
  Trajectory t;
  t.waypoints = {Eigen::Vector3d::Zero()};
  EXPECT_FALSE(InsideWorkspace(g, t, GraspFilterParams{}));
}

// ---------------------------------------------------------------- (c) section

TEST(GraspFilters, EscapeGraspMustBeInAllowedSection) {
  const Tube tube =
      MakeTube(0, {FlatCylinder(-0.2, 0.0, -0.02, 0.0, 1), FlatCylinder(0.02, 0.0, 0.2, 0.0, 2)});
  const std::vector<Grasp> grasps = SynthesizeGrasps(tube, GraspParams{});
  Trajectory escape;
  escape.kind = TrajectoryKind::kEscape;
  escape.section_begin = 1;
  escape.section_end = 2;
  int allowed = 0;
  for (const Grasp& g : grasps) {
    EXPECT_EQ(InAllowedSection(g, escape), g.cylinder_index == 1);
    allowed += InAllowedSection(g, escape) ? 1 : 0;
  }
  EXPECT_GT(allowed, 0);
  EXPECT_LT(allowed, static_cast<int>(grasps.size()));
  const Trajectory up = UpwardTrajectory(0, tube, TrajectoryParams{});
  for (const Grasp& g : grasps) EXPECT_TRUE(InAllowedSection(g, up));
}

// ---------------------------------------------------------------- cost and ranking

TEST(GraspRanking, CostTermsHandCalculation) {
  EXPECT_NEAR(HeightCost(0.05, 0.10), 0.5, kTol);
  EXPECT_NEAR(HeightCost(0.20, 0.10), 1.0, kTol);  // clamped
  EXPECT_EQ(HeightCost(0.05, 0.0), 0.0);
  EXPECT_NEAR(CentreCost(0.10, 0.40), 0.5, kTol);
  EXPECT_NEAR(CentreCost(0.30, 0.40), 0.5, kTol);
  EXPECT_NEAR(CentreCost(0.20, 0.40), 0.0, kTol);
  EXPECT_NEAR(CentreCost(0.0, 0.40), 1.0, kTol);
  EXPECT_NEAR(TrajectoryCost(0.25, 1.0), 0.25, kTol);
  EXPECT_NEAR(TrajectoryCost(2.0, 1.0), 1.0, kTol);
  EXPECT_EQ(TrajectoryCost(std::nullopt, 1.0), 0.0);

  // Eq. 5.3 with Table 5.3 weights: 0.2·0.5 + 0.5·0.5 + 0.3·0.25 = 0.425.
  const PlanCosts c = PlanCost(0.05, 0.10, 0.10, 0.40, 0.25, CostParams{});
  EXPECT_NEAR(c.height, 0.5, kTol);
  EXPECT_NEAR(c.centre, 0.5, kTol);
  EXPECT_NEAR(c.trajectory, 0.25, kTol);
  EXPECT_NEAR(c.total, 0.425, kTol);
}

TEST(GraspRanking, CentreCostAlongTheCurve) {
  // A U-shaped tube: 0.2 along +y, 0.1 along +x, 0.2 back along −y (L = 0.5, middle at curve
  // 0.25 = the point (0.05, 0.2)). A grasp at (0, 0.04) on the first leg is 0.21 from the middle
  // along the curve (C = 0.21/0.25 = 0.84) but only |(0.05, 0.16)| = 0.168 in a straight line.
  const Tube tube = MakeTube(0, {FlatCylinder(0.0, 0.0, 0.0, 0.2, 1), FlatCylinder(0.0, 0.2, 0.1, 0.2, 1),
                                 FlatCylinder(0.1, 0.2, 0.1, 0.0, 1)});
  ASSERT_NEAR(tube.length(), 0.5, kTol);
  const std::vector<Grasp> grasps = SynthesizeGrasps(tube, GraspParams{});
  const Grasp* g = nullptr;
  for (const Grasp& c : grasps) {
    if (c.cylinder_index == 0 && std::abs(c.p_Bin_grasp.y() - 0.04) < 1e-9) g = &c;
  }
  ASSERT_NE(g, nullptr);
  EXPECT_NEAR(g->curve_position, 0.04, kTol);
  EXPECT_NEAR(CentreCost(g->curve_position, tube.length()), 0.84, kTol);
}

PickPlan Plan(std::uint32_t tube, double total, std::uint32_t trajectory, double curve) {
  PickPlan p;
  p.tube_id = tube;
  p.costs.total = total;
  p.trajectory_index = trajectory;
  p.grasp.curve_position = curve;
  return p;
}

TEST(GraspRanking, BestFirstWithDeterministicTies) {
  std::vector<PickPlan> plans = {Plan(2, 0.3, 0, 0.1), Plan(1, 0.1, 3, 0.2), Plan(0, 0.1, 5, 0.2),
                                 Plan(0, 0.1, 4, 0.3), Plan(0, 0.1, 4, 0.1), Plan(3, 0.05, 9, 0.0)};
  RankPlans(&plans, CertaintyParams{});
  ASSERT_EQ(plans.size(), 6u);
  EXPECT_EQ(plans[0].tube_id, 3u);
  // Equal totals 0.1: tube 0 before tube 1; within tube 0, trajectory 4 before 5; then curve.
  EXPECT_EQ(plans[1].tube_id, 0u);
  EXPECT_EQ(plans[1].trajectory_index, 4u);
  EXPECT_DOUBLE_EQ(plans[1].grasp.curve_position, 0.1);
  EXPECT_DOUBLE_EQ(plans[2].grasp.curve_position, 0.3);
  EXPECT_EQ(plans[3].trajectory_index, 5u);
  EXPECT_EQ(plans[4].tube_id, 1u);
  EXPECT_EQ(plans[5].tube_id, 2u);
}

}  // namespace
}  // namespace tubepick

namespace tubepick {
namespace {

PickPlan PlanOf(std::uint32_t tube, double total, PlanCertainty certainty, std::optional<double> disp = {}) {
  PickPlan p;
  p.tube_id = tube;
  p.costs.total = total;
  p.certainty = certainty;
  p.displacement = disp;
  return p;
}

std::vector<std::uint32_t> TubeOrder(const std::vector<PickPlan>& plans) {
  std::vector<std::uint32_t> order;
  for (const PickPlan& p : plans) order.push_back(p.tube_id);
  return order;
}

TEST(GraspRanking, SafePlansOutrankPlansThatNeedLuck) {
  const std::vector<PickPlan> plans = {
      PlanOf(0, 0.40, PlanCertainty::kSure),             // safe
      PlanOf(1, 0.10, PlanCertainty::kUnsure),           // occluded, not simulated: T_cost 0
      PlanOf(2, 0.20, PlanCertainty::kSimulated, 0.02),  // simulated, 2 cm: safe
      PlanOf(3, 0.05, PlanCertainty::kSimulated, 0.30),  // simulated, 30 cm: not safe
      PlanOf(4, 0.30, PlanCertainty::kSimulated, 0.05),  // exactly the threshold: safe
  };
  const CertaintyParams rule;
  EXPECT_TRUE(PlanIsSafe(plans[0], rule));
  EXPECT_FALSE(PlanIsSafe(plans[1], rule));
  EXPECT_TRUE(PlanIsSafe(plans[2], rule));
  EXPECT_FALSE(PlanIsSafe(plans[3], rule));
  EXPECT_TRUE(PlanIsSafe(plans[4], rule));

  std::vector<PickPlan> ranked = plans;
  RankPlans(&ranked, rule);
  EXPECT_EQ(TubeOrder(ranked), (std::vector<std::uint32_t>{2, 4, 0, 3, 1}));

  // The threshold is the parameter: at 1 cm only the sure plan is safe.
  CertaintyParams strict;
  strict.safe_displacement = 0.01;
  ranked = plans;
  RankPlans(&ranked, strict);
  EXPECT_EQ(TubeOrder(ranked), (std::vector<std::uint32_t>{0, 3, 1, 2, 4}));

  // Without the rule: G_cost alone (the thesis).
  CertaintyParams off;
  off.safe_first = false;
  ranked = plans;
  RankPlans(&ranked, off);
  EXPECT_EQ(TubeOrder(ranked), (std::vector<std::uint32_t>{3, 1, 2, 4, 0}));
}

TEST(PlanCertainty, TubesLyingOnNeedContactFromAbove) {
  using namespace testing_planning;  // NOLINT
  const std::vector<Tube> tubes = {
      MakeTube(0, {FlatCylinder(-0.2, 0.05, 0.2, 0.05, 1)}),
      // Across tube 0's end, resting on it (axis 2r above tube 0's axis).
      MakeTube(1, {FlatCylinder(0.17, -0.1, 0.17, 0.2, 2, 3.0 * kR)}),
      // Beside tube 0 on the floor, touching it: not on it.
      MakeTube(2, {FlatCylinder(-0.2, 0.05 + 2.0 * kR, 0.1, 0.05 + 2.0 * kR, 3)}),
      // Above tube 0 but 3 cm clear of it: not on it.
      MakeTube(3, {FlatCylinder(-0.1, -0.1, -0.1, 0.2, 4, 3.0 * kR + 0.03)}),
  };
  const CertaintyParams params;
  EXPECT_EQ(TubesLyingOn(tubes, 0, params), (std::vector<std::uint32_t>{1}));
  EXPECT_TRUE(TubesLyingOn(tubes, 1, params).empty());
  EXPECT_TRUE(TubesLyingOn(tubes, 2, params).empty());
  EXPECT_TRUE(TubesLyingOn(tubes, 3, params).empty());
  // Within the margin: 3 cm of margin reaches tube 3.
  CertaintyParams wide;
  wide.contact_margin = 0.031;
  EXPECT_EQ(TubesLyingOn(tubes, 0, wide), (std::vector<std::uint32_t>{1, 3}));
}

}  // namespace
}  // namespace tubepick

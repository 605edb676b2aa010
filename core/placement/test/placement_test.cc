#include "core/placement/placement.h"

#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/common/types.h"
#include "core/testing/error_of.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;

constexpr double kDeg = M_PI / 180.0;
constexpr double kRadius = 0.0125;
// Float points: directions and positions agree to float round-off.
constexpr double kDirectionTol = 1e-5;
constexpr double kPositionTol = 1e-5;
// Analytic quantities (tube models, pose algebra) in double.
constexpr double kExactTol = 1e-12;

// Points on the surface of a straight tube from `start` to `end`, 1 mm apart along it and every
// 30° around it.
Points TubeSurface(const Eigen::Vector3d& start, const Eigen::Vector3d& end) {
  const Eigen::Vector3d d = (end - start).normalized();
  const Eigen::Vector3d u = d.unitOrthogonal();
  const Eigen::Vector3d v = d.cross(u);
  const int steps = static_cast<int>(std::round((end - start).norm() / 0.001));
  Points points;
  for (int i = 0; i <= steps; ++i) {
    const Eigen::Vector3d c = start + (end - start) * (static_cast<double>(i) / steps);
    for (int k = 0; k < 12; ++k) {
      const double a = k * 30.0 * kDeg;
      points.push_back((c + kRadius * (std::cos(a) * u + std::sin(a) * v)).cast<float>());
    }
  }
  return points;
}

Eigen::Isometry3d Pose(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) {
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() = R;
  X.translation() = p;
  return X;
}

Eigen::Matrix3d Rz(double angle) {
  return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

using tubepick::testing::ErrorOf;

TEST(PlacementFrame, StraightTubeAlongDiagonal) {
  const Eigen::Vector3d centre(0.05, -0.1, 0.03);
  const Eigen::Vector3d d = Eigen::Vector3d(1.0, 1.0, 0.0).normalized();
  const std::optional<TubeFrame> frame =
      EstimateTubeFrame(TubeSurface(centre - 0.2 * d, centre + 0.2 * d), PlacementParams{});
  ASSERT_TRUE(frame.has_value());
  const Eigen::Matrix3d R = frame->X_BinTube.linear();
  EXPECT_TRUE(R.col(0).isApprox(d, kDirectionTol));
  EXPECT_TRUE(R.col(1).isApprox(Eigen::Vector3d(-1.0, 1.0, 0.0).normalized(), kDirectionTol));
  EXPECT_TRUE(R.col(2).isApprox(Eigen::Vector3d::UnitZ(), kDirectionTol));
  EXPECT_TRUE(frame->X_BinTube.translation().isApprox(centre, kPositionTol));
  EXPECT_TRUE(frame->p_Bin_centroid.isApprox(centre, kPositionTol));
  // Variance along a 0.4 m tube ≈ L²/12; across it r²/2.
  EXPECT_NEAR(frame->eigenvalues[0], 0.4 * 0.4 / 12.0, 1e-4);
  EXPECT_NEAR(frame->eigenvalues[1], kRadius * kRadius / 2.0, 1e-6);
}

TEST(PlacementFrame, SignPointsAlongBinX) {
  const PlacementParams params;
  const auto x_of = [&](const Eigen::Vector3d& direction) {
    const std::optional<TubeFrame> frame =
        EstimateTubeFrame(TubeSurface(-0.2 * direction.normalized(), 0.2 * direction.normalized()), params);
    EXPECT_TRUE(frame.has_value());
    return frame.has_value() ? Eigen::Vector3d(frame->X_BinTube.linear().col(0)) : Eigen::Vector3d::Zero();
  };
  EXPECT_TRUE(x_of({-1.0, -1.0, 0.0}).isApprox(Eigen::Vector3d(1.0, 1.0, 0.0).normalized(), kDirectionTol));
  EXPECT_TRUE(x_of({-1.0, 1.0, 0.0}).isApprox(Eigen::Vector3d(1.0, -1.0, 0.0).normalized(), kDirectionTol));
  // No x component: +y decides.
  EXPECT_TRUE(x_of({0.0, -1.0, 0.0}).isApprox(Eigen::Vector3d::UnitY(), kDirectionTol));
}

TEST(PlacementFrame, YawOnlyProjectsTiltedTube) {
  const Eigen::Vector3d d(std::cos(30.0 * kDeg), 0.0, std::sin(30.0 * kDeg));
  PlacementParams params;
  params.yaw_only = true;
  const std::optional<TubeFrame> frame = EstimateTubeFrame(TubeSurface({0, 0, 0}, 0.4 * d), params);
  ASSERT_TRUE(frame.has_value());
  EXPECT_TRUE(frame->X_BinTube.linear().isApprox(Eigen::Matrix3d::Identity(), kDirectionTol));
  EXPECT_TRUE(frame->principal_direction_Bin.isApprox(d, kDirectionTol));
}

TEST(PlacementFrame, FullAlignmentKeepsTilt) {
  const Eigen::Vector3d d(std::cos(30.0 * kDeg), 0.0, std::sin(30.0 * kDeg));
  PlacementParams params;
  params.yaw_only = false;
  const std::optional<TubeFrame> frame = EstimateTubeFrame(TubeSurface({0, 0, 0}, 0.4 * d), params);
  ASSERT_TRUE(frame.has_value());
  const Eigen::Matrix3d R = frame->X_BinTube.linear();
  EXPECT_TRUE(R.col(0).isApprox(d, kDirectionTol));
  EXPECT_TRUE(R.col(1).isApprox(Eigen::Vector3d::UnitY(), kDirectionTol));
  EXPECT_TRUE(
      R.col(2).isApprox(Eigen::Vector3d(-std::sin(30.0 * kDeg), 0.0, std::cos(30.0 * kDeg)), kDirectionTol));
  EXPECT_NEAR(R.determinant(), 1.0, kDirectionTol);
}

TEST(PlacementFrame, AwayFromGraspPointsToFartherEnd) {
  PlacementParams params;
  params.sign = AxisSign::kAwayFromGrasp;
  const Points points = TubeSurface({0.0, 0.0, 0.0}, {0.4, 0.0, 0.0});
  const std::optional<TubeFrame> near_end = EstimateTubeFrame(points, params, Eigen::Vector3d(0.3, 0.0, 0.0));
  ASSERT_TRUE(near_end.has_value());
  EXPECT_TRUE(near_end->X_BinTube.linear().col(0).isApprox(-Eigen::Vector3d::UnitX(), kDirectionTol));
  EXPECT_TRUE(near_end->X_BinTube.linear().col(2).isApprox(Eigen::Vector3d::UnitZ(), kDirectionTol));
  const std::optional<TubeFrame> far_end = EstimateTubeFrame(points, params, Eigen::Vector3d(0.1, 0.0, 0.0));
  ASSERT_TRUE(far_end.has_value());
  EXPECT_TRUE(far_end->X_BinTube.linear().col(0).isApprox(Eigen::Vector3d::UnitX(), kDirectionTol));
}

TEST(PlacementFrame, GraspPointOrigin) {
  PlacementParams params;
  params.origin = TubeFrameOrigin::kGraspPoint;
  const Eigen::Vector3d p_Bin_grasp(0.1, 0.0, 0.0125);
  const std::optional<TubeFrame> frame =
      EstimateTubeFrame(TubeSurface({0.0, 0.0, 0.0}, {0.4, 0.0, 0.0}), params, p_Bin_grasp);
  ASSERT_TRUE(frame.has_value());
  EXPECT_TRUE(frame->X_BinTube.translation().isApprox(p_Bin_grasp, kExactTol));
  EXPECT_TRUE(frame->p_Bin_centroid.isApprox(Eigen::Vector3d(0.2, 0.0, 0.0), kPositionTol));
}

TEST(PlacementFrame, NearlyVerticalTubeHasNoFrame) {
  const Eigen::Vector3d d = Eigen::Vector3d(0.01, 0.0, 1.0).normalized();
  PlacementParams params;
  EXPECT_FALSE(EstimateTubeFrame(TubeSurface({0, 0, 0}, 0.4 * d), params).has_value());
  params.yaw_only = false;
  EXPECT_FALSE(EstimateTubeFrame(TubeSurface({0, 0, 0}, 0.4 * d), params).has_value());
}

TEST(PlacementFrame, FewerThanTwoPointsRejected) {
  const PlacementParams params;
  EXPECT_THAT(ErrorOf([&] { EstimateTubeFrame(Points{}, params); }),
              HasSubstr("points_Bin: the tube frame needs at least 2 points, got 0"));
  EXPECT_THAT(ErrorOf([&] { EstimateTubeFrame(Points{Eigen::Vector3f(0.1f, 0.2f, 0.0f)}, params); }),
              HasSubstr("needs at least 2 points, got 1"));
}

TEST(PlacementFrame, IdenticalPointsRejected) {
  const Points points(50, Eigen::Vector3f(0.1f, 0.2f, 0.05f));
  EXPECT_THAT(ErrorOf([&] { EstimateTubeFrame(points, PlacementParams{}); }),
              HasSubstr("points_Bin: the points all coincide"));
}

TEST(PlacementFrame, NonFinitePointRejected) {
  Points points = TubeSurface({0, 0, 0}, {0.4, 0, 0});
  points[7].y() = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THAT(ErrorOf([&] { EstimateTubeFrame(points, PlacementParams{}); }),
              HasSubstr("points_Bin[7]: must be finite"));
}

TEST(PlacementFrame, MissingGraspPointRejected) {
  PlacementParams params;
  params.sign = AxisSign::kAwayFromGrasp;
  EXPECT_THAT(
      ErrorOf([&] {
        EstimateTubeFrame(TubeSurface({0, 0, 0}, {0.4, 0, 0}), params);
      }),
      HasSubstr("p_Bin_grasp: required by placement.origin = centroid / placement.sign = away_from_grasp"));
}

TEST(PlacementFrame, TubeModelIntegratesItsAxis) {
  // Two collinear cylinders along (1,1,0) with a 2.8 cm joint between them: one straight 0.3·√2 m
  // axis, variance L²/12, centroid in the middle.
  Tube tube;
  tube.id = 4;
  tube.cylinders.resize(2);
  tube.cylinders[0].start = {0.0, 0.0, 0.02};
  tube.cylinders[0].end = {0.1, 0.1, 0.02};
  tube.cylinders[1].start = {0.12, 0.12, 0.02};
  tube.cylinders[1].end = {0.3, 0.3, 0.02};
  const std::optional<TubeFrame> frame = EstimateTubeFrame(tube, PlacementParams{});
  ASSERT_TRUE(frame.has_value());
  EXPECT_TRUE(
      frame->X_BinTube.linear().col(0).isApprox(Eigen::Vector3d(1.0, 1.0, 0.0).normalized(), kExactTol));
  EXPECT_TRUE(frame->X_BinTube.translation().isApprox(Eigen::Vector3d(0.15, 0.15, 0.02), kExactTol));
  const double length = 0.3 * std::sqrt(2.0);
  EXPECT_NEAR(frame->eigenvalues[0], length * length / 12.0, kExactTol);
  EXPECT_NEAR(frame->eigenvalues[1], 0.0, kExactTol);
}

TEST(PlacementFrame, TubeModelMatchesDenseSampling) {
  Tube tube;
  tube.cylinders.resize(2);
  tube.cylinders[0].start = {0.0, 0.0, 0.0};
  tube.cylinders[0].end = {0.3, 0.0, 0.01};
  tube.cylinders[1].start = {0.31, 0.01, 0.01};
  tube.cylinders[1].end = {0.45, 0.2, 0.03};
  // Midpoint samples 0.1 mm apart along the polyline (joint included).
  Points samples;
  const Eigen::Vector3d vertices[] = {tube.cylinders[0].start, tube.cylinders[0].end, tube.cylinders[1].start,
                                      tube.cylinders[1].end};
  for (int s = 0; s < 3; ++s) {
    const Eigen::Vector3d a = vertices[s];
    const Eigen::Vector3d b = vertices[s + 1];
    const int n = static_cast<int>(std::ceil((b - a).norm() / 1e-4));
    for (int k = 0; k < n; ++k) samples.push_back((a + (b - a) * ((k + 0.5) / n)).cast<float>());
  }
  PlacementParams params;
  params.yaw_only = false;
  const std::optional<TubeFrame> model = EstimateTubeFrame(tube, params);
  const std::optional<TubeFrame> sampled = EstimateTubeFrame(samples, params);
  ASSERT_TRUE(model.has_value());
  ASSERT_TRUE(sampled.has_value());
  EXPECT_TRUE(model->X_BinTube.linear().isApprox(sampled->X_BinTube.linear(), kDirectionTol));
  // Rounding each segment to whole samples skews its weight by up to one sample (0.1 mm).
  constexpr double kSamplingTol = 1e-4;
  EXPECT_LT((model->X_BinTube.translation() - sampled->X_BinTube.translation()).norm(), kSamplingTol);
}

TEST(PlacementFrame, DegenerateTubeModelsRejected) {
  Tube tube;
  tube.id = 9;
  EXPECT_THAT(ErrorOf([&] { EstimateTubeFrame(tube, PlacementParams{}); }),
              HasSubstr("tube 9: the tube frame needs at least one cylinder"));
  tube.cylinders.resize(1);
  tube.cylinders[0].start = tube.cylinders[0].end = {0.1, 0.1, 0.0};
  EXPECT_THAT(ErrorOf([&] { EstimateTubeFrame(tube, PlacementParams{}); }),
              HasSubstr("tube 9: the axis has zero length"));
}

TEST(PlacementPose, HandComputedComposition) {
  // Gripper pointing down (Rx(180°)) yawed 90°, 2 cm short of the tube frame along bin x.
  const Eigen::Matrix3d Rx180 = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Isometry3d X_BinTcp = Pose(Rz(90.0 * kDeg) * Rx180, {0.10, 0.20, 0.05});
  const Eigen::Isometry3d X_BinTube = Pose(Rz(90.0 * kDeg), {0.12, 0.20, 0.05});
  const Eigen::Isometry3d X_BinPlace = Pose(Eigen::Matrix3d::Identity(), {0.0, 0.8, 0.1});
  // X_TubeTcp: rotation Rz(−90°)·Rz(90°)·Rx(180°) = Rx(180°); position Rz(−90°)·(−0.02, 0, 0) = (0, 0.02, 0).
  // X_BinTcpPlace = X_BinPlace · X_TubeTcp: rotation Rx(180°), position (0, 0.82, 0.1).
  const Eigen::Isometry3d X_BinTcpPlace = PlacementTcpPose(X_BinTcp, X_BinTube, X_BinPlace);
  EXPECT_TRUE(X_BinTcpPlace.linear().isApprox(Rx180, kExactTol));
  EXPECT_TRUE(X_BinTcpPlace.translation().isApprox(Eigen::Vector3d(0.0, 0.82, 0.1), kExactTol));
}

TEST(PlacementPose, TubeFrameLandsOnPlace) {
  const Eigen::Vector3d d = Eigen::Vector3d(1.0, 2.0, 0.0).normalized();
  const std::optional<TubeFrame> tube = EstimateTubeFrame(TubeSurface(-0.2 * d, 0.2 * d), PlacementParams{});
  ASSERT_TRUE(tube.has_value());
  const Eigen::Isometry3d X_BinTcp = Pose(Rz(20.0 * kDeg), {0.05, 0.1, 0.0125});
  const Eigen::Isometry3d X_BinPlace = Pose(Rz(-90.0 * kDeg), {0.3, 0.8, 0.1});
  const Placement placement = PlanPlacement(X_BinTcp, *tube, X_BinPlace, PlacementParams{});
  EXPECT_FALSE(placement.flipped);
  EXPECT_TRUE((placement.X_BinTcpPlace * placement.X_TubeTcp.inverse()).isApprox(X_BinPlace, kExactTol));
  // Yaw only: grasp to place is a pure rotation about z.
  const Eigen::Matrix3d R_TcpTcpPlace = X_BinTcp.linear().transpose() * placement.X_BinTcpPlace.linear();
  EXPECT_TRUE((R_TcpTcpPlace * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitZ(), kDirectionTol));
}

TEST(PlacementPose, FlipShortensTcpRotation) {
  const Eigen::Isometry3d X_BinTcp = Pose(Eigen::Matrix3d::Identity(), {0.1, 0.0, 0.05});
  TubeFrame tube;
  tube.X_BinTube = Pose(Rz(170.0 * kDeg), {0.1, 0.0, 0.05});
  const Eigen::Isometry3d X_BinPlace = Pose(Eigen::Matrix3d::Identity(), {0.0, 0.8, 0.1});
  PlacementParams params;
  const Placement exact = PlanPlacement(X_BinTcp, tube, X_BinPlace, params);
  EXPECT_FALSE(exact.flipped);
  EXPECT_NEAR(exact.tcp_rotation_angle, 170.0 * kDeg, kExactTol);
  params.allow_flip = true;
  const Placement flipped = PlanPlacement(X_BinTcp, tube, X_BinPlace, params);
  EXPECT_TRUE(flipped.flipped);
  EXPECT_NEAR(flipped.tcp_rotation_angle, 10.0 * kDeg, 1e-9);
  EXPECT_TRUE(flipped.X_BinTcpPlace.linear().isApprox(Rz(10.0 * kDeg), 1e-9));
  EXPECT_TRUE(flipped.X_BinTcpPlace.translation().isApprox(X_BinPlace.translation(), kExactTol));
}

TEST(PlacementPose, NonRigidPoseRejected) {
  Eigen::Isometry3d X_BinPlace = Eigen::Isometry3d::Identity();
  X_BinPlace.linear() *= 1.5;
  EXPECT_THAT(ErrorOf([&] {
                PlacementTcpPose(Eigen::Isometry3d::Identity(), Eigen::Isometry3d::Identity(), X_BinPlace);
              }),
              HasSubstr("X_BinPlace: rotation is not proper orthonormal"));
}

TEST(PlacementParams, MinHorizontalOutOfRangeRejected) {
  PlacementParams params;
  params.min_horizontal = 1.0;
  EXPECT_THAT(ErrorOf([&] { params.Validate(); }),
              HasSubstr("placement.min_horizontal: 1 is out of range (0, 1)"));
  params.min_horizontal = 0.0;
  EXPECT_THAT(ErrorOf([&] { params.Validate(); }), HasSubstr("placement.min_horizontal: 0"));
}

TEST(PlacementParams, EnumNamesRoundTrip) {
  for (TubeFrameOrigin o : {TubeFrameOrigin::kCentroid, TubeFrameOrigin::kGraspPoint}) {
    EXPECT_EQ(ParseTubeFrameOrigin(ToString(o), "placement.origin"), o);
  }
  for (AxisSign s : {AxisSign::kAlongBinX, AxisSign::kAwayFromGrasp}) {
    EXPECT_EQ(ParseAxisSign(ToString(s), "placement.sign"), s);
  }
  EXPECT_THAT(ErrorOf([] { ParseAxisSign("up", "placement.sign"); }),
              HasSubstr("placement.sign: unknown sign rule 'up'"));
}

}  // namespace
}  // namespace tubepick

#include "core/wrench/held_count.h"

#include <cmath>
#include <limits>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"
#include "core/testing/error_of.h"
#include "core/wrench/wrench.h"
#include "core/wrench/wrench_params.h"

namespace tubepick {
namespace {

using ::testing::HasSubstr;

constexpr double kForceTol = 1e-12;
// Exactly representable: weight = 0.0625 kg × 8 m/s² = 0.5 N, expected = 10 − 0.5 = 9.5 N, band
// edges 9.25 N and 9.75 N, so the boundary tests compare the very same doubles.
constexpr double kMass = 0.0625;
constexpr double kGravity = 8.0;
constexpr double kReference = 10.0;
constexpr double kTolerance = 0.25;
constexpr double kExpected = 9.5;

WrenchParams ExactParams() {
  WrenchParams params;
  params.gravity = kGravity;
  params.force_tolerance = kTolerance;
  return params;
}

using tubepick::testing::ErrorOf;

TEST(HeldCount, ExpectedForceIsSingle) {
  const HeldCount result = CountHeldTubes(kReference, kExpected, kMass, ExactParams());
  EXPECT_EQ(result.outcome, HeldOutcome::kSingle);
  EXPECT_NEAR(result.tube_weight, 0.5, kForceTol);
  EXPECT_NEAR(result.expected_force, kExpected, kForceTol);
  EXPECT_NEAR(result.held_weight, 0.5, kForceTol);
  EXPECT_NEAR(result.tube_ratio, 1.0, kForceTol);
  EXPECT_EQ(result.estimated_count, 1u);
}

TEST(HeldCount, LowerBandEdgeIsSingle) {
  EXPECT_EQ(CountHeldTubes(kReference, kExpected - kTolerance, kMass, ExactParams()).outcome,
            HeldOutcome::kSingle);
}

TEST(HeldCount, UpperBandEdgeIsSingle) {
  EXPECT_EQ(CountHeldTubes(kReference, kExpected + kTolerance, kMass, ExactParams()).outcome,
            HeldOutcome::kSingle);
}

TEST(HeldCount, JustBelowLowerEdgeIsMultiple) {
  const double fz = std::nextafter(kExpected - kTolerance, -std::numeric_limits<double>::infinity());
  const HeldCount result = CountHeldTubes(kReference, fz, kMass, ExactParams());
  EXPECT_EQ(result.outcome, HeldOutcome::kMultiple);
  EXPECT_EQ(result.estimated_count, 2u);  // ratio 1.5 rounds to 2
}

TEST(HeldCount, JustAboveUpperEdgeIsNone) {
  const double fz = std::nextafter(kExpected + kTolerance, std::numeric_limits<double>::infinity());
  const HeldCount result = CountHeldTubes(kReference, fz, kMass, ExactParams());
  EXPECT_EQ(result.outcome, HeldOutcome::kNone);
  EXPECT_EQ(result.estimated_count, 0u);
}

TEST(HeldCount, EmptyGripperIsNone) {
  const HeldCount result = CountHeldTubes(kReference, kReference, kMass, ExactParams());
  EXPECT_EQ(result.outcome, HeldOutcome::kNone);
  EXPECT_NEAR(result.held_weight, 0.0, kForceTol);
  EXPECT_EQ(result.estimated_count, 0u);
}

TEST(HeldCount, ThreeTubesEstimateThree) {
  const HeldCount result = CountHeldTubes(kReference, kReference - 3.0 * 0.5 + 0.1, kMass, ExactParams());
  EXPECT_EQ(result.outcome, HeldOutcome::kMultiple);
  EXPECT_NEAR(result.tube_ratio, 2.8, 1e-9);
  EXPECT_EQ(result.estimated_count, 3u);
}

TEST(HeldCount, ThesisTubeWithDefaultGravity) {
  // 55 g tube (cell default), g = 9.81: one tube lowers F_z by 0.540 N.
  const WrenchParams params;
  const HeldCount result = CountHeldTubes(4.0, 4.0 - 0.055 * 9.81 + 0.02, 0.055, params);
  EXPECT_EQ(result.outcome, HeldOutcome::kSingle);
  EXPECT_NEAR(result.tube_weight, 0.53955, 1e-12);
}

TEST(HeldCount, WrenchOverloadReadsForceAlongUp) {
  // A TCP whose z points down: the upward force is −force.z.
  WrenchParams params = ExactParams();
  params.up_Tcp = Eigen::Vector3d(0.0, 0.0, -1.0);
  Wrench reference;
  reference.force = Eigen::Vector3d(0.3, -0.2, -kReference);
  Wrench current;
  current.force = Eigen::Vector3d(0.1, 0.4, -(kReference - 2.0));  // four tubes' weight
  const HeldCount result = CountHeldTubes(reference, current, kMass, params);
  EXPECT_EQ(result.outcome, HeldOutcome::kMultiple);
  EXPECT_EQ(result.estimated_count, 4u);

  current.force.z() = -kExpected;
  EXPECT_EQ(CountHeldTubes(reference, current, kMass, params).outcome, HeldOutcome::kSingle);
}

TEST(HeldCount, ZeroMassRejectedNamingTubeMass) {
  const std::string error = ErrorOf([] { CountHeldTubes(kReference, kExpected, 0.0, ExactParams()); });
  EXPECT_THAT(error, HasSubstr("tube.mass"));
  EXPECT_THAT(error, HasSubstr("must be > 0, got 0"));
}

TEST(HeldCount, NegativeToleranceRejectedNamingField) {
  WrenchParams params = ExactParams();
  params.force_tolerance = -0.1;
  const std::string error = ErrorOf([&] { CountHeldTubes(kReference, kExpected, kMass, params); });
  EXPECT_THAT(error, HasSubstr("wrench.force_tolerance"));
  EXPECT_THAT(error, HasSubstr("-0.1"));
}

TEST(HeldCount, ToleranceNotBelowWeightRejected) {
  WrenchParams params = ExactParams();
  params.force_tolerance = 0.5;  // equal to one tube's weight
  const std::string error = ErrorOf([&] { CountHeldTubes(kReference, kExpected, kMass, params); });
  EXPECT_THAT(error, HasSubstr("wrench.force_tolerance: 0.5 N is not below the weight of one tube"));
}

TEST(HeldCount, AShareNarrowsTheBandOfALightTube) {
  // Weight 0.5 N, share 0.25: F_tol = min(0.25, 0.125) = 0.125 N, single from 9.375 to 9.625 N.
  WrenchParams params = ExactParams();
  params.force_tolerance_share = 0.25;
  const HeldCount edge = CountHeldTubes(kReference, kExpected - 0.125, kMass, params);
  EXPECT_EQ(edge.outcome, HeldOutcome::kSingle);
  EXPECT_EQ(edge.force_tolerance, 0.125);
  // 1.3 tubes: single with the thesis' 0.25 N, several with the share.
  const double partial = kReference - 1.3 * 0.5;
  EXPECT_EQ(CountHeldTubes(kReference, partial, kMass, ExactParams()).outcome, HeldOutcome::kSingle);
  EXPECT_EQ(CountHeldTubes(kReference, partial, kMass, params).outcome, HeldOutcome::kMultiple);
  EXPECT_EQ(CountHeldTubes(kReference, kReference - 0.7 * 0.5, kMass, params).outcome, HeldOutcome::kNone);
  // A heavy tube keeps F_tol: weight 2 N, share · weight 0.5 N > 0.25 N.
  EXPECT_EQ(CountHeldTubes(kReference, kReference - 2.0, 0.25, params).force_tolerance, kTolerance);
}

TEST(HeldCount, ShareOutOfRangeRejectedNamingField) {
  WrenchParams params = ExactParams();
  params.force_tolerance_share = 1.0;
  EXPECT_THAT(ErrorOf([&] { CountHeldTubes(kReference, kExpected, kMass, params); }),
              HasSubstr("wrench.force_tolerance_share: 1 is out of range [0, 1)"));
  params.force_tolerance_share = -0.1;
  EXPECT_THAT(ErrorOf([&] { params.Validate(); }), HasSubstr("wrench.force_tolerance_share: -0.1"));
}

TEST(HeldCount, NonFiniteForceRejected) {
  const std::string error = ErrorOf([] { CountHeldTubes(kReference, std::nan(""), kMass, ExactParams()); });
  EXPECT_THAT(error, HasSubstr("fz: value must be finite"));
  Wrench current;
  current.force.x() = std::numeric_limits<double>::infinity();
  EXPECT_THAT(ErrorOf([&] { CountHeldTubes(Wrench{}, current, kMass, ExactParams()); }),
              HasSubstr("current.force: must be finite"));
}

TEST(HeldCount, OutcomeNames) {
  EXPECT_EQ(ToString(HeldOutcome::kNone), "none");
  EXPECT_EQ(ToString(HeldOutcome::kSingle), "single");
  EXPECT_EQ(ToString(HeldOutcome::kMultiple), "multiple");
}

TEST(WrenchParams, DefaultsAreValidAndThesisAngle) {
  const WrenchParams params;
  EXPECT_NO_THROW(params.Validate());
  EXPECT_NEAR(params.rotation_angle, 45.0 * M_PI / 180.0, 1e-15);
  EXPECT_EQ(params.variant, ResolutionVariant::kTorqueAxis);
}

TEST(WrenchParams, NonPositiveGravityRejected) {
  WrenchParams params;
  params.gravity = 0.0;
  EXPECT_THAT(ErrorOf([&] { params.Validate(); }), HasSubstr("wrench.gravity: must be > 0, got 0"));
}

TEST(WrenchParams, RotationAngleOutOfRangeRejected) {
  WrenchParams params;
  params.rotation_angle = 0.0;
  EXPECT_THAT(ErrorOf([&] { params.Validate(); }), HasSubstr("wrench.rotation_angle: 0 rad is out of range"));
  params.rotation_angle = 4.0;
  EXPECT_THAT(ErrorOf([&] { params.Validate(); }), HasSubstr("wrench.rotation_angle: 4 rad"));
}

TEST(WrenchParams, NonPositiveMinTorqueRejected) {
  WrenchParams params;
  params.min_torque = -1e-3;
  EXPECT_THAT(ErrorOf([&] { params.Validate(); }), HasSubstr("wrench.min_torque: must be > 0, got -0.001"));
}

TEST(WrenchParams, ZeroUpRejected) {
  WrenchParams params;
  params.up_Tcp = Eigen::Vector3d::Zero();
  EXPECT_THAT(ErrorOf([&] { params.Validate(); }),
              HasSubstr("wrench.up_Tcp: must be a finite non-zero vector"));
}

TEST(WrenchParams, JointSafeAxisMustBeHorizontal) {
  WrenchParams params;
  params.joint_safe_axis = Eigen::Vector3d(1.0, 0.0, 1.0);
  EXPECT_THAT(ErrorOf([&] { params.Validate(); }),
              HasSubstr("wrench.joint_safe_axis: [1, 0, 1] must be perpendicular to wrench.up_Tcp"));
  params.joint_safe_frame = JointSafeFrame::kBin;
  EXPECT_THAT(ErrorOf([&] { params.Validate(); }), HasSubstr("perpendicular to the bin's z"));
}

TEST(WrenchParams, EnumNamesRoundTrip) {
  for (ResolutionVariant v : {ResolutionVariant::kTorqueAxis, ResolutionVariant::kTorqueAxisNegative,
                              ResolutionVariant::kPerpendicular, ResolutionVariant::kJointSafe,
                              ResolutionVariant::kTorqueAxisThenPerpendicular}) {
    EXPECT_EQ(ParseResolutionVariant(ToString(v), "wrench.variant"), v);
  }
  EXPECT_EQ(ParseJointSafeFrame("bin", "wrench.joint_safe_frame"), JointSafeFrame::kBin);
  EXPECT_THAT(ErrorOf([] { ParseResolutionVariant("tilt", "wrench.variant"); }),
              HasSubstr("wrench.variant: unknown resolution variant 'tilt'"));
}

}  // namespace
}  // namespace tubepick

// CheckTubeMass: lifts whose weights fit no whole number of tubes name tube.mass.
#include "core/wrench/tube_mass_check.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/common/errors.h"

namespace tubepick {
namespace {

TEST(TubeMassCheck, LiftsOfAboutWholeTubesFit) {
  // The simulated cell's lifts with the right mass: singles 0.93-1.04, doubles about 2, entangled
  // rubber 5.32 (one off, so the window fits).
  EXPECT_FALSE(CheckTubeMass({0.93, 1.04, 0.97, 1.01, 0.99}, 0.110).has_value());
  EXPECT_FALSE(CheckTubeMass({1.98, 2.13, 3.0, 5.32, 5.42}, 0.055).has_value());
  // Lifts that read about none between them: one whole tube in the window is enough.
  EXPECT_FALSE(CheckTubeMass({0.01, -0.02, 0.0, 1.01}, 0.110).has_value());
}

TEST(TubeMassCheck, LiftsTheGripperHeldThatWeighAboutNothingDoubtAMassTenTimesTooHigh) {
  // The simulated cell with PVC tubes of 0.0055 kg and tube.mass 0.055 kg (`--sim-tube-mass 0.0055`):
  // every lift read 0.05-0.12 tubes, Algorithm 3's "none", while the gripper held a tube.
  const std::optional<TubeMassDoubt> d = CheckTubeMass({0.121, 0.103, 0.114}, 0.055);
  ASSERT_TRUE(d.has_value());
  EXPECT_NEAR(d->mass_if_single, 0.055 * 0.114, 1e-12);
  EXPECT_NE(d->message.find("0.10-0.12 times tube.mass (0.055 kg)"), std::string::npos) << d->message;
  EXPECT_NE(d->message.find("the gripper held something each time"), std::string::npos) << d->message;
  EXPECT_NE(d->message.find("would weigh 0.006 kg"), std::string::npos) << d->message;
}

TEST(TubeMassCheck, LiftsOfMoreTubesThanAGraspHoldsDoubtAMassTenTimesTooLow) {
  // PVC tubes of 0.55 kg and tube.mass 0.055 kg: every lift read ten tubes.
  const std::optional<TubeMassDoubt> d = CheckTubeMass({10.021, 10.014, 10.061}, 0.055);
  ASSERT_TRUE(d.has_value());
  EXPECT_NEAR(d->mass_if_single, 0.055 * 10.021, 1e-12);
  EXPECT_NE(d->message.find("none a whole number of tubes from 1 to 6"), std::string::npos) << d->message;
  TubeMassCheckParams p;
  p.max_tubes_per_lift = 12;  // a cell whose grasps can lift a dozen
  EXPECT_FALSE(CheckTubeMass({10.021, 10.014, 10.061}, 0.055, p).has_value());
  // Half the real mass is not seen: every lift weighs two whole tubes.
  EXPECT_FALSE(CheckTubeMass({2.02, 2.01, 2.06, 1.97}, 0.055).has_value());
}

TEST(TubeMassCheck, TooFewLiftsAreNotJudged) {
  EXPECT_FALSE(CheckTubeMass({}, 0.110).has_value());
  EXPECT_FALSE(CheckTubeMass({1.36, 1.34}, 0.110).has_value());
  EXPECT_TRUE(CheckTubeMass({1.36, 1.34, 1.31}, 0.110).has_value());
  TubeMassCheckParams p;
  p.min_lifts = 4;
  EXPECT_FALSE(CheckTubeMass({1.36, 1.34, 1.31}, 0.110, p).has_value());
}

TEST(TubeMassCheck, AMassAQuarterTooLowIsNamedWithTheMassTheLiftsSuggest) {
  // PVC tubes of 0.146 kg in a cell that says 0.110 kg: each lift weighs about 1.33 tubes.
  const std::optional<TubeMassDoubt> d = CheckTubeMass({1.0, 1.31, 1.36, 1.33, 1.34, 1.38}, 0.110);
  ASSERT_TRUE(d.has_value());
  EXPECT_EQ(d->lifts, 5u);  // the window: the first lift (1.0) is older
  EXPECT_DOUBLE_EQ(d->min_ratio, 1.31);
  EXPECT_DOUBLE_EQ(d->max_ratio, 1.38);
  EXPECT_DOUBLE_EQ(d->median_ratio, 1.34);
  EXPECT_NEAR(d->mass_if_single, 0.1474, 1e-12);
  EXPECT_NE(d->message.find("tube.mass (0.110 kg)"), std::string::npos) << d->message;
  EXPECT_NE(d->message.find("1.31-1.38 times"), std::string::npos) << d->message;
  EXPECT_NE(d->message.find("would weigh 0.147 kg"), std::string::npos) << d->message;
}

TEST(TubeMassCheck, AMassTooHighReadsAsLessThanOneTube) {
  // Tubes of 0.080 kg in a cell that says 0.110 kg: 0.73 tubes each, Algorithm 3's "none".
  const std::optional<TubeMassDoubt> d = CheckTubeMass({0.72, 0.74, 0.73}, 0.110);
  ASSERT_TRUE(d.has_value());
  EXPECT_NEAR(d->mass_if_single, 0.110 * 0.73, 1e-12);
  // One lift within 0.2 of a whole number is enough to fit (a mass 15 % off still works).
  EXPECT_FALSE(CheckTubeMass({0.72, 0.85, 0.73}, 0.110).has_value());
}

TEST(TubeMassCheck, BadInputsAreRefused) {
  EXPECT_THROW(CheckTubeMass({1.0}, 0.0), InvalidArgument);
  EXPECT_THROW(CheckTubeMass({1.0, std::nan("")}, 0.110), InvalidArgument);
  TubeMassCheckParams p;
  p.min_lifts = 6;  // more than the window
  EXPECT_THROW(CheckTubeMass({1.0}, 0.110, p), InvalidArgument);
  p = {};
  p.max_off_whole = 0.5;  // every ratio would fit
  EXPECT_THROW(CheckTubeMass({1.0}, 0.110, p), InvalidArgument);
  p = {};
  p.max_tubes_per_lift = 0;
  EXPECT_THROW(CheckTubeMass({1.0}, 0.110, p), InvalidArgument);
}

}  // namespace
}  // namespace tubepick

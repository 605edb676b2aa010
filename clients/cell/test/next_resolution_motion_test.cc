#include <gtest/gtest.h>

#include "clients/cell/cell_controller_params.h"

namespace tubepick::cell {
namespace {

using Source = ResolutionMotionSource;

CellControllerParams Params(bool replan, std::uint32_t extra) {
  CellControllerParams p;
  p.resolution_replan = replan;
  p.resolution_extra_motions = extra;
  return p;
}

TEST(NextResolutionMotionTest, WithoutReplanThePlansMotionsInOrderThenNone) {
  const CellControllerParams p = Params(false, 3);  // extra motions need replan
  EXPECT_EQ(NextResolutionMotion(p, 0, 2, false), Source::kPlan);
  EXPECT_EQ(NextResolutionMotion(p, 1, 2, true), Source::kPlan);  // a reading's motion is not used
  EXPECT_EQ(NextResolutionMotion(p, 2, 2, true), Source::kNone);
}

TEST(NextResolutionMotionTest, WithReplanAReadingsMotionReplacesThePlansNext) {
  const CellControllerParams p = Params(true, 0);
  EXPECT_EQ(NextResolutionMotion(p, 0, 2, false), Source::kPlan);
  EXPECT_EQ(NextResolutionMotion(p, 1, 2, true), Source::kReading);
  EXPECT_EQ(NextResolutionMotion(p, 1, 2, false), Source::kPlan);  // that reading planned none
  EXPECT_EQ(NextResolutionMotion(p, 2, 2, true), Source::kNone);
}

TEST(NextResolutionMotionTest, ExtraMotionsGoOnOnlyFromReadingsAndStopAtTheirCount) {
  const CellControllerParams p = Params(true, 2);
  EXPECT_EQ(NextResolutionMotion(p, 2, 2, true), Source::kReading);
  EXPECT_EQ(NextResolutionMotion(p, 3, 2, true), Source::kReading);
  EXPECT_EQ(NextResolutionMotion(p, 4, 2, true), Source::kNone);
  EXPECT_EQ(NextResolutionMotion(p, 2, 2, false), Source::kNone);  // the plan's are spent
}

TEST(NextResolutionMotionTest, NoPlanNoMotions) {
  EXPECT_EQ(NextResolutionMotion(Params(true, 2), 0, 0, false), Source::kNone);
  EXPECT_EQ(NextResolutionMotion(Params(true, 2), 0, 0, true), Source::kNone);
}

}  // namespace
}  // namespace tubepick::cell

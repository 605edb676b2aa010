#include "core/evaluation/virtual_labelling.h"

#include <cmath>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"

namespace tubepick {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
constexpr double kTol = 1e-12;
constexpr double kR = 0.0125;

Tube TwoCylinderTube(std::uint32_t id, double y) {
  Tube t;
  t.id = id;
  Cylinder a, b;
  a.start = {-0.2, y, kR};
  a.end = {-0.05, y, kR};
  b.start = {0.05, y, kR};
  b.end = {0.2, y, kR};
  a.radius = b.radius = kR;
  t.cylinders = {a, b};
  return t;
}

TEST(VirtualLabelling, InliersKeepTheirTubeJointAndCylinderPointsAreFilled) {
  // Tube ids 5 and 9 (indices 0 and 1), at y = 0 and y = 0.1.
  const std::vector<Tube> tubes{TwoCylinderTube(5, 0.0), TwoCylinderTube(9, 0.1)};
  const Points points{
      {-0.1f, 0.0f, 2 * kR},           // 0: inlier of tube id 9 (kept even though it lies on tube 0)
      {0.0f, 0.0f, 2 * kR},            // 1: top of tube 0's joint
      {-0.1f, 0.1f, 2 * kR + 0.004f},  // 2: just above tube 1's first cylinder (within tolerance)
      {0.0f, 0.05f, kR},               // 3: between the tubes: c∅
      {0.1f, 0.1f, 2 * kR + 0.01f},    // 4: 1 cm above tube 1's second cylinder: c∅
  };
  const VirtualLabels labels =
      LabelVirtualTubes(points, {9, -1, -1, -1, -1}, tubes, VirtualLabellingParams{});
  EXPECT_THAT(labels.tube, ElementsAre(1, 0, 1, -1, -1));
  EXPECT_THAT(labels.source, ElementsAre(0, 1, 2, -1, -1));
  EXPECT_THAT(labels.cylinder, ElementsAre(0, 0, 0, -1, -1));  // point 1 is equidistant: the first

  VirtualLabellingParams joints_only;
  joints_only.label_inside_cylinders = false;
  EXPECT_THAT(LabelVirtualTubes(points, {9, -1, -1, -1, -1}, tubes, joints_only).tube,
              ElementsAre(1, 0, -1, -1, -1));
}

TEST(VirtualLabelling, NearestSurfaceWinsWhereTubesOverlap) {
  // Two parallel tubes 2 cm apart (closer than their diameter, so their capsules overlap).
  const std::vector<Tube> tubes{TwoCylinderTube(0, 0.0), TwoCylinderTube(1, 0.02)};
  // Both points lie inside both capsules; each goes to the tube whose surface is nearer.
  const Points points{{-0.1f, 0.012f, kR + 0.01f}, {-0.1f, 0.008f, kR + 0.01f}};
  EXPECT_THAT(LabelVirtualTubes(points, {-1, -1}, tubes, VirtualLabellingParams{}).tube, ElementsAre(1, 0));
}

TEST(VirtualLabelling, DistanceToSegment) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0);
  EXPECT_NEAR(DistanceToSegment({0.5, 2.0, 0.0}, a, b), 2.0, kTol);
  EXPECT_NEAR(DistanceToSegment({-3.0, 4.0, 0.0}, a, b), 5.0, kTol);
  EXPECT_NEAR(DistanceToSegment({1.0, 0.0, 1.0}, a, a), std::sqrt(2.0), kTol);
}

TEST(VirtualLabelling, RejectsUnknownTubeIdsAndSizeMismatch) {
  const std::vector<Tube> tubes{TwoCylinderTube(0, 0.0)};
  try {
    LabelVirtualTubes(Points(2, Eigen::Vector3f::Zero()), {0}, tubes, VirtualLabellingParams{});
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("1 tube labels for 2 points"));
  }
  try {
    LabelVirtualTubes(Points(1, Eigen::Vector3f::Zero()), {3}, tubes, VirtualLabellingParams{});
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("tube id 3"));
  }
}

}  // namespace
}  // namespace tubepick

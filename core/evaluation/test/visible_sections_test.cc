#include "core/evaluation/visible_sections.h"

#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"

namespace tubepick {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

// Points every 2 mm along x in [x0, x1] at height y, labelled `label`.
void AddLine(double x0, double x1, double y, std::int32_t label, Points& points,
             std::vector<std::int32_t>& truth) {
  for (double x = x0; x <= x1 + 1e-9; x += 0.002) {
    points.emplace_back(static_cast<float>(x), static_cast<float>(y), 0.0125f);
    truth.push_back(label);
  }
}

TEST(VisibleSections, AnOccluderSplitsATubeInTwoAndSpecksDoNotCount) {
  Points points;
  std::vector<std::int32_t> truth;
  AddLine(-0.20, -0.02, 0.0, 0, points, truth);  // tube 0, left of the occluder
  AddLine(0.02, 0.20, 0.0, 0, points, truth);    // tube 0, right of it (4 cm gap)
  AddLine(-0.02, 0.02, 0.0, 1, points, truth);   // tube 1 crosses on top: one section
  AddLine(0.30, 0.31, 0.1, 0, points, truth);    // a 6-point speck of tube 0
  AddLine(-0.1, 0.1, 0.1, -1, points, truth);    // background: ignored
  const auto sections = CountVisibleSections(points, truth, 3, VisibleSectionParams{});
  EXPECT_THAT(sections, ElementsAre(2, 0, 0));  // tube 1 has only 21 points (< 30)

  VisibleSectionParams lenient;
  lenient.min_points = 5;
  EXPECT_THAT(CountVisibleSections(points, truth, 3, lenient), ElementsAre(3, 1, 0));
}

TEST(VisibleSections, RejectsBadInput) {
  Points points(2, Eigen::Vector3f::Zero());
  try {
    CountVisibleSections(points, {0}, 1, VisibleSectionParams{});
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("1 labels for 2 points"));
  }
  VisibleSectionParams bad;
  bad.link_radius = 0.0;
  EXPECT_THROW(CountVisibleSections(points, {0, 0}, 1, bad), InvalidArgument);
}

}  // namespace
}  // namespace tubepick

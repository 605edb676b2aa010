#include "core/evaluation/tube_evaluation.h"

#include <cmath>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"

namespace tubepick {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
constexpr double kTol = 1e-9;
constexpr double kR = 0.0125;  // tube radius, metres
constexpr double kPi = 3.14159265358979323846;

Cylinder FloorCylinder(double x0, double x1, double y) {
  Cylinder c;
  c.start = {x0, y, kR};
  c.end = {x1, y, kR};
  c.radius = kR;
  return c;
}

// A hand-made modeling result: the upper half of straight floor tubes along x, sampled every
// 4 mm along the tube and every 15° around it, with ground truth per point.
struct Fixture {
  ModelingResult result;
  std::vector<std::int32_t> truth;  // per input point (= per filtered point here)

  // Adds the visible surface of a real tube from x0 to x1 at y; its points are inliers of virtual
  // tube `virtual_id` where `inlier_of(x)` says so (−1: no cylinder took them).
  template <typename InlierOf>
  void AddRealTube(std::int32_t label, double x0, double x1, double y, InlierOf inlier_of) {
    for (double x = x0; x <= x1 + 1e-9; x += 0.004) {
      for (int k = 0; k <= 12; ++k) {
        const double angle = kPi * k / 12.0;  // 0..180° over the top
        const Eigen::Vector3d p(x, y + kR * std::cos(angle), kR + kR * std::sin(angle));
        result.filtered.points.push_back(p.cast<float>());
        result.filtered_source_index.push_back(static_cast<std::uint32_t>(truth.size()));
        result.tube_of_point.push_back(inlier_of(x));
        result.segment_of_point.push_back(0);
        truth.push_back(label);
      }
    }
  }

  void AddVirtualTube(std::vector<Cylinder> cylinders) {
    Tube t;
    t.id = static_cast<std::uint32_t>(result.tubes.size());
    t.cylinders = std::move(cylinders);
    result.tubes.push_back(t);
  }

  SceneEvaluation Evaluate(std::uint32_t real_tubes) const {
    return EvaluateScene(result, truth, real_tubes, EvaluationParams{});
  }
};

TEST(EvaluateScene, PerfectModelIsAllCorrect) {
  Fixture f;
  f.AddRealTube(0, -0.25, 0.25, -0.1, [](double) { return 0; });
  f.AddRealTube(1, -0.25, 0.25, 0.1, [](double) { return 1; });
  f.AddVirtualTube({FloorCylinder(-0.25, 0.25, -0.1)});
  f.AddVirtualTube({FloorCylinder(-0.25, 0.25, 0.1)});
  const SceneEvaluation e = f.Evaluate(2);
  EXPECT_EQ(e.correct, 2u);
  EXPECT_EQ(e.partially_correct + e.not_correct + e.hidden, 0u);
  EXPECT_NEAR(e.micro_recall(), 1.0, kTol);
  EXPECT_NEAR(e.micro_precision(), 1.0, kTol);
  EXPECT_NEAR(e.accuracy(), 1.0, kTol);
  EXPECT_EQ(e.real_tubes[0].matched_virtual, 0);
  EXPECT_EQ(e.real_tubes[1].matched_virtual, 1);
  EXPECT_TRUE(e.virtual_tubes[0].pure);
  EXPECT_EQ(e.visible_sections, 2u);
  ASSERT_TRUE(e.mean_length.has_value());
  EXPECT_NEAR(*e.mean_length, 0.5, 1e-6);
  EXPECT_NEAR(*e.stddev_length, 0.0, 1e-6);
}

TEST(EvaluateScene, JointPointsAreLabelledAndStillCorrect) {
  // One real tube modeled by two cylinders with a 6 cm gap between them; the points in the gap
  // were nobody's inliers but lie in the joint, so they get the tube (§4.5.2).
  Fixture f;
  f.AddRealTube(0, -0.25, 0.25, 0.0, [](double x) { return std::abs(x) < 0.03 ? -1 : 0; });
  f.AddVirtualTube({FloorCylinder(-0.25, -0.03, 0.0), FloorCylinder(0.03, 0.25, 0.0)});
  const SceneEvaluation e = f.Evaluate(1);
  EXPECT_EQ(e.correct, 1u);
  EXPECT_NEAR(e.real_tubes[0].coverage, 1.0, kTol);
  EXPECT_EQ(e.real_null, 0u);
}

TEST(EvaluateScene, TubeSplitInTwoIsPartiallyCorrect) {
  Fixture f;
  f.AddRealTube(0, -0.25, 0.25, 0.0, [](double x) { return x < 0.0 ? 0 : 1; });
  f.AddVirtualTube({FloorCylinder(-0.25, -0.002, 0.0)});
  f.AddVirtualTube({FloorCylinder(0.002, 0.25, 0.0)});
  const SceneEvaluation e = f.Evaluate(1);
  EXPECT_EQ(e.correct, 0u);
  EXPECT_EQ(e.partially_correct, 1u);
  EXPECT_THAT(e.real_tubes[0].touching, ElementsAre(0, 1));
  // Only one of the halves is matched one-to-one: recall is about one half.
  EXPECT_NEAR(e.micro_recall(), 0.5, 0.02);
  EXPECT_NEAR(e.micro_precision(), 0.5, 0.02);
}

TEST(EvaluateScene, TwoTubesMergedIntoOneAreNotCorrect) {
  // Two collinear real tubes end to end (4 cm apart) joined into one virtual tube.
  Fixture f;
  f.AddRealTube(0, -0.30, -0.02, 0.0, [](double) { return 0; });
  f.AddRealTube(1, 0.02, 0.30, 0.0, [](double) { return 0; });
  f.AddVirtualTube({FloorCylinder(-0.30, -0.02, 0.0), FloorCylinder(0.02, 0.30, 0.0)});
  const SceneEvaluation e = f.Evaluate(2);
  EXPECT_EQ(e.correct, 0u);
  EXPECT_EQ(e.partially_correct, 0u);
  EXPECT_EQ(e.not_correct, 2u);
  EXPECT_EQ(e.real_tubes[0].failure, TubeFailure::kMerged);
  EXPECT_EQ(e.real_tubes[1].failure, TubeFailure::kMerged);
  EXPECT_FALSE(e.virtual_tubes[0].pure);
  EXPECT_EQ(e.virtual_tubes[0].stray_cylinders, 1u);
  // Where: at the joint between its two cylinders (end-to-end joining), not in a cylinder.
  EXPECT_EQ(e.virtual_tubes[0].mixed_joints, 1u);
  EXPECT_EQ(e.virtual_tubes[0].mixed_nodes, 0u);
  EXPECT_EQ(e.virtual_tubes[0].mixed_cylinders, 0u);
}

TEST(EvaluateScene, AMergeAtAJunctionNodeIsCountedThere) {
  // A tree: two branches on real tube 0 meet at x = −0.16, where a third branch on real tube 1
  // leaves (a chance junction).
  Fixture f;
  f.AddRealTube(0, -0.30, -0.02, 0.0, [](double) { return 0; });
  f.AddRealTube(1, 0.02, 0.30, 0.0, [](double) { return 0; });
  f.AddVirtualTube(
      {FloorCylinder(-0.30, -0.16, 0.0), FloorCylinder(-0.16, -0.02, 0.0), FloorCylinder(0.02, 0.30, 0.0)});
  Tube& tree = f.result.tubes[0];
  tree.nodes = {{{-0.30, 0, kR}}, {{-0.16, 0, kR}}, {{-0.02, 0, kR}}, {{0.30, 0, kR}}};
  tree.branches = {{0, 1, 0, 1}, {1, 2, 1, 1}, {1, 3, 2, 1}};
  const SceneEvaluation e = f.Evaluate(2);
  EXPECT_EQ(e.not_correct, 2u);
  EXPECT_EQ(e.virtual_tubes[0].mixed_nodes, 1u);
  EXPECT_EQ(e.virtual_tubes[0].mixed_joints, 0u);
  EXPECT_EQ(e.virtual_tubes[0].mixed_cylinders, 0u);
}

TEST(EvaluateScene, MissedHiddenAndUnderCoveredTubes) {
  Fixture f;
  f.AddRealTube(0, -0.25, 0.25, -0.15, [](double) { return -1; });                  // nothing models it
  f.AddRealTube(1, 0.0, 0.008, 0.0, [](double) { return -1; });                     // 39 points: hidden
  f.AddRealTube(2, -0.25, 0.25, 0.15, [](double x) { return x < -0.1 ? 0 : -1; });  // 30 % modeled
  f.AddVirtualTube({FloorCylinder(-0.25, -0.1, 0.15)});
  const SceneEvaluation e = f.Evaluate(3);
  EXPECT_EQ(e.real_tubes[0].failure, TubeFailure::kMissed);
  EXPECT_EQ(e.real_tubes[1].verdict, TubeVerdict::kHidden);
  EXPECT_EQ(e.real_tubes[2].failure, TubeFailure::kUnderCovered);
  EXPECT_EQ(e.not_correct, 2u);
  EXPECT_EQ(e.hidden, 1u);
  EXPECT_EQ(e.correct, 0u);
  // Table 4.6's null row holds the unmodeled points of every tube.
  const ConfusionMatrix& cm = e.confusion;
  EXPECT_EQ(cm.at(cm.null_row(), 0), e.real_tubes[0].visible_points);
  EXPECT_EQ(cm.at(cm.null_row(), 1), e.real_tubes[1].visible_points);
  EXPECT_GT(cm.at(cm.null_row(), 2), 0u);
}

TEST(EvaluateScene, NoVirtualTubeAtAllMissesEveryTube) {
  Fixture f;
  f.AddRealTube(0, -0.25, 0.25, 0.0, [](double) { return -1; });
  const SceneEvaluation e = f.Evaluate(1);
  EXPECT_EQ(e.real_tubes[0].failure, TubeFailure::kMissed);
  EXPECT_EQ(e.real_tubes[0].matched_virtual, -1);
  EXPECT_FALSE(e.mean_length.has_value());
  EXPECT_NEAR(e.micro_recall(), 0.0, kTol);
}

TEST(EvaluateScene, BackgroundInAVirtualTubeLowersPrecisionNotRecall) {
  Fixture f;
  f.AddRealTube(0, -0.25, 0.25, 0.0, [](double) { return 0; });
  f.AddRealTube(-1, -0.25, 0.25, 0.2, [](double) { return 1; });  // "bin" points taken as a tube
  f.AddVirtualTube({FloorCylinder(-0.25, 0.25, 0.0)});
  f.AddVirtualTube({FloorCylinder(-0.25, 0.25, 0.2)});
  const SceneEvaluation e = f.Evaluate(1);
  EXPECT_EQ(e.correct, 1u);
  EXPECT_NEAR(e.micro_recall(), 1.0, kTol);
  EXPECT_NEAR(e.micro_precision(), 0.5, kTol);
  EXPECT_NEAR(e.accuracy(), 0.5, kTol);
  EXPECT_EQ(e.virtual_tubes[1].majority, -1);
  EXPECT_EQ(e.virtual_tubes[1].matched_real, -1);
}

TEST(EvaluateScene, RejectsInconsistentInput) {
  Fixture f;
  f.AddRealTube(0, -0.1, 0.1, 0.0, [](double) { return 0; });
  f.AddVirtualTube({FloorCylinder(-0.1, 0.1, 0.0)});
  std::vector<std::int32_t> short_truth(f.truth.begin(), f.truth.end() - 1);
  try {
    EvaluateScene(f.result, short_truth, 1, EvaluationParams{});
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("ground-truth labels"));
  }
  EvaluationParams bad;
  bad.coverage = 1.5;
  try {
    EvaluateScene(f.result, f.truth, 1, bad);
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("evaluation.coverage"));
  }
  f.result.tube_of_point[0] = 7;  // no tube with id 7
  EXPECT_THROW(EvaluateScene(f.result, f.truth, 1, EvaluationParams{}), InvalidArgument);
}

}  // namespace
}  // namespace tubepick

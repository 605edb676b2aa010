#include "core/evaluation/aggregation.h"

#include <vector>

#include <gtest/gtest.h>

namespace tubepick {
namespace {

constexpr double kTol = 1e-12;

SceneEvaluation MakeScene(std::uint32_t tubes, std::uint32_t correct, std::uint32_t partial,
                          std::uint32_t virtuals, double filter_s, double total_s) {
  SceneEvaluation s;
  s.real_tube_count = tubes;
  s.correct = correct;
  s.partially_correct = partial;
  s.not_correct = tubes - correct - partial;
  s.real_tubes.resize(tubes);
  for (std::uint32_t j = correct + partial; j < tubes; ++j) {
    s.real_tubes[j].verdict = TubeVerdict::kNotCorrect;
    s.real_tubes[j].failure = TubeFailure::kMerged;
  }
  s.virtual_tubes.resize(virtuals);
  s.timings = {{"filter", filter_s}, {"joining", 0.001}};
  s.total_seconds = total_s;
  return s;
}

TEST(Aggregation, MeansPerSceneAndPooledPointScores) {
  std::vector<SceneEvaluation> scenes;
  scenes.push_back(MakeScene(2, 2, 0, 2, 0.1, 0.2));
  scenes.push_back(MakeScene(2, 1, 1, 3, 0.3, 0.4));
  scenes.push_back(MakeScene(1, 1, 0, 1, 0.05, 0.1));
  scenes[0].segmentation_error = 0.5;
  scenes[0].mean_length = 0.40;
  scenes[0].stddev_length = 0.02;
  scenes[1].mean_length = 0.50;
  scenes[1].stddev_length = 0.04;  // no segmentation error (nothing visible)
  // Pooled: scene 0 matched 90 of 100 real points, scene 1 matched 10 of 100 → recall 0.5 (a
  // mean of per-scene recalls would also be 0.5 here; the precisions below differ).
  scenes[0].matched_points = 90;
  scenes[0].real_points = 100;
  scenes[0].labelled_points = 90;
  scenes[1].matched_points = 10;
  scenes[1].real_points = 100;
  scenes[1].labelled_points = 110;
  scenes[1].background_points = 50;
  scenes[1].background_null = 50;

  const std::vector<EvaluationAggregate> rows = AggregateByTubeCount(scenes);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].tube_count, 1u);
  EXPECT_EQ(rows[0].scenes, 1u);
  const EvaluationAggregate& two = rows[1];
  EXPECT_EQ(two.tube_count, 2u);
  EXPECT_EQ(two.scenes, 2u);
  EXPECT_EQ(two.real_tubes, 4u);
  EXPECT_NEAR(two.correct, 1.5, kTol);
  EXPECT_NEAR(two.partially_correct, 0.5, kTol);
  EXPECT_NEAR(two.not_correct, 0.0, kTol);
  EXPECT_NEAR(two.virtual_tubes, 2.5, kTol);
  EXPECT_NEAR(two.correct_fraction, 0.75, kTol);
  EXPECT_EQ(two.scenes_all_correct, 1u);
  ASSERT_TRUE(two.segmentation_error.has_value());
  EXPECT_NEAR(*two.segmentation_error, 0.5, kTol);  // only scene 0 defines it
  EXPECT_NEAR(*two.mean_length, 0.45, kTol);
  EXPECT_NEAR(*two.stddev_length, 0.03, kTol);
  EXPECT_NEAR(two.micro_recall, 0.5, kTol);
  EXPECT_NEAR(two.micro_precision, 100.0 / 200.0, kTol);
  EXPECT_NEAR(two.accuracy, (100.0 + 50.0) / 250.0, kTol);
  ASSERT_EQ(two.mean_timings.size(), 2u);
  EXPECT_EQ(two.mean_timings[0].stage, "filter");
  EXPECT_NEAR(two.mean_timings[0].seconds, 0.2, kTol);
  EXPECT_NEAR(two.mean_total_seconds, 0.3, kTol);
  EXPECT_NEAR(two.max_total_seconds, 0.4, kTol);

  const EvaluationAggregate all = Aggregate({&scenes[0], &scenes[1], &scenes[2]});
  EXPECT_EQ(all.tube_count, 0u);  // mixed counts
  EXPECT_EQ(all.real_tubes, 5u);
  EXPECT_EQ(all.total_correct, 4u);
  EXPECT_NEAR(all.correct_fraction, 0.8, kTol);
  EXPECT_NEAR(all.correct, 4.0 / 3.0, kTol);
  EXPECT_EQ(all.merged, 0u);
}

TEST(Aggregation, CountsFailuresAndHiddenTubes) {
  SceneEvaluation s = MakeScene(3, 1, 0, 1, 0.1, 0.1);
  s.hidden = 1;
  s.not_correct = 1;
  s.real_tubes[2].verdict = TubeVerdict::kHidden;
  s.real_tubes[2].failure = TubeFailure::kNone;
  const EvaluationAggregate a = Aggregate({&s});
  EXPECT_EQ(a.merged, 1u);
  EXPECT_EQ(a.total_hidden, 1u);
  EXPECT_NEAR(a.correct_fraction, 1.0 / 3.0, kTol);
  EXPECT_NEAR(a.correct_fraction_visible, 0.5, kTol);
  EXPECT_TRUE(Aggregate({}).mean_timings.empty());
}

}  // namespace
}  // namespace tubepick

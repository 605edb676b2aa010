#include "core/evaluation/assignment.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/common/errors.h"

namespace tubepick {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
constexpr double kTol = 1e-9;

// Smallest summed cost over every way of giving min(rows, columns) pairs (brute force).
double BruteForceMinCost(const std::vector<std::vector<double>>& cost) {
  const std::size_t rows = cost.size(), columns = cost.front().size();
  const bool transpose = rows > columns;
  const std::size_t small = transpose ? columns : rows, large = transpose ? rows : columns;
  std::vector<std::size_t> perm(large);
  std::iota(perm.begin(), perm.end(), 0);
  double best = std::numeric_limits<double>::infinity();
  do {
    double sum = 0.0;
    for (std::size_t k = 0; k < small; ++k) sum += transpose ? cost[perm[k]][k] : cost[k][perm[k]];
    best = std::min(best, sum);
  } while (std::next_permutation(perm.begin(), perm.end()));
  return best;
}

TEST(Assignment, BeatsTheGreedyChoiceOnAHandMadeConfusion) {
  // Virtual tube 0 shares 10 points with real tube 0 and 9 with real tube 1; virtual tube 1
  // shares 9 with real tube 0 only. Greedy (largest first) pairs 0–0 and leaves 1 unmatched
  // (10 points); the optimum pairs 0–1 and 1–0 (18 points).
  const Assignment a = MatchMaxOverlap({{10, 9}, {9, 0}}, 2);
  EXPECT_THAT(a.column_of_row, ElementsAre(1, 0));
  EXPECT_THAT(a.row_of_column, ElementsAre(1, 0));
  EXPECT_NEAR(a.total_cost, -18.0, kTol);
}

TEST(Assignment, LeavesOutPairsWithoutOverlap) {
  // Three virtual tubes, two real ones; virtual tube 2 shares nothing with anyone.
  const Assignment a = MatchMaxOverlap({{0, 50}, {40, 0}, {0, 0}}, 2);
  EXPECT_THAT(a.column_of_row, ElementsAre(1, 0, -1));
  EXPECT_THAT(a.row_of_column, ElementsAre(1, 0));
  // A real tube nobody models stays unmatched even though a row is free.
  const Assignment b = MatchMaxOverlap({{30, 0, 0}}, 3);
  EXPECT_THAT(b.column_of_row, ElementsAre(0));
  EXPECT_THAT(b.row_of_column, ElementsAre(0, -1, -1));
  // No virtual tube at all: every real tube is unmatched.
  const Assignment none = MatchMaxOverlap({}, 2);
  EXPECT_TRUE(none.column_of_row.empty());
  EXPECT_THAT(none.row_of_column, ElementsAre(-1, -1));
  EXPECT_THROW(MatchMaxOverlap({{1, 2}}, 3), InvalidArgument);
}

TEST(Assignment, RectangularBothWaysMatchesBruteForce) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> uniform(-5.0, 20.0);
  for (int trial = 0; trial < 200; ++trial) {
    const std::size_t rows = 1 + rng() % 5, columns = 1 + rng() % 5;
    std::vector<std::vector<double>> cost(rows, std::vector<double>(columns));
    for (auto& row : cost)
      for (double& c : row) c = std::round(uniform(rng));  // integers: many ties
    const Assignment a = SolveMinCostAssignment(cost);
    ASSERT_EQ(a.column_of_row.size(), rows);
    ASSERT_EQ(a.row_of_column.size(), columns);
    std::size_t pairs = 0;
    double sum = 0.0;
    for (std::size_t r = 0; r < rows; ++r) {
      if (a.column_of_row[r] < 0) continue;
      ++pairs;
      EXPECT_EQ(a.row_of_column[a.column_of_row[r]], static_cast<std::int32_t>(r));
      sum += cost[r][a.column_of_row[r]];
    }
    EXPECT_EQ(pairs, std::min(rows, columns));
    EXPECT_NEAR(sum, a.total_cost, kTol);
    EXPECT_NEAR(a.total_cost, BruteForceMinCost(cost), kTol) << "trial " << trial;
  }
}

TEST(Assignment, EmptyAndInvalidInputs) {
  EXPECT_TRUE(SolveMinCostAssignment({}).column_of_row.empty());
  const Assignment no_columns = SolveMinCostAssignment({{}, {}});
  EXPECT_THAT(no_columns.column_of_row, ElementsAre(-1, -1));
  try {
    SolveMinCostAssignment({{1.0, 2.0}, {3.0}});
    FAIL() << "ragged matrix accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("row 1 has 1 costs"));
  }
  try {
    SolveMinCostAssignment({{1.0, std::numeric_limits<double>::quiet_NaN()}});
    FAIL() << "NaN accepted";
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("cost[0][1] is not finite"));
  }
}

}  // namespace
}  // namespace tubepick

// The round tables of `tubepick cell` (thesis Tables 5.4-5.9) from known statistics.
#include "clients/cli/cell/cell_tables.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace tubepick::cli {
namespace {

using ::testing::HasSubstr;

cell::CellStatistics TwoCounts() {
  cell::CellStatistics s;
  s.rounds = 4;
  s.bins_emptied = 3;
  s.picks = 10;
  s.tubes_total = 12;
  s.by_count[7] = {.picked = 4,
                   .first_try = 3,
                   .attempts = 5,
                   .simulated_upward = 1,
                   .simulated_escape = 0,
                   .resolution = 1};
  s.by_count[2] = {.picked = 6,
                   .first_try = 6,
                   .attempts = 6,
                   .simulated_upward = 0,
                   .simulated_escape = 2,
                   .resolution = 0};
  s.resolution = {.uses = 1, .successes = 1};
  s.times.planning = {0.2, 0.4, 0.3};
  return s;
}

TEST(CellTables, ColumnsAreTubeCountsLargestFirstThenOverall) {
  const std::string text = FormatCellTables(TwoCounts(), "pvc, 4 rounds of 7 tubes");
  EXPECT_THAT(text, HasSubstr("== Cell results: pvc, 4 rounds of 7 tubes =="));
  EXPECT_THAT(text, HasSubstr("bins emptied                            3/4 (75%)"));
  EXPECT_THAT(text, HasSubstr("tubes picked                           10/12"));
  // Table 5.5: 3 of 4 first-try at 7 tubes, 6 of 6 at 2, 9 of 10 overall.
  const std::string header = "  tubes in the bin                        7      2  overall";
  EXPECT_THAT(text, HasSubstr(header));
  EXPECT_THAT(text, HasSubstr("  success rate                          75%   100%      90%"));
  // Table 5.6 total simulation usage: 1 of 5, 2 of 6, 3 of 11.
  EXPECT_THAT(text, HasSubstr("  usage rate (total)                    20%    33%      27%"));
  // Table 5.9 and the times: median 0.30 s, mean 0.30 s of planning.
  EXPECT_THAT(text, HasSubstr("  success rate                         100% of 1"));
  EXPECT_THAT(text, HasSubstr("  planning (PlanPick, wall)             0.30s    0.30s"));
}

TEST(CellTables, TubesUnaccountedForSayWhetherAnyRoundKnewItsCount) {
  cell::CellStatistics s = TwoCounts();
  s.tubes_unaccounted = 3;
  s.counted_rounds = 4;
  EXPECT_THAT(FormatCellTables(s, "counted"),
              HasSubstr("  bin empty, tubes unaccounted for        3 (4 of 4 rounds counted)"));
  // No round knew tubes_per_bin: a dash, not a reassuring 0.
  EXPECT_THAT(FormatCellTables(TwoCounts(), "not counted"),
              HasSubstr("  bin empty, tubes unaccounted for        - (tubes_per_bin not known)"));
}

TEST(CellTables, AnUnusedRowShowsADashNotAZeroRate) {
  const std::string text = FormatCellTables(cell::CellStatistics{}, "empty");
  EXPECT_THAT(text, HasSubstr("bins emptied                            0/0 (-)"));
  EXPECT_THAT(text, HasSubstr("  success rate (upward trajectories)      - of 0"));
}

}  // namespace
}  // namespace tubepick::cli

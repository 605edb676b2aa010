#include "clients/cell/cell_statistics.h"

#include <gtest/gtest.h>

namespace tubepick::cell {
namespace {

using nlohmann::json;

json Attempt(int round, int in_bin_before, int in_bin_after, const std::string& result,
             const std::string& kind = "upward", bool simulated = false, int resolution_used = 0,
             bool resolution_succeeded = false) {
  return {{"type", "attempt"},
          {"round", round},
          {"tubes_left_plan", in_bin_before + 1},  // the truth wins over the planner's count
          {"trajectory_kind", kind},
          {"used_simulation", simulated},
          {"result", result},
          {"resolution", {{"used", resolution_used}, {"succeeded", resolution_succeeded}}},
          {"durations", {{"planning_wall_s", 1.0}, {"robot_device_s", 10.0}, {"attempt_wall_s", 2.0}}},
          {"truth_before", {{"tubes_in_bin", in_bin_before}}},
          {"truth_after", {{"tubes_in_bin", in_bin_after}}}};
}

json End(int round, const std::string& reason, int start, int left) {
  return {{"type", "end"},
          {"round", round},
          {"reason", reason},
          {"truth_start", {{"tubes_in_bin", start}}},
          {"truth", {{"tubes_in_bin", left}}}};
}

TEST(CellStatisticsTest, OperatorStopsAreCountedApartFromFaults) {
  json stopped = Attempt(0, 2, 2, "stopped");
  const CellStatistics s = SummarizeRecords({stopped, End(0, "stopped", 2, 2), End(1, "fault", 2, 2)});
  EXPECT_EQ(s.rounds, 2u);
  EXPECT_EQ(s.operator_stops, 1u);
  EXPECT_EQ(s.fault_stops, 1u);
  EXPECT_EQ(s.attempts, 1u);
  EXPECT_EQ(s.picks, 0u);
  EXPECT_EQ(StatisticsJson(s)["operator_stops"], 1);
}

TEST(CellStatisticsTest, ReproducesTheThesisTablesFromRecords) {
  const std::vector<json> records = {
      // Round 0: 3 tubes. At 3: entangled pair returned, then picked on the second attempt
      // with an escape trajectory found by simulation. At 2: picked after a resolution. At 1: picked.
      Attempt(0, 3, 3, "multiple_returned", "upward", true, 1, false),
      Attempt(0, 3, 2, "picked", "escape", true),
      Attempt(0, 2, 1, "picked", "upward", false, 1, true),
      Attempt(0, 1, 0, "picked"),
      End(0, "bin_empty", 3, 0),
      // Round 1: 3 tubes; the first pick carries a second tube out; a scan without plan; then a
      // limit stop with one tube left.
      Attempt(1, 3, 1, "picked"),
      {{"type", "attempt"},
       {"round", 1},
       {"tubes_left_plan", 1},
       {"result", "no_plan"},
       {"durations", {{"planning_wall_s", 3.0}}}},
      Attempt(1, 1, 1, "grasp_failed"),
      End(1, "limit_reached", 3, 1),
  };
  const CellStatistics s = SummarizeRecords(records);
  EXPECT_EQ(s.rounds, 2u);
  EXPECT_EQ(s.bins_emptied, 1u);
  EXPECT_EQ(s.limit_stops, 1u);
  EXPECT_EQ(s.tubes_total, 6u);
  EXPECT_EQ(s.picks, 4u);
  EXPECT_EQ(s.tubes_lost, 1u);
  EXPECT_EQ(s.attempts, 6u);
  EXPECT_EQ(s.no_plan_scans, 1u);
  EXPECT_EQ(s.grasp_failures, 1u);

  ASSERT_EQ(s.by_count.size(), 3u);
  EXPECT_EQ(s.by_count.begin()->first, 3u);  // largest first, like the thesis' columns
  const CountStatistics& at3 = s.by_count.at(3);
  EXPECT_EQ(at3.picked, 2u);
  EXPECT_EQ(at3.first_try, 1u);  // round 0 needed two attempts, round 1 one
  EXPECT_EQ(at3.attempts, 3u);
  EXPECT_EQ(at3.simulated_upward, 1u);
  EXPECT_EQ(at3.simulated_escape, 1u);
  EXPECT_EQ(at3.resolution, 1u);
  EXPECT_EQ(s.by_count.at(2).first_try, 1u);
  EXPECT_EQ(s.by_count.at(1).picked, 1u);
  EXPECT_EQ(s.by_count.at(1).attempts, 2u);
  EXPECT_NEAR(s.FirstTryRate(), 3.0 / 4.0, 1e-12);

  EXPECT_EQ(s.simulated_attempts, 2u);
  EXPECT_EQ(s.simulated_upward.uses, 1u);
  EXPECT_EQ(s.simulated_upward.successes, 0u);
  EXPECT_EQ(s.simulated_escape.successes, 1u);
  EXPECT_EQ(s.upward.uses, 5u);
  EXPECT_EQ(s.upward.successes, 3u);
  EXPECT_EQ(s.resolution.uses, 2u);
  EXPECT_EQ(s.resolution.successes, 1u);
  EXPECT_DOUBLE_EQ(s.resolution.rate(), 0.5);

  // Time per pick: the first pick of round 0 took two attempts (2 planning s, 20 motion s).
  ASSERT_EQ(s.times.planning.size(), 4u);
  EXPECT_DOUBLE_EQ(s.times.planning[0], 2.0);
  EXPECT_DOUBLE_EQ(s.times.motion[0], 20.0);
  EXPECT_DOUBLE_EQ(Median(s.times.planning), 1.0);
  EXPECT_DOUBLE_EQ(Mean(s.times.motion), 12.5);

  const json j = StatisticsJson(s);
  EXPECT_EQ(j["bins_emptied"], 1);
  EXPECT_EQ(j["by_tubes_in_bin"][0]["tubes_in_bin"], 3);
}

TEST(CellStatisticsTest, WithoutTruthTheplannersCountAndBinEmptyDecide) {
  json a = Attempt(0, 2, 1, "picked");
  a.erase("truth_before");
  a.erase("truth_after");
  const CellStatistics s = SummarizeRecords({a, {{"type", "end"}, {"round", 0}, {"reason", "bin_empty"}}});
  EXPECT_EQ(s.bins_emptied, 1u);
  EXPECT_EQ(s.by_count.count(3), 1u);  // tubes_left_plan
  EXPECT_EQ(s.tubes_total, 0u);
}

TEST(CellStatisticsTest, TubesUnaccountedForAreSummedOverTheRounds) {
  json first = End(0, "bin_empty", 20, 0);
  first["tubes_unaccounted"] = 2;
  json second = End(1, "bin_empty", 20, 0);
  second["tubes_unaccounted"] = 1;
  json third = End(2, "bin_empty", 20, 0);
  for (json* end : {&first, &second}) (*end)["tubes_expected"] = 20;
  const CellStatistics s = SummarizeRecords({first, second, third});
  EXPECT_EQ(s.tubes_unaccounted, 3u);
  EXPECT_EQ(s.counted_rounds, 2u);  // the third round's count was not known
  EXPECT_EQ(StatisticsJson(s)["tubes_unaccounted"], 3);
  EXPECT_EQ(StatisticsJson(s)["counted_rounds"], 2);
}

TEST(CellStatisticsTest, MedianOfEvenAndOddLists) {
  EXPECT_DOUBLE_EQ(Median({3.0, 1.0, 2.0}), 2.0);
  EXPECT_DOUBLE_EQ(Median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_DOUBLE_EQ(Median({}), 0.0);
}

}  // namespace
}  // namespace tubepick::cell

namespace tubepick::cell {
namespace {

TEST(CellStatisticsTest, NudgesCountWhenAPickFollowsBeforeTheNextScanWithoutPlan) {
  json nudge = Attempt(0, 1, 1, "nudge");
  nudge["nudge"] = {{"tube", 0}};
  json nudge1 = Attempt(1, 1, 1, "nudge");
  nudge1["nudge"] = {{"tube", 0}};
  json fault = Attempt(1, 1, 1, "fault");
  fault["nudge"] = {{"tube", 0}};
  const std::vector<json> records = {
      // Round 0: nudge, nudge, picked (one success, one nudge superseded by the next), nudge at the end.
      nudge, nudge, Attempt(0, 1, 0, "picked"), nudge, End(0, "limit_reached", 1, 0),
      // Round 1: a nudge, a scan without a plan, then a pick: the nudge did not help; a nudge fault.
      nudge1, Attempt(1, 1, 1, "no_plan"), Attempt(1, 1, 0, "picked"), fault, End(1, "fault", 1, 0)};
  const CellStatistics s = SummarizeRecords(records);
  EXPECT_EQ(s.nudges.uses, 5u);
  EXPECT_EQ(s.nudges.successes, 1u);
  EXPECT_EQ(s.attempts, 2u);  // nudges (and a fault during one) are not picking attempts
  EXPECT_EQ(s.picks, 2u);
  EXPECT_EQ(s.no_plan_scans, 1u);
  EXPECT_EQ(StatisticsJson(s)["nudges"]["uses"], 5);
}

}  // namespace
}  // namespace tubepick::cell

namespace tubepick::cell {
namespace {

TEST(CellStatisticsTest, PathsCountWhatEachAttemptNeededAndWhetherItWorked) {
  json sure = Attempt(0, 4, 3, "picked");
  sure["certainty"] = "sure";
  json lucky = Attempt(0, 3, 3, "multiple_returned", "upward", false, 1, false);
  lucky["certainty"] = "unsure";
  json escape = Attempt(0, 3, 2, "picked", "escape", true);
  escape["certainty"] = "simulated";
  json resolved = Attempt(0, 2, 1, "picked", "upward", true, 1, true);
  resolved["certainty"] = "simulated";
  json old_record = Attempt(0, 1, 0, "picked");  // written before plans carried a certainty
  const CellStatistics s =
      SummarizeRecords({sure, lucky, escape, resolved, old_record, End(0, "bin_empty", 4, 0)});
  EXPECT_EQ(s.free_pick.uses, 2u);  // the sure plan and the old unsimulated upward one
  EXPECT_EQ(s.free_pick.successes, 2u);
  EXPECT_EQ(s.needed_luck.uses, 1u);
  EXPECT_EQ(s.needed_luck.successes, 0u);
  EXPECT_EQ(s.escape_path.uses, 1u);
  EXPECT_EQ(s.escape_path.successes, 1u);
  EXPECT_EQ(s.simulated_path.uses, 2u);
  EXPECT_EQ(s.simulated_path.successes, 1u);  // the resolved pick needed the rotation: not worked
  EXPECT_EQ(s.resolution.uses, 2u);
  EXPECT_EQ(s.resolution.successes, 1u);
  const json paths = StatisticsJson(s)["paths"];
  EXPECT_EQ(paths["free_pick"]["uses"], 2);
  EXPECT_EQ(paths["simulated"]["successes"], 1);
}

}  // namespace
}  // namespace tubepick::cell

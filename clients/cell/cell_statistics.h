#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace tubepick::cell {

/// Uses and successes of something (an attempt kind, the resolution).
struct UseCount {
  std::uint32_t uses = 0;
  std::uint32_t successes = 0;
  /// successes / uses, 0 when unused.
  double rate() const { return uses ? static_cast<double>(successes) / uses : 0.0; }
};

/// Picking statistics at one number of tubes in the bin (the columns of Tables 5.5, 5.6, 5.8).
struct CountStatistics {
  /// Tubes picked while this many were in the bin (Table 5.5, "number of picked tubes").
  std::uint32_t picked = 0;
  /// ... of which the first attempt at this count picked exactly one tube (Table 5.5).
  std::uint32_t first_try = 0;
  /// Picking attempts at this count (Table 5.6, "number of picking attempts").
  std::uint32_t attempts = 0;
  /// Attempts whose plan came from a simulated evaluation, by the chosen trajectory (Table 5.6).
  std::uint32_t simulated_upward = 0;
  std::uint32_t simulated_escape = 0;
  /// Attempts that used the resolution rotation (Table 5.8).
  std::uint32_t resolution = 0;
};

/// Per-pick durations: everything spent since the previous pick of the round, seconds.
struct PickTimes {
  /// PlanPick wall time as the client saw it (modeling + planning + transfer).
  std::vector<double> planning;
  /// Robot motion time in device time (simulated seconds in the simulated cell).
  std::vector<double> motion;
  /// Wall time of the whole cycle (scan, plan, every device call).
  std::vector<double> cycle_wall;
};

/// The thesis' result tables (5.4-5.10) computed from controller records. The number of tubes in
/// the bin is the ground truth (truth_before.tubes_in_bin) when the records carry it, else the
/// number of tubes the planner modeled.
struct CellStatistics {
  std::uint32_t rounds = 0;
  /// Rounds that ended with no tube left in the bin (ground truth, else the planner's bin_empty).
  std::uint32_t bins_emptied = 0;
  /// Rounds the planner declared empty while tubes were still in the bin (ground truth).
  std::uint32_t false_empty = 0;
  /// Tubes the controller found unaccounted for when a bin looked empty (CellRunResult::
  /// tubes_unaccounted: tubes_per_bin known, fewer placed; no ground truth needed), and the rounds
  /// whose count was known (tubes_expected > 0): with none, the 0 says nothing.
  std::uint32_t tubes_unaccounted = 0;
  std::uint32_t counted_rounds = 0;
  std::uint32_t limit_stops = 0;
  std::uint32_t fault_stops = 0;
  /// Rounds the operator stopped (CellController::RequestStop).
  std::uint32_t operator_stops = 0;
  /// Tubes in the bins at the start (ground truth; 0 without it).
  std::uint32_t tubes_total = 0;
  /// Attempts that ended in "picked".
  std::uint32_t picks = 0;
  /// Tubes that left the bin during attempts that did not place exactly one of them: carried along
  /// with the picked one, or dropped outside (ground truth).
  std::uint32_t tubes_lost = 0;
  /// Picking attempts (grasp executions) and scans that gave no plan (without a nudge).
  std::uint32_t attempts = 0;
  std::uint32_t no_plan_scans = 0;
  std::uint32_t grasp_failures = 0;
  /// Attempts whose tube the controller saw slip out between grasp and place ("lost").
  std::uint32_t lost_in_transit = 0;
  /// Attempts whose plan used simulation (Table 5.6 "usage rate (total)").
  std::uint32_t simulated_attempts = 0;
  /// By tubes in the bin, largest first.
  std::map<std::uint32_t, CountStatistics, std::greater<>> by_count;
  /// Table 5.7: attempts with simulation, by trajectory (escape includes occlusion escapes).
  UseCount simulated_upward, simulated_escape;
  /// Every attempt by trajectory.
  UseCount upward, escape;
  /// Table 5.9: attempts that used the resolution rotation and those it turned into a pick.
  UseCount resolution;
  /// Which path each attempt's plan took, and how often it worked: picked one tube with no
  /// resolution rotation. A free pick is a sure plan (a non-occluded tube nothing lies on, lifted
  /// straight up); a plan that needed luck is an unsure one (not simulated: occluded, or lain on);
  /// escape and simulated count every escape trajectory and every simulated plan.
  UseCount free_pick, needed_luck, escape_path, simulated_path;
  /// Nudges (result "nudge", or a fault during one), and those followed by a pick in the same
  /// round before the next nudge or scan without a plan.
  UseCount nudges;
  PickTimes times;

  /// Overall first-try success: sum of first_try over sum of picked.
  double FirstTryRate() const;
};

/// Aggregates records of any number of rounds ("attempt" and "end" records; others are ignored).
/// @throws InvalidArgument when a record lacks a field the statistics need.
CellStatistics SummarizeRecords(const std::vector<nlohmann::json>& records);

/// Median and mean of `values` (0 for an empty list).
double Median(std::vector<double> values);
double Mean(const std::vector<double>& values);

/// The statistics as one JSON object (for --json).
nlohmann::json StatisticsJson(const CellStatistics& stats);

}  // namespace tubepick::cell

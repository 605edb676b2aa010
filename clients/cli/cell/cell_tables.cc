#include "clients/cli/cell/cell_tables.h"

#include <fmt/core.h>

#include <functional>

namespace tubepick::cli {
namespace {

using cell::CellStatistics;
using cell::CountStatistics;

std::string Percent(std::uint32_t part, std::uint32_t whole) {
  return whole ? fmt::format("{:.0f}%", 100.0 * part / whole) : "-";
}

/// One row: label, one cell per tube count, then the overall cell.
std::string Row(const CellStatistics& s, const std::string& label,
                const std::function<std::string(const CountStatistics&)>& cell, const std::string& overall) {
  std::string line = fmt::format("  {:<34}", label);
  for (const auto& [n, c] : s.by_count) line += fmt::format("{:>7}", cell(c));
  return line + fmt::format("{:>9}\n", overall);
}

std::string Header(const CellStatistics& s) {
  std::string line = fmt::format("  {:<34}", "tubes in the bin");
  for (const auto& [n, c] : s.by_count) line += fmt::format("{:>7}", n);
  return line + fmt::format("{:>9}\n", "overall");
}

}  // namespace

std::string FormatCellTables(const CellStatistics& s, const std::string& title) {
  std::uint32_t picked = 0, first = 0, attempts = 0, sim_up = 0, sim_esc = 0, resolution = 0;
  for (const auto& [n, c] : s.by_count) {
    picked += c.picked;
    first += c.first_try;
    attempts += c.attempts;
    sim_up += c.simulated_upward;
    sim_esc += c.simulated_escape;
    resolution += c.resolution;
  }
  std::string out = fmt::format("== Cell results: {} ==\n\n", title);

  out += "Table 5.4: rounds where the bin was emptied\n";
  out += fmt::format("  {:<34}{:>7}/{} ({})\n", "bins emptied", s.bins_emptied, s.rounds,
                     Percent(s.bins_emptied, s.rounds));
  out += fmt::format("  {:<34}{:>7}/{}\n", "tubes picked", s.picks, s.tubes_total);
  out += fmt::format("  {:<34}{:>7} limit, {} fault, {} operator\n", "rounds stopped early", s.limit_stops,
                     s.fault_stops, s.operator_stops);
  out += fmt::format("  {:<34}{:>7}\n", "bin reported empty, tubes left", s.false_empty);
  out +=
      s.counted_rounds > 0
          ? fmt::format("  {:<34}{:>7} ({} of {} rounds counted)\n", "bin empty, tubes unaccounted for",
                        s.tubes_unaccounted, s.counted_rounds, s.rounds)
          : fmt::format("  {:<34}{:>7} (tubes_per_bin not known)\n", "bin empty, tubes unaccounted for", "-");
  out += fmt::format("  {:<34}{:>7}\n", "tubes carried along or dropped out", s.tubes_lost);
  out += fmt::format("  {:<34}{:>7}\n", "tubes seen slipping out (lost)", s.lost_in_transit);
  out += "\n";

  out += "Table 5.5: picked tubes placed on the first attempt\n";
  out += Header(s);
  out += Row(
      s, "success rate", [](const CountStatistics& c) { return Percent(c.first_try, c.picked); },
      Percent(first, picked));
  out += Row(
      s, "number of picked tubes", [](const CountStatistics& c) { return std::to_string(c.picked); },
      std::to_string(picked));
  out += "\n";

  out += "Table 5.6: picking attempts with trajectory simulation, by chosen trajectory\n";
  out += Header(s);
  out += Row(
      s, "usage rate (upward trajectories)",
      [](const CountStatistics& c) { return Percent(c.simulated_upward, c.attempts); },
      Percent(sim_up, attempts));
  out += Row(
      s, "usage rate (escape trajectories)",
      [](const CountStatistics& c) { return Percent(c.simulated_escape, c.attempts); },
      Percent(sim_esc, attempts));
  out += Row(
      s, "usage rate (total)",
      [](const CountStatistics& c) { return Percent(c.simulated_upward + c.simulated_escape, c.attempts); },
      Percent(sim_up + sim_esc, attempts));
  out += Row(
      s, "number of picking attempts", [](const CountStatistics& c) { return std::to_string(c.attempts); },
      std::to_string(attempts));
  out += fmt::format("  ({} grasps closed on nothing; {} scans gave no plan)\n\n", s.grasp_failures,
                     s.no_plan_scans);

  out += "Table 5.7: attempts with trajectory simulation that picked a tube\n";
  const auto use_line = [](const std::string& label, const cell::UseCount& u) {
    return fmt::format("  {:<34}{:>7} of {}\n", label, Percent(u.successes, u.uses), u.uses);
  };
  cell::UseCount sim_total{s.simulated_upward.uses + s.simulated_escape.uses,
                           s.simulated_upward.successes + s.simulated_escape.successes};
  out += use_line("success rate (upward trajectories)", s.simulated_upward);
  out += use_line("success rate (escape trajectories)", s.simulated_escape);
  out += use_line("success rate (total)", sim_total);
  out += "  every attempt, by trajectory:\n";
  out += use_line("upward: success rate", s.upward);
  out += use_line("escape: success rate", s.escape);
  out += "\n";

  out += "Table 5.8: picking attempts with entanglement resolution\n";
  out += Header(s);
  out += Row(
      s, "usage rate", [](const CountStatistics& c) { return Percent(c.resolution, c.attempts); },
      Percent(resolution, attempts));
  out += "\n";

  out += "Table 5.9: resolution attempts that ended in a pick\n";
  out += use_line("success rate", s.resolution);
  out += "\n";

  out += "Paths: how often each was needed, and how often it worked (one tube picked, no resolution)\n";
  const auto path_line = [](const std::string& label, const cell::UseCount& u) {
    return fmt::format("  {:<34}{:>5} attempts{:>9} worked\n", label, u.uses, Percent(u.successes, u.uses));
  };
  out += path_line("free pick (sure plan)", s.free_pick);
  out += path_line("plan that needed luck (unsure)", s.needed_luck);
  out += path_line("escape trajectory", s.escape_path);
  out += path_line("simulated choice", s.simulated_path);
  out += fmt::format("  {:<34}{:>5} attempts{:>9} freed one tube\n", "resolution rotation", s.resolution.uses,
                     Percent(s.resolution.successes, s.resolution.uses));
  out += "\n";

  out += "Nudges: a tube along a wall dragged off it when no plan was executable (beyond the thesis)\n";
  out += fmt::format("  {:<34}{:>7}\n", "nudges", s.nudges.uses);
  out += use_line("followed by a pick", s.nudges);
  out += "\n";

  out += "Time per pick (everything since the previous pick)\n";
  out += fmt::format("  {:<34}{:>9}{:>9}\n", "", "median", "mean");
  const auto time_line = [](const std::string& label, const std::vector<double>& v) {
    return fmt::format("  {:<34}{:>8.2f}s{:>8.2f}s\n", label, cell::Median(v), cell::Mean(v));
  };
  out += time_line("planning (PlanPick, wall)", s.times.planning);
  out += time_line("robot motion (device time)", s.times.motion);
  out += time_line("whole cycle (wall)", s.times.cycle_wall);
  return out;
}

}  // namespace tubepick::cli

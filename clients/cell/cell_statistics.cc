#include "clients/cell/cell_statistics.h"

#include <fmt/core.h>

#include <algorithm>
#include <numeric>
#include <set>

#include "core/common/errors.h"

namespace tubepick::cell {
namespace {

using nlohmann::json;

/// Per-round bookkeeping while walking the records.
struct RoundState {
  std::set<std::uint32_t> counts_attempted;
  std::set<std::uint32_t> first_try_success;  // counts whose first attempt picked
  double planning = 0.0, motion = 0.0, cycle = 0.0;
  /// A nudge not yet followed by a pick.
  bool nudge_pending = false;
};

bool HasTruth(const json& truth) { return truth.is_object() && truth.contains("tubes_in_bin"); }

std::uint32_t TubesInBin(const json& record) {
  if (record.contains("truth_before") && HasTruth(record["truth_before"]))
    return record["truth_before"]["tubes_in_bin"].get<std::uint32_t>();
  return record.at("tubes_left_plan").get<std::uint32_t>();
}

double Duration(const json& record, const char* key) {
  if (!record.contains("durations")) return 0.0;
  const json& d = record["durations"];
  return d.contains(key) && d[key].is_number() ? d[key].get<double>() : 0.0;
}

}  // namespace

double CellStatistics::FirstTryRate() const {
  std::uint32_t picked = 0, first = 0;
  for (const auto& [count, s] : by_count) {
    picked += s.picked;
    first += s.first_try;
  }
  return picked ? static_cast<double>(first) / picked : 0.0;
}

double Median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  const std::size_t mid = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + mid, values.end());
  if (values.size() % 2 == 1) return values[mid];
  const double upper = values[mid];
  const double lower = *std::max_element(values.begin(), values.begin() + mid);
  return 0.5 * (lower + upper);
}

double Mean(const std::vector<double>& values) {
  return values.empty() ? 0.0 : std::accumulate(values.begin(), values.end(), 0.0) / values.size();
}

CellStatistics SummarizeRecords(const std::vector<json>& records) {
  CellStatistics s;
  std::map<std::uint32_t, RoundState> rounds;
  for (const json& r : records) {
    try {
      const std::string type = r.at("type").get<std::string>();
      const std::uint32_t round = r.at("round").get<std::uint32_t>();
      RoundState& state = rounds[round];
      if (type == "end") {
        ++s.rounds;
        const std::string reason = r.at("reason").get<std::string>();
        const bool truth = HasTruth(r.value("truth", json()));
        const bool emptied =
            truth ? r["truth"]["tubes_in_bin"].get<std::uint32_t>() == 0 : reason == "bin_empty";
        if (emptied) ++s.bins_emptied;
        if (truth && reason == "bin_empty" && !emptied) ++s.false_empty;
        s.tubes_unaccounted += r.value("tubes_unaccounted", 0u);
        if (r.value("tubes_expected", 0u) > 0) ++s.counted_rounds;
        if (reason == "limit_reached") ++s.limit_stops;
        if (reason == "fault") ++s.fault_stops;
        if (reason == "stopped") ++s.operator_stops;
        if (HasTruth(r.value("truth_start", json())))
          s.tubes_total += r["truth_start"]["tubes_in_bin"].get<std::uint32_t>();
        continue;
      }
      if (type != "attempt") continue;

      const std::string result = r.at("result").get<std::string>();
      state.planning += Duration(r, "planning_wall_s");
      state.motion += Duration(r, "robot_device_s");
      state.cycle += Duration(r, "attempt_wall_s");
      if (result == "no_plan") {
        ++s.no_plan_scans;
        state.nudge_pending = false;
        continue;
      }
      if (result == "nudge" || r.contains("nudge")) {
        ++s.nudges.uses;
        state.nudge_pending = result == "nudge";
        continue;
      }
      const std::uint32_t n = TubesInBin(r);
      CountStatistics& c = s.by_count[n];
      const bool picked = result == "picked";
      const bool first_at_count = state.counts_attempted.insert(n).second;
      ++s.attempts;
      ++c.attempts;
      if (result == "grasp_failed") ++s.grasp_failures;
      if (result == "lost") ++s.lost_in_transit;

      const std::string kind = r.value("trajectory_kind", "upward");
      const bool escape = kind == "escape" || kind == "occlusion_escape";
      UseCount& by_kind = escape ? s.escape : s.upward;
      ++by_kind.uses;
      if (picked) ++by_kind.successes;
      if (r.value("used_simulation", false)) {
        ++s.simulated_attempts;
        ++(escape ? c.simulated_escape : c.simulated_upward);
        UseCount& sim = escape ? s.simulated_escape : s.simulated_upward;
        ++sim.uses;
        if (picked) ++sim.successes;
      }
      const bool resolved = r.contains("resolution") && r["resolution"].value("used", 0) > 0;
      const bool worked = picked && !resolved;
      const bool simulated = r.value("used_simulation", false);
      // Records before plans carried a certainty: an unsimulated upward plan was a free pick.
      const std::string certainty = r.value("certainty", std::string(simulated ? "simulated"
                                                                     : escape  ? "unsure"
                                                                               : "sure"));
      const auto count = [worked](UseCount& u) {
        ++u.uses;
        if (worked) ++u.successes;
      };
      if (certainty == "sure") count(s.free_pick);
      if (certainty == "unsure") count(s.needed_luck);
      if (escape) count(s.escape_path);
      if (simulated) count(s.simulated_path);
      if (resolved) {
        ++c.resolution;
        ++s.resolution.uses;
        if (r["resolution"].value("succeeded", false)) ++s.resolution.successes;
      }
      if (picked) {
        if (state.nudge_pending) ++s.nudges.successes;
        state.nudge_pending = false;
        ++s.picks;
        ++c.picked;
        if (first_at_count) ++c.first_try;
        s.times.planning.push_back(state.planning);
        s.times.motion.push_back(state.motion);
        s.times.cycle_wall.push_back(state.cycle);
        state.planning = state.motion = state.cycle = 0.0;
      }
      // Ground truth: tubes that left the bin beyond the one placed.
      if (r.contains("truth_after") && HasTruth(r["truth_after"]) && r.contains("truth_before") &&
          HasTruth(r["truth_before"])) {
        const int before = r["truth_before"]["tubes_in_bin"].get<int>();
        const int after = r["truth_after"]["tubes_in_bin"].get<int>();
        const int left = before - after - (picked ? 1 : 0);
        if (left > 0) s.tubes_lost += static_cast<std::uint32_t>(left);
      }
    } catch (const json::exception& e) {
      throw InvalidArgument(fmt::format("cell record {}: {}", r.dump(), e.what()));
    }
  }
  return s;
}

json StatisticsJson(const CellStatistics& s) {
  json by_count = json::array();
  for (const auto& [n, c] : s.by_count)
    by_count.push_back({{"tubes_in_bin", n},
                        {"picked", c.picked},
                        {"first_try", c.first_try},
                        {"first_try_rate", c.picked ? static_cast<double>(c.first_try) / c.picked : 0.0},
                        {"attempts", c.attempts},
                        {"simulated_upward", c.simulated_upward},
                        {"simulated_escape", c.simulated_escape},
                        {"resolution", c.resolution}});
  const auto use = [](const UseCount& u) {
    return json{{"uses", u.uses}, {"successes", u.successes}, {"rate", u.rate()}};
  };
  const auto times = [](const std::vector<double>& v) {
    return json{{"count", v.size()}, {"median_s", Median(v)}, {"mean_s", Mean(v)}};
  };
  return {{"rounds", s.rounds},
          {"bins_emptied", s.bins_emptied},
          {"false_empty", s.false_empty},
          {"tubes_unaccounted", s.tubes_unaccounted},
          {"counted_rounds", s.counted_rounds},
          {"limit_stops", s.limit_stops},
          {"fault_stops", s.fault_stops},
          {"operator_stops", s.operator_stops},
          {"tubes_total", s.tubes_total},
          {"picks", s.picks},
          {"tubes_lost", s.tubes_lost},
          {"attempts", s.attempts},
          {"no_plan_scans", s.no_plan_scans},
          {"grasp_failures", s.grasp_failures},
          {"lost_in_transit", s.lost_in_transit},
          {"first_try_rate", s.FirstTryRate()},
          {"simulated_attempts", s.simulated_attempts},
          {"by_tubes_in_bin", by_count},
          {"simulated_upward", use(s.simulated_upward)},
          {"simulated_escape", use(s.simulated_escape)},
          {"upward", use(s.upward)},
          {"escape", use(s.escape)},
          {"resolution", use(s.resolution)},
          {"paths",
           {{"free_pick", use(s.free_pick)},
            {"needed_luck", use(s.needed_luck)},
            {"escape", use(s.escape_path)},
            {"simulated", use(s.simulated_path)},
            {"resolution", use(s.resolution)}}},
          {"nudges", use(s.nudges)},
          {"time_per_pick",
           {{"planning", times(s.times.planning)},
            {"motion", times(s.times.motion)},
            {"cycle_wall", times(s.times.cycle_wall)}}}};
}

}  // namespace tubepick::cell

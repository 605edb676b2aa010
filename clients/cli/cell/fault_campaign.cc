#include "clients/cli/cell/fault_campaign.h"

#include <fmt/core.h>

namespace tubepick::cli {

void FaultCampaign::Add(const SimRoundResult& round, const FaultInjector* injector) {
  ++rounds;
  if (injector) {
    injected += injector->injected();
    for (const auto& [kind, count] : injector->by_kind()) by_kind[kind] += count;
  }
  const cell::CellRunResult& run = round.run;
  if (run.reason == cell::CellStopReason::kFault) {
    ++safe_stops;
    if (run.safe_stop && run.safe_stop->held != cell::Held::kNothing) {
      ++safe_stops_holding;
      if (run.safe_stop->action == "released_in_bin") ++released_in_bin;
      if (run.safe_stop->action == "kept_closed") ++kept_closed;
      if (run.safe_stop->action == "load_on_tool") ++load_on_tool;
    }
  }
  released_outside += round.tubes_elsewhere;
  carried_out_unnoticed += round.tubes_unnoticed;
  lost_in_transit += run.lost;
  local_analyses += run.local_analyses;
  if (run.reason == cell::CellStopReason::kBinEmpty && round.tubes_in_bin == 0) ++bins_emptied;
  thrown_by_simulation += static_cast<std::uint32_t>(round.runaways.size());
}

std::string FaultCampaign::SummaryLine() const {
  return fmt::format(
      "faults: injected={} safe_stops={} released_outside={} lost_in_transit={} bins_emptied={}/{}{}{}",
      injected, safe_stops, released_outside, lost_in_transit, bins_emptied, rounds,
      carried_out_unnoticed > 0 ? fmt::format(" carried_out_unnoticed={}", carried_out_unnoticed) : "",
      thrown_by_simulation > 0 ? fmt::format(" thrown_by_simulation={}", thrown_by_simulation) : "");
}

std::string FaultCampaign::KindsLine() const {
  std::string kinds;
  for (const auto& [kind, count] : by_kind)
    kinds += fmt::format("{}{}={}", kinds.empty() ? "" : " ", kind, count);
  return fmt::format(
      "faults by kind: {}; safe stops holding a tube: {} (released in the bin {}, kept closed {}, "
      "load still on the tool {}); local analyses: {}",
      kinds.empty() ? "none" : kinds, safe_stops_holding, released_in_bin, kept_closed, load_on_tool,
      local_analyses);
}

nlohmann::json FaultCampaign::Json(double rate, std::uint64_t seed) const {
  return {{"rate", rate},
          {"seed", seed},
          {"rounds", rounds},
          {"injected", injected},
          {"by_kind", by_kind},
          {"safe_stops", safe_stops},
          {"safe_stops_holding", safe_stops_holding},
          {"released_in_bin", released_in_bin},
          {"kept_closed", kept_closed},
          {"load_on_tool", load_on_tool},
          {"released_outside", released_outside},
          {"carried_out_unnoticed", carried_out_unnoticed},
          {"lost_in_transit", lost_in_transit},
          {"local_analyses", local_analyses},
          {"bins_emptied", bins_emptied},
          {"thrown_by_simulation", thrown_by_simulation}};
}

}  // namespace tubepick::cli

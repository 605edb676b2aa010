#pragma once

#include <cstdint>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "clients/cli/cell/fault_injector.h"
#include "clients/cli/cell/sim_round.h"

namespace tubepick::cli {

/// The totals of a fault campaign (`tubepick cell --sim --inject-faults RATE`) over its rounds.
struct FaultCampaign {
  std::uint32_t rounds = 0;
  std::uint32_t injected = 0;
  std::map<std::string, std::uint32_t> by_kind;
  /// Rounds that ended in a safe stop, and how the safe stops left what the gripper held.
  std::uint32_t safe_stops = 0;
  std::uint32_t safe_stops_holding = 0;
  std::uint32_t released_in_bin = 0;
  std::uint32_t kept_closed = 0;
  /// Opened over the bin, but what was caught on the tool still hung there (the arm stayed in the bin).
  std::uint32_t load_on_tool = 0;
  /// Tubes at rest anywhere but the bin, the place zone or the gripper (the world's truth).
  std::uint32_t released_outside = 0;
  /// Tubes that reached the place zone beyond the picks (SimRoundResult::tubes_unnoticed).
  std::uint32_t carried_out_unnoticed = 0;
  /// Tubes the controller recorded as lost between grasp and place.
  std::uint32_t lost_in_transit = 0;
  /// AnalyzeWrench answered by the local fallback.
  std::uint32_t local_analyses = 0;
  /// Rounds that ended with the bin reported empty and no tube left in it.
  std::uint32_t bins_emptied = 0;
  /// Tubes the simulation threw (SimRoundResult::runaways): released_outside may count them, but
  /// where they went is the simulator's doing, not a fault path's.
  std::uint32_t thrown_by_simulation = 0;

  /// Adds one round (`injector` null: no faults were injected in it).
  void Add(const SimRoundResult& round, const FaultInjector* injector);
  /// "faults: injected=I safe_stops=S released_outside=R lost_in_transit=L bins_emptied=E/N"
  /// (and " carried_out_unnoticed=U", " thrown_by_simulation=T" when they are not 0).
  std::string SummaryLine() const;
  /// "faults by kind: robot_alarm=…, slip=…; safe stops holding a tube: …".
  std::string KindsLine() const;
  nlohmann::json Json(double rate, std::uint64_t seed) const;
};

}  // namespace tubepick::cli

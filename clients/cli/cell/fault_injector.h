#pragma once

#include <cstdint>
#include <map>
#include <random>
#include <string>

#include "clients/cell/cell_controller.h"
#include "clients/cli/cell/planner_outage.h"
#include "devices/sim/sim_cell.h"

namespace tubepick::cli {

/// Makes the simulated cell's devices (and the planner, through `planner_outage`) fail at random
/// moments of the controller's state machine: on every state the controller enters, with
/// probability `rate`, one fault that fits the state, drawn uniformly:
///   scan: scanner timeout, empty scan · plan: planner restart, planner outage · approach, home,
///   release, nudge: robot alarm · return_to_bin: robot alarm, snag · grasp: robot alarm, gripper
///   fault · reference: F/T timeout, F/T spike, F/T lost · lift: robot alarm, gripper fault, slip ·
///   analyze: F/T timeout, F/T spike, F/T lost, planner restart, planner outage, slip · resolve:
///   robot alarm, F/T spike, slip · place: robot alarm, gripper fault, F/T timeout, F/T lost, slip,
///   snag.
/// Robot alarms and slips happen after a random 0-2 s of further robot motion (a slip falls in the
/// Bullet world wherever the gripper is then); a slip is only drawn while a tube is held. A snag
/// (SimCell::ArmSnag) keeps the held tube on the tool when the gripper next opens (on the place
/// pose, or putting several back into the bin), until it opens again; drawn only while holding. Robot
/// alarms and gripper faults stay until the round ends, and so does "F/T lost" (every reading times
/// out: an unplugged cable); timeouts, spikes and empty scans hit one call. A planner restart kills
/// the server and starts it again 0.5-1.5 s later (the client's ~5 s of retries ride it out); a
/// planner outage kills it until the controller enters its next state (the call under way fails
/// after its retries). Both are tied to the controller's steps, not to the wall clock, so the same
/// rate, seed and cell give the same faults on a fast or a slow machine.
class FaultInjector {
 public:
  /// `planner` takes the planner away (null: no planner faults).
  FaultInjector(double rate, std::uint64_t seed, devices::sim::SimCell& sim, RestartableServer* planner);

  /// The controller's state observer.
  void OnState(cell::CellState state);

  /// Faults that took effect: armed ones, except robot alarms, slips and snags that never came due.
  std::uint32_t injected() const;
  /// The same by kind ("robot_alarm", "slip", "gripper_fault", ...).
  std::map<std::string, std::uint32_t> by_kind() const;

 private:
  void Inject(const std::string& kind);

  double rate_;
  std::mt19937_64 rng_;
  devices::sim::SimCell& sim_;
  RestartableServer* planner_;
  /// The planner was killed by a "planner_outage" and comes back at the next state.
  bool planner_down_ = false;
  std::map<std::string, std::uint32_t> armed_;
};

}  // namespace tubepick::cli

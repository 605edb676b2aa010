#include "clients/cli/cell/fault_injector.h"

#include <spdlog/spdlog.h>

#include <vector>

namespace tubepick::cli {
namespace {

using cell::CellState;
using devices::sim::SimDevice;
using devices::sim::SimFault;

/// The faults that can strike while the controller is in `state`.
std::vector<std::string> KindsFor(CellState state, bool holding, bool planner) {
  std::vector<std::string> kinds;
  const auto add = [&](const char* kind) { kinds.emplace_back(kind); };
  switch (state) {
    case CellState::kScan:
      add("scanner_timeout");
      add("empty_scan");
      break;
    case CellState::kPlan:
      if (planner) add("planner_restart");
      if (planner) add("planner_outage");
      break;
    case CellState::kApproach:
    case CellState::kHome:
    case CellState::kRelease:
    case CellState::kNudge:
      add("robot_alarm");
      break;
    case CellState::kReturnToBin:
      add("robot_alarm");
      if (holding) add("snag");
      break;
    case CellState::kGrasp:
      add("robot_alarm");
      add("gripper_fault");
      break;
    case CellState::kReference:
      add("ft_timeout");
      add("ft_spike");
      add("ft_lost");
      break;
    case CellState::kLift:
      add("robot_alarm");
      add("gripper_fault");
      if (holding) add("slip");
      break;
    case CellState::kAnalyze:
      add("ft_timeout");
      add("ft_spike");
      add("ft_lost");
      if (planner) add("planner_restart");
      if (planner) add("planner_outage");
      if (holding) add("slip");
      break;
    case CellState::kResolve:
      add("robot_alarm");
      add("ft_spike");
      if (holding) add("slip");
      break;
    case CellState::kPlace:
      add("robot_alarm");
      add("gripper_fault");
      add("ft_timeout");
      add("ft_lost");
      if (holding) add("slip");
      if (holding) add("snag");
      break;
    case CellState::kStart:
    case CellState::kBias:
    case CellState::kSafeStop:
      break;
  }
  return kinds;
}

}  // namespace

FaultInjector::FaultInjector(double rate, std::uint64_t seed, devices::sim::SimCell& sim,
                             RestartableServer* planner)
    : rate_(rate), rng_(seed), sim_(sim), planner_(planner) {}

void FaultInjector::OnState(CellState state) {
  if (planner_down_) {
    planner_->StartAgain();
    planner_down_ = false;
  }
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  if (unit(rng_) >= rate_) return;
  const std::vector<std::string> kinds = KindsFor(state, !sim_.HeldTubes().empty(), planner_ != nullptr);
  if (kinds.empty()) return;
  std::uniform_int_distribution<std::size_t> pick(0, kinds.size() - 1);
  const std::string& kind = kinds[pick(rng_)];
  spdlog::info("fault injection: {} during {}", kind, cell::ToString(state));
  Inject(kind);
}

void FaultInjector::Inject(const std::string& kind) {
  std::uniform_real_distribution<double> delay(0.0, 2.0);
  ++armed_[kind];
  if (kind == "scanner_timeout") {
    sim_.InjectFaultOnce(SimDevice::kScanner, SimFault::kTimeout);
  } else if (kind == "empty_scan") {
    sim_.InjectEmptyScan();
  } else if (kind == "robot_alarm") {
    sim_.ArmRobotAlarm(delay(rng_));
  } else if (kind == "gripper_fault") {
    sim_.InjectFault(SimDevice::kGripper, SimFault::kFault);
  } else if (kind == "ft_timeout") {
    sim_.InjectFaultOnce(SimDevice::kForceTorque, SimFault::kTimeout);
  } else if (kind == "ft_lost") {
    sim_.InjectFault(SimDevice::kForceTorque, SimFault::kTimeout);
  } else if (kind == "ft_spike") {
    sim_.InjectFtSpike();
  } else if (kind == "slip") {
    sim_.ArmSlip(delay(rng_));
  } else if (kind == "snag") {
    sim_.ArmSnag();
  } else if (kind == "planner_restart") {
    std::uniform_real_distribution<double> down(0.5, 1.5);
    planner_->Restart(down(rng_));
  } else if (kind == "planner_outage") {
    planner_->Kill();
    planner_down_ = true;
  }
}

std::map<std::string, std::uint32_t> FaultInjector::by_kind() const {
  std::map<std::string, std::uint32_t> counts = armed_;
  const devices::sim::SimFaultEvents& events = sim_.fault_events();
  if (counts.count("robot_alarm")) counts["robot_alarm"] = events.robot_alarms;
  if (counts.count("slip")) counts["slip"] = events.slips;
  if (counts.count("snag")) counts["snag"] = events.snags;
  return counts;
}

std::uint32_t FaultInjector::injected() const {
  std::uint32_t total = 0;
  for (const auto& [kind, count] : by_kind()) total += count;
  return total;
}

}  // namespace tubepick::cli

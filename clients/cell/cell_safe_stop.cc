// The safe stop: what the controller does after a fault, knowing what the gripper holds. Nothing:
// stop where the arm is. A tube (or not sure): up, over the bin's middle, down into it and open; if
// the arm cannot move or the gripper cannot open, keep the gripper closed and say where the tube is.

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "clients/cell/attempt_record.h"
#include "clients/cell/cell_controller.h"
#include "clients/cell/cell_controller_internal.h"

namespace tubepick::cell {
namespace {

std::string FormatPosition(const Eigen::Vector3d& p) {
  return fmt::format("({:.3f}, {:.3f}, {:.3f}) m", p.x(), p.y(), p.z());
}

}  // namespace

using detail::kSameHeight;
using detail::WithHeight;

/// Nothing held: stop where the arm is. Holding (or not sure): back over the bin, down into it and
/// open; when the arm or the gripper cannot do that, keep the gripper closed and say where the tube
/// is held. A dry run, or a stop before anything was commanded, moves nothing. Never throws, never
/// opens the gripper outside the bin.
void CellController::SafeStop(const StopCause& cause, CellRunResult& result) {
  stopping_ = true;  // no stop check from here on
  Enter(CellState::kSafeStop);
  if (cause.fault)
    spdlog::error("cell: {}", cause.fault->what());
  else
    spdlog::warn("cell: {} during {}: safe stop", cause.why, cause.state);
  SafeStopOutcome outcome;
  outcome.held = held_;
  std::string note;
  const bool may_move = !dry_run_ && commanded_;
  if (held_ == Held::kNothing || !may_move) {
    outcome.action = "stopped";
    if (dry_run_)
      note = fmt::format("dry run: nothing moved (the gripper holds {})", ToString(held_));
    else if (!commanded_)
      note = "stopped before the cell started: nothing moved";
    else
      note = "nothing held: stopped where it is";
    try {
      outcome.p_Bin_tcp = devices_.robot->CurrentPose(params_.robot_timeout).translation();
      note += fmt::format(" (X_BinTcp at {})", FormatPosition(*outcome.p_Bin_tcp));
    } catch (const std::exception& e) {
      note += fmt::format(" (the robot did not report its pose: {})", e.what());
    }
  } else {
    // A stop the F/T caused (lost, disagreeing, a load on the open tool) does not read it again.
    const bool ft_usable = !(cause.fault && cause.fault->device() == "ft_sensor");
    note = ReturnHeldTubeToBin(outcome, ft_usable);
  }
  result.safe_stop = outcome;
  if (cause.fault) {
    const CellFault& fault = *cause.fault;
    result.reason = CellStopReason::kFault;
    result.fault = fault;
    result.message = fmt::format("SAFE STOP: {} {} during {}: {}; {}", fault.device(), ToString(fault.kind()),
                                 fault.state(), fault.error(), note);
    spdlog::error("cell: {}", result.message);
  } else {
    result.reason = CellStopReason::kStopped;
    result.operator_stop = cause.why;
    result.message = fmt::format("STOPPED: {} during {}; {}", cause.why, cause.state, note);
    spdlog::warn("cell: {}", result.message);
  }
  if (sink_) sink_->Write(SafeStopRecord(round_, result, cause.state));
}

std::optional<std::string> CellController::LoadStillCaught() {
  if (!caught_reference_) return std::nullopt;
  try {
    const std::optional<double> load =
        LoadOnTool(*caught_reference_, devices_.ft_sensor->Read(params_.ft_timeout));
    if (!load) return std::nullopt;
    return fmt::format("{:.2f} N still hang on the tool", *load);
  } catch (const std::exception& e) {
    return fmt::format("the F/T sensor did not answer ({}), so what was caught may still hang on the tool",
                       e.what());
  }
}

Eigen::Isometry3d CellController::SafeReleasePose(const Eigen::Isometry3d& X_BinTcpNow) const {
  // Turn about the vertical so that x_Tcp (along the grasped tube) lies along the bin's longer side,
  // by the smaller of the two turns that do.
  const Eigen::Vector3d x_Tcp = X_BinTcpNow.linear().col(0);
  const Eigen::Vector3d size = cell_.bin.inner_size;
  const double target = size.x() >= size.y() ? 0.0 : M_PI / 2;
  double turn = target - std::atan2(x_Tcp.y(), x_Tcp.x());
  turn = std::remainder(turn, M_PI);  // a tube is symmetric: ±x_Tcp are the same
  Eigen::Isometry3d X_BinTcpRelease = X_BinTcpNow;
  X_BinTcpRelease.linear() = Eigen::AngleAxisd(turn, Eigen::Vector3d::UnitZ()) * X_BinTcpNow.linear();
  X_BinTcpRelease.translation() = Eigen::Vector3d(0.0, 0.0, params_.safe_release_height);
  return X_BinTcpRelease;
}

Eigen::Isometry3d CellController::DescendIntoBin(const Eigen::Isometry3d& X_BinTcpRelease,
                                                 std::string* rest) {
  const Eigen::Isometry3d X_BinTcpAbove = WithHeight(X_BinTcpRelease, TransitHeight(params_, cell_));
  const std::vector<Eigen::Isometry3d> steps =
      DescentSteps(params_.safe_release_step, X_BinTcpAbove, X_BinTcpRelease);
  // No steps, or no reading over the bin to compare with: straight down.
  const std::optional<devices::WrenchReading> over_bin = steps.empty() ? std::nullopt : SafeStopReading(rest);
  // Half a tube's weight: the held tube resting on the heap lightens the load by about its weight
  // (or more, the tool pressing); a swing after a step does not.
  const double contact = 0.5 * TubeWeight();
  if (over_bin) {
    for (const Eigen::Isometry3d& X_BinTcpStep : steps) {
      devices_.robot->MoveTo(X_BinTcpStep, params_.approach_speed, params_.robot_timeout);
      bool pressing = false;
      const std::optional<devices::WrenchReading> now = SafeStopReading(rest, &pressing);
      const double change = now ? (now->force - over_bin->force).norm() : 0.0;
      if (pressing || change > contact) {
        *rest = pressing ? ", where the F/T readings started to disagree (resting on the heap)"
                         : fmt::format(", where it rests on the heap (the load changed by {:.2f} N)", change);
        spdlog::warn("cell: safe stop: the held tube rests on the heap at X_BinTcp z {:.3f} m: opening there",
                     X_BinTcpStep.translation().z());
        return X_BinTcpStep;
      }
      if (!now) break;
    }
  }
  devices_.robot->MoveTo(X_BinTcpRelease, params_.approach_speed, params_.robot_timeout);
  return X_BinTcpRelease;
}

std::optional<devices::WrenchReading> CellController::SafeStopReading(std::string* rest, bool* pressing) {
  try {
    return ReadWrench();
  } catch (const CellFault& fault) {
    if (pressing && detail::ReadingsDisagree(fault)) {
      *pressing = true;  // readings that keep disagreeing below a steady one: pressing on the heap
      return std::nullopt;
    }
    *rest = fmt::format(" (the F/T did not answer on the way down: {}; lowered without it)", fault.error());
  } catch (const std::exception& e) {
    *rest = fmt::format(" (the F/T did not answer on the way down: {}; lowered without it)", e.what());
  }
  spdlog::warn("cell: safe stop:{}", *rest);
  return std::nullopt;
}

std::string CellController::ReturnHeldTubeToBin(SafeStopOutcome& outcome, bool ft_usable) {
  const std::string what = held_ == Held::kTube ? "a tube" : "possibly a tube";
  outcome.action = "kept_closed";
  Eigen::Isometry3d X_BinTcp;
  try {
    X_BinTcp = devices_.robot->CurrentPose(params_.robot_timeout);
  } catch (const std::exception& e) {
    return fmt::format("HOLDING {} at an unknown pose: the robot does not answer ({}); gripper kept closed",
                       what, e.what());
  }
  outcome.p_Bin_tcp = X_BinTcp.translation();
  const double z_transit = TransitHeight(params_, cell_);
  const Eigen::Isometry3d X_BinTcpRelease = SafeReleasePose(X_BinTcp);
  Eigen::Isometry3d X_BinTcpOpen = X_BinTcpRelease;
  std::string rest;
  try {
    if (X_BinTcp.translation().z() < z_transit - kSameHeight)
      devices_.robot->MoveTo(WithHeight(X_BinTcp, z_transit), params_.transit_speed, params_.robot_timeout);
    devices_.robot->MoveTo(WithHeight(X_BinTcpRelease, z_transit), params_.transit_speed,
                           params_.robot_timeout);
    if (ft_usable) {
      X_BinTcpOpen = DescendIntoBin(X_BinTcpRelease, &rest);
    } else {
      devices_.robot->MoveTo(X_BinTcpRelease, params_.approach_speed, params_.robot_timeout);
    }
  } catch (const std::exception& e) {
    try {
      outcome.p_Bin_tcp = devices_.robot->CurrentPose(params_.robot_timeout).translation();
    } catch (const std::exception&) {
    }
    return fmt::format("HOLDING {} at X_BinTcp {}: the robot cannot move ({}); gripper kept closed", what,
                       FormatPosition(*outcome.p_Bin_tcp), e.what());
  }
  outcome.p_Bin_tcp = X_BinTcpOpen.translation();
  try {
    const devices::GripperStatus status = devices_.gripper->Open(params_.gripper_timeout);
    if (status.fault != 0)
      return fmt::format(
          "HOLDING {} over the bin at X_BinTcp {}: the gripper cannot open (fault 0x{:02X}: {})", what,
          FormatPosition(*outcome.p_Bin_tcp), status.fault, status.fault_text);
  } catch (const std::exception& e) {
    return fmt::format("HOLDING {} over the bin at X_BinTcp {}: the gripper cannot open ({})", what,
                       FormatPosition(*outcome.p_Bin_tcp), e.what());
  }
  if (const std::optional<std::string> caught = LoadStillCaught()) {
    outcome.action = "load_on_tool";
    return fmt::format(
        "opened over the bin at X_BinTcp {}, but {}: the arm stays there, inside the bin; take "
        "it off by hand",
        FormatPosition(*outcome.p_Bin_tcp), *caught);
  }
  held_ = Held::kNothing;
  outcome.action = "released_in_bin";
  std::string note = fmt::format("{} released into the bin at X_BinTcp {}{}", what,
                                 FormatPosition(*outcome.p_Bin_tcp), rest);
  try {
    devices_.robot->MoveTo(WithHeight(X_BinTcpRelease, z_transit), params_.transit_speed,
                           params_.robot_timeout);
    outcome.p_Bin_tcp = WithHeight(X_BinTcpRelease, z_transit).translation();
    note += ", robot moved up out of the bin";
  } catch (const std::exception& e) {
    note += fmt::format(", robot could not move up ({})", e.what());
  }
  return note;
}

}  // namespace tubepick::cell

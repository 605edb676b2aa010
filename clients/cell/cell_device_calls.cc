// The controller's device and planner calls: each is timed where an attempt needs it, and its
// failures become a CellFault naming the device and the state.

#include <fmt/core.h>

#include <algorithm>

#include "clients/cell/cell_controller.h"
#include "clients/cell/cell_controller_internal.h"
#include "core/common/errors.h"
#include "wire/proto_convert.h"

namespace tubepick::cell {

using detail::CallDevice;
using detail::CallPlanner;
using detail::Clock;
using detail::kSameHeight;
using detail::SecondsSince;
using detail::WithHeight;

Eigen::Isometry3d detail::PlannerPose(const v1::Pose& pose, const std::string& field, CellState state) {
  try {
    return FromProto(pose, field);
  } catch (const InvalidArgument& e) {
    throw CellFault("planner", FaultKind::kServerError, ToString(state), e.what());
  }
}

devices::Capture CellController::Scan() {
  return CallDevice("scanner", state_, [&] { return devices_.scanner->Scan(params_.scanner_timeout); });
}

template <typename Motion>
void CellController::TimedRobotMotion(Attempt* attempt, const Motion& motion) {
  const Clock::time_point start = Clock::now();
  const double device_start = DeviceNow();
  CallDevice("robot", state_, motion);
  if (attempt) {
    attempt->robot_wall_s += SecondsSince(start);
    attempt->robot_device_s += DeviceNow() - device_start;
  }
}

void CellController::MoveTo(const Eigen::Isometry3d& X_BinTcp, double speed, Attempt* attempt) {
  TimedRobotMotion(attempt, [&] { devices_.robot->MoveTo(X_BinTcp, speed, params_.robot_timeout); });
}

void CellController::MoveThrough(const std::vector<Eigen::Vector3d>& waypoints_Bin, double speed,
                                 Attempt* attempt) {
  TimedRobotMotion(attempt,
                   [&] { devices_.robot->MoveThrough(waypoints_Bin, speed, params_.robot_timeout); });
}

Eigen::Isometry3d CellController::CurrentPose() {
  return CallDevice("robot", state_, [&] { return devices_.robot->CurrentPose(params_.robot_timeout); });
}

void CellController::TransitTo(const Eigen::Isometry3d& X_BinTcp, Attempt* attempt) {
  const Eigen::Isometry3d X_BinTcpNow = CurrentPose();
  const double z_transit =
      std::max({TransitHeight(params_, cell_), X_BinTcpNow.translation().z(), X_BinTcp.translation().z()});
  if (X_BinTcpNow.translation().z() < z_transit - kSameHeight)
    MoveTo(WithHeight(X_BinTcpNow, z_transit), params_.transit_speed, attempt);
  MoveTo(WithHeight(X_BinTcp, z_transit), params_.transit_speed, attempt);
  if (X_BinTcp.translation().z() < z_transit - kSameHeight) MoveTo(X_BinTcp, params_.transit_speed, attempt);
}

devices::GripperStatus CellController::CheckGripper(const devices::GripperStatus& status) {
  if (status.fault != 0)
    throw CellFault("gripper", FaultKind::kDeviceFault, ToString(state_),
                    fmt::format("fault 0x{:02X}: {}", status.fault,
                                status.fault_text.empty() ? "(no description)" : status.fault_text));
  return status;
}

void CellController::OpenGripper() {
  CheckGripper(
      CallDevice("gripper", state_, [&] { return devices_.gripper->Open(params_.gripper_timeout); }));
}

devices::GripperStatus CellController::CloseGripper() {
  return CheckGripper(CallDevice("gripper", state_, [&] {
    return devices_.gripper->Close(params_.gripper_speed, params_.gripper_force, params_.gripper_timeout);
  }));
}

devices::WrenchReading CellController::ReadWrench() {
  for (std::uint32_t i = 0; i < params_.ft_settle_samples; ++i)
    CallDevice("ft_sensor", state_, [&] { return devices_.ft_sensor->Read(params_.ft_timeout); });
  devices::WrenchReading mean;
  for (std::uint32_t i = 0; i < params_.ft_samples; ++i) {
    const devices::WrenchReading r =
        CallDevice("ft_sensor", state_, [&] { return devices_.ft_sensor->Read(params_.ft_timeout); });
    mean.force += r.force;
    mean.torque += r.torque;
    mean.sequence = r.sequence;
  }
  mean.force /= params_.ft_samples;
  mean.torque /= params_.ft_samples;
  return mean;
}

v1::AnalyzeWrenchResponse CellController::Analyze(const devices::WrenchReading& reference,
                                                  const devices::WrenchReading& current,
                                                  const Eigen::Isometry3d& X_BinTcpLift, Attempt& attempt) {
  v1::AnalyzeWrenchRequest request;
  *request.mutable_reference() = ToProto(Wrench{reference.force, reference.torque});
  *request.mutable_current() = ToProto(Wrench{current.force, current.torque});
  request.set_tube_mass(cell_.tube.mass);
  *request.mutable_tcp_pose() = ToProto(X_BinTcpLift);
  request.set_variant(params_.resolution_variant);
  const Clock::time_point start = Clock::now();
  v1::AnalyzeWrenchResponse response =
      CallPlanner(state_, [&] { return planner_.AnalyzeWrench(request, params_.analyze_deadline); });
  attempt.analysis_wall_s += SecondsSince(start);
  if (response.outcome() != v1::HELD_OUTCOME_NONE && response.outcome() != v1::HELD_OUTCOME_SINGLE &&
      response.outcome() != v1::HELD_OUTCOME_MULTIPLE)
    throw CellFault("planner", FaultKind::kServerError, ToString(state_),
                    fmt::format("AnalyzeWrench answered outcome {}", static_cast<int>(response.outcome())));
  return response;
}

}  // namespace tubepick::cell

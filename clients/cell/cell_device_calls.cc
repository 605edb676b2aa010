// The controller's device and planner calls: each is timed where an attempt needs it, and its
// failures become a CellFault naming the device and the state.

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <optional>
#include <string>

#include "clients/cell/cell_controller.h"
#include "clients/cell/cell_controller_internal.h"
#include "clients/cell/local_wrench_analysis.h"
#include "core/common/errors.h"
#include "core/wrench/wrench_params.h"
#include "wire/proto_convert.h"

namespace tubepick::cell {
namespace {

/// Per-axis median of one field of the readings.
Eigen::Vector3d MedianOf(const std::vector<devices::WrenchReading>& readings,
                         Eigen::Vector3d devices::WrenchReading::*field) {
  Eigen::Vector3d median;
  std::vector<double> values(readings.size());
  for (int axis = 0; axis < 3; ++axis) {
    for (std::size_t i = 0; i < readings.size(); ++i) values[i] = (readings[i].*field)[axis];
    std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
    median[axis] = values[values.size() / 2];
  }
  return median;
}

// The mean of the readings within spike_force / spike_torque of their median; nullopt when half of
// them or more lie farther (*dropped: how many lay farther).
std::optional<devices::WrenchReading> MeanWithoutSpikes(const std::vector<devices::WrenchReading>& readings,
                                                        double spike_force, double spike_torque,
                                                        std::size_t* dropped) {
  const Eigen::Vector3d force_median = MedianOf(readings, &devices::WrenchReading::force);
  const Eigen::Vector3d torque_median = MedianOf(readings, &devices::WrenchReading::torque);
  devices::WrenchReading mean;
  std::uint32_t kept = 0;
  for (const devices::WrenchReading& r : readings) {
    if ((r.force - force_median).norm() > spike_force || (r.torque - torque_median).norm() > spike_torque)
      continue;
    mean.force += r.force;
    mean.torque += r.torque;
    mean.sequence = r.sequence;
    ++kept;
  }
  *dropped = readings.size() - kept;
  if (2 * kept <= readings.size()) return std::nullopt;
  mean.force /= kept;
  mean.torque /= kept;
  return mean;
}

// Why readings keep disagreeing: a load far beyond a tube's weight (kPressingTubes of them) is
// the tool or the held tube pressing on something that gives way; a small one, the sensor.
std::string LikelyDisagreementCause(double load, double tube_weight) {
  constexpr double kPressingTubes = 10.0;
  if (load > kPressingTubes * tube_weight) {
    return fmt::format(
        "their median load is {:.1f} N, {:.0f} times a tube's weight: the tool or the held "
        "tube is pressing on something, a pile on the place zone or an obstacle?",
        load, load / tube_weight);
  }
  return fmt::format("their median load is {:.1f} N: a loose cable, a hit tool, a saturated gauge?", load);
}

}  // namespace

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

/// A timed-out or empty scan is tried again (params.scan_retries); an empty bin still returns
/// the bin floor's points, so "no point at all" is a scanner failure, never "bin empty".
devices::Capture CellController::Scan() {
  for (std::uint32_t attempt = 0;; ++attempt) {
    const bool last = attempt >= params_.scan_retries;
    try {
      devices::Capture capture = devices_.scanner->Scan(params_.scanner_timeout);
      if (!capture.points_Sensor.empty()) return capture;
      if (last)
        throw CellFault("scanner", FaultKind::kDeviceFault, ToString(state_),
                        fmt::format("{} scans in a row returned no point (is the projector on, the "
                                    "exposure right, the bin in view?)",
                                    attempt + 1));
      spdlog::warn("cell: scan returned no point; scanning again ({} of {} retries)", attempt + 1,
                   params_.scan_retries);
    } catch (const devices::DeviceTimeout& e) {
      if (last) throw CellFault("scanner", FaultKind::kTimeout, ToString(state_), e.what());
      spdlog::warn("cell: scan timed out ({}); scanning again ({} of {} retries)", e.what(), attempt + 1,
                   params_.scan_retries);
    } catch (const devices::DeviceFault& e) {
      throw CellFault("scanner", FaultKind::kDeviceFault, ToString(state_), e.what());
    }
  }
}

template <typename Motion>
void CellController::TimedRobotMotion(Attempt* attempt, const Motion& motion) {
  CheckStop();  // between motions: an operator stop does not wait for the next state
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

void CellController::HoldStill(double seconds, Attempt* attempt) {
  TimedRobotMotion(attempt, [&] { devices_.robot->Hold(seconds, params_.robot_timeout); });
}

Eigen::Isometry3d CellController::CurrentPose() {
  return CallDevice("robot", state_, [&] { return devices_.robot->CurrentPose(params_.robot_timeout); });
}

std::vector<Eigen::Isometry3d> CellController::TransitSegments(const Eigen::Isometry3d& X_BinTcpFrom,
                                                               const Eigen::Isometry3d& X_BinTcpTo) const {
  const double z_transit =
      std::max({TransitHeight(params_, cell_), X_BinTcpFrom.translation().z(), X_BinTcpTo.translation().z()});
  std::vector<Eigen::Isometry3d> segments;
  if (X_BinTcpFrom.translation().z() < z_transit - kSameHeight)
    segments.push_back(WithHeight(X_BinTcpFrom, z_transit));
  segments.push_back(WithHeight(X_BinTcpTo, z_transit));
  if (X_BinTcpTo.translation().z() < z_transit - kSameHeight) segments.push_back(X_BinTcpTo);
  return segments;
}

void CellController::TransitTo(const Eigen::Isometry3d& X_BinTcp, Attempt* attempt,
                               const std::function<void()>& after_each) {
  for (const Eigen::Isometry3d& X_BinTcpTo : TransitSegments(CurrentPose(), X_BinTcp)) {
    MoveTo(X_BinTcpTo, params_.transit_speed, attempt);
    if (after_each) after_each();
  }
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
  held_ = Held::kNothing;
}

devices::GripperStatus CellController::CloseGripper() {
  return CheckGripper(CallDevice("gripper", state_, [&] {
    return devices_.gripper->Close(params_.gripper_speed, params_.gripper_force, params_.gripper_timeout);
  }));
}

devices::WrenchReading CellController::ReadOneWrench() {
  for (std::uint32_t attempt = 0;; ++attempt) {
    try {
      return CallDevice("ft_sensor", state_, [&] { return devices_.ft_sensor->Read(params_.ft_timeout); });
    } catch (const CellFault& fault) {
      if (fault.kind() != FaultKind::kTimeout || attempt >= params_.ft_read_retries) throw;
      spdlog::warn("cell: F/T reading timed out ({}); reading again", fault.error());
    }
  }
}

devices::WrenchReading CellController::ReadWrench() {
  for (std::uint32_t measurement = 0;; ++measurement) {
    for (std::uint32_t i = 0; i < params_.ft_settle_samples; ++i) ReadOneWrench();
    std::vector<devices::WrenchReading> readings;
    for (std::uint32_t i = 0; i < params_.ft_samples; ++i) readings.push_back(ReadOneWrench());
    std::size_t dropped = 0;
    if (const std::optional<devices::WrenchReading> mean =
            MeanWithoutSpikes(readings, params_.ft_spike_force, params_.ft_spike_torque, &dropped)) {
      if (dropped > 0) spdlog::warn("cell: {} F/T spike(s) dropped of {} readings", dropped, readings.size());
      return *mean;
    }
    const std::string disagreement =
        fmt::format("{} of {} readings are more than {} N / {} N*m off their median", dropped,
                    readings.size(), params_.ft_spike_force, params_.ft_spike_torque);
    if (measurement >= params_.ft_unsettled_retries) {
      const double load = MedianOf(readings, &devices::WrenchReading::force).norm();
      throw CellFault("ft_sensor", FaultKind::kDeviceFault, ToString(state_),
                      fmt::format("{}, in each of {} measurements ({})", disagreement, measurement + 1,
                                  LikelyDisagreementCause(load, cell_.tube.mass * WrenchParams{}.gravity)));
    }
    spdlog::warn("cell: {} (the payload still swinging?); settling and measuring again", disagreement);
  }
}

v1::AnalyzeWrenchRequest CellController::WrenchRequest(const devices::WrenchReading& reference,
                                                       const devices::WrenchReading& current,
                                                       const Eigen::Isometry3d& X_BinTcp) const {
  v1::AnalyzeWrenchRequest request;
  *request.mutable_reference() = ToProto(devices::AsWrench(reference));
  *request.mutable_current() = ToProto(devices::AsWrench(current));
  request.set_tube_mass(cell_.tube.mass);
  *request.mutable_tcp_pose() = ToProto(X_BinTcp);
  request.set_variant(params_.resolution_variant);
  return request;
}

v1::AnalyzeWrenchResponse CellController::Analyze(const devices::WrenchReading& reference,
                                                  const devices::WrenchReading& current,
                                                  const Eigen::Isometry3d& X_BinTcpLift, Attempt& attempt) {
  const v1::AnalyzeWrenchRequest request = WrenchRequest(reference, current, X_BinTcpLift);
  const Clock::time_point start = Clock::now();
  v1::AnalyzeWrenchResponse response;
  try {
    response = CallPlanner(state_, [&] { return planner_.AnalyzeWrench(request, params_.analyze_deadline); });
  } catch (const CellFault& fault) {
    if (fault.kind() != FaultKind::kServerUnavailable) throw;
    // A tube is held: the analysis runs here rather than ending the run with the tube in the air.
    spdlog::warn("cell: AnalyzeWrench unavailable ({}); analysing locally", fault.error());
    response = LocalAnalyzeWrench(request, params_.profile);
    nlohmann::json& fallback = attempt.record["analysis_fallback"];
    fallback["local_analyses"] = ++attempt.local_analyses;
    fallback["planner_error"] = fault.error();
  }
  attempt.analysis_wall_s += SecondsSince(start);
  if (response.outcome() != v1::HELD_OUTCOME_NONE && response.outcome() != v1::HELD_OUTCOME_SINGLE &&
      response.outcome() != v1::HELD_OUTCOME_MULTIPLE)
    throw CellFault("planner", FaultKind::kServerError, ToString(state_),
                    fmt::format("AnalyzeWrench answered outcome {}", static_cast<int>(response.outcome())));
  return response;
}

}  // namespace tubepick::cell

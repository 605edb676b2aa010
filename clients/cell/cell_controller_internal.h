#pragma once

#include <spdlog/spdlog.h>

// What the controller's source files share (cell_controller.cc, cell_attempt.cc,
// cell_device_calls.cc): the state of a run, a scan and an attempt, and the device and planner call
// wrappers that turn failures into CellFault. Not for use outside the controller.

#include <chrono>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "clients/cell/cell_controller.h"

namespace tubepick::cell {

namespace detail {

using Clock = std::chrono::steady_clock;

inline double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Runs a device call; its DeviceTimeout / DeviceFault become a CellFault naming the device.
template <typename F>
auto CallDevice(const char* device, CellState state, F&& call) -> decltype(call()) {
  try {
    return call();
  } catch (const devices::DeviceTimeout& e) {
    throw CellFault(device, FaultKind::kTimeout, ToString(state), e.what());
  } catch (const devices::DeviceFault& e) {
    throw CellFault(device, FaultKind::kDeviceFault, ToString(state), e.what());
  }
}

/// Runs a planner call; a PlannerError becomes a CellFault.
template <typename F>
auto CallPlanner(CellState state, F&& call) -> decltype(call()) {
  try {
    return call();
  } catch (const PlannerError& e) {
    const bool unavailable = e.code() == grpc::StatusCode::UNAVAILABLE ||
                             e.code() == grpc::StatusCode::RESOURCE_EXHAUSTED ||
                             e.code() == grpc::StatusCode::DEADLINE_EXCEEDED;
    throw CellFault("planner", unavailable ? FaultKind::kServerUnavailable : FaultKind::kServerError,
                    ToString(state), e.what());
  }
}

/// A pose the planner sent, bin frame; an unusable one is a planner fault in `state`.
Eigen::Isometry3d PlannerPose(const v1::Pose& pose, const std::string& field, CellState state);

/// `X` moved vertically to height `z` (bin frame).
inline Eigen::Isometry3d WithHeight(Eigen::Isometry3d X, double z) {
  X.translation().z() = z;
  return X;
}

constexpr double kSameHeight = 1e-4;  // m: moves shorter than this are skipped

/// The "no_plan" record's cell_mismatch: every one of `plans` skipped as not fitting the cell.
std::string CellMismatchMessage(std::uint32_t plans, const std::string& first_reason);

/// An F/T measurement whose readings kept disagreeing (ReadWrench's ft_sensor device_fault): the
/// held tube pressing on something, where the place and the safe stop expect it to.
inline bool ReadingsDisagree(const CellFault& fault) {
  return fault.device() == "ft_sensor" && fault.kind() == FaultKind::kDeviceFault;
}

}  // namespace detail

/// One picking attempt (or nudge) under way: its record and its running durations.
struct CellController::Attempt {
  nlohmann::json record;
  double robot_wall_s = 0.0;
  double robot_device_s = 0.0;
  double analysis_wall_s = 0.0;
  /// AnalyzeWrench calls the local fallback answered.
  std::uint32_t local_analyses = 0;
  detail::Clock::time_point started = detail::Clock::now();
  double device_started = 0.0;
  std::optional<AttemptResult> result;
  /// The grasp point once the plan's poses are known (failed_grasp_radius remembers it).
  std::optional<Eigen::Vector3d> p_Bin_grasp;
};

/// The held tube is gone (a slip, a drop): where it was noticed and by what.
struct CellController::TubeLost : std::runtime_error {
  TubeLost(std::string state_in, std::string detected_by_in, const std::string& detail)
      : std::runtime_error(detail), state(std::move(state_in)), detected_by(std::move(detected_by_in)) {}
  std::string state;
  std::string detected_by;  ///< "gripper_status" or "wrench"
};

/// Thrown at a state or before a robot motion once RequestStop was called (not a std::exception:
/// no catch of device errors on the way swallows it).
struct CellController::StopRequested {
  std::string why;
  std::string state;
};

/// Why a run ends in the safe stop: a fault (device, planner, internal) or the operator.
struct CellController::StopCause {
  std::optional<CellFault> fault;
  /// The operator's reason (RequestStop) and the state the stop was noticed in, when no fault.
  std::string why;
  std::string state;
};

/// One run (one bin): its result so far, the counters the attempt limits look at and the attempt
/// under way (recorded as "fault" when a fault stops the run).
struct CellController::RunState {
  CellRunResult result;
  std::uint32_t attempts_since_pick = 0;
  std::uint32_t consecutive_failures = 0;
  std::uint32_t nudges_since_pick = 0;
  /// What each attempt or scan without a plan since the last pick came to ("multiple 2.02 tubes": the
  /// lift's outcome and tubes of tube.mass; "grasp_failed"; "no plan, nudged tube 3"), for the message
  /// of a limit.
  std::vector<std::string> since_pick;
  /// Grasps that closed on nothing or lifted nothing since tubes last moved (a pick, a put-back, a
  /// lost tube, a nudge): failed_grasp_radius.
  struct FailedGrasp {
    Eigen::Vector3d p_Bin_grasp = Eigen::Vector3d::Zero();
    std::uint32_t attempt = 0;
    std::string result;
  };
  std::vector<FailedGrasp> failed_grasps;
  /// Nudges since tubes last moved otherwise (a pick, a put-back, a lost tube): nudge.repeat_radius.
  struct NudgeDone {
    Eigen::Vector3d p_Bin_contact = Eigen::Vector3d::Zero();
    double wall_distance = 0.0;
    std::uint32_t scan = 0;
  };
  std::vector<NudgeDone> nudges_done;
  std::optional<Attempt> active;
  /// The last scan's tubes hanging over a wall, and the tubes attempted or nudged since.
  std::vector<TubeOverWall> over_walls;
  std::vector<std::uint32_t> touched;
  /// An attempt since that scan lifted several tubes (which ones is not known).
  bool lifted_several = false;
};

template <typename Body>
std::optional<CellController::StopCause> CellController::Guarded(Body&& body) {
  try {
    try {
      body();
      return std::nullopt;
    } catch (const CellFault&) {
      throw;
    } catch (const StopRequested&) {
      throw;
    } catch (const std::exception& e) {
      throw CellFault("controller", FaultKind::kInternal, ToString(state_), e.what());
    }
  } catch (const CellFault& fault) {
    // The planner call the stop cancelled (CancelCalls) ends in a planner fault: it is the stop.
    if (fault.device() == "planner" && stop_requested()) {
      std::lock_guard<std::mutex> lock(stop_mutex_);
      stopping_ = true;
      spdlog::warn("cell: {} during {} (the planner call was cancelled)", stop_why_, fault.state());
      return StopCause{std::nullopt, stop_why_, fault.state()};
    }
    return StopCause{fault, "", fault.state()};
  } catch (const StopRequested& stop) {
    return StopCause{std::nullopt, stop.why, stop.state};
  }
}

/// One scan and the planner's answer to it; its time counts towards the scan's first attempt.
struct CellController::PlannedScan {
  std::uint32_t index = 0;  ///< scans before this one in the run
  nlohmann::json truth_before;
  detail::Clock::time_point started;
  double device_started = 0.0;
  v1::PlanPickResponse response;
  double planning_wall_s = 0.0;
  /// Plans skipped since the last attempt (rank, tube, check, reason), for the next record.
  nlohmann::json skipped = nlohmann::json::array();
  /// Plans of this scan skipped because they do not fit this controller's cell, and the first reason.
  std::uint32_t cell_mismatches = 0;
  std::string first_cell_mismatch;
  /// Tubes over a wall the scan before showed and this one does not (Describe), for the next record.
  std::vector<std::string> vanished_over_walls;
};

/// The TCP poses of one plan, bin frame.
struct CellController::PlanPoses {
  Eigen::Isometry3d X_BinTcpGrasp = Eigen::Isometry3d::Identity();
  /// X_BinTcpGrasp backed off params.approach_height against the approach direction.
  Eigen::Isometry3d X_BinTcpPreGrasp = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d X_BinTcpPlace = Eigen::Isometry3d::Identity();
  /// Unit approach direction, bin axes (the TCP's z axis when the plan gives none).
  Eigen::Vector3d approach_Bin = Eigen::Vector3d::UnitZ();
  /// The lift: TCP translations from the grasp pose, bin axes (the first is (0, 0, 0)).
  std::vector<Eigen::Vector3d> waypoints_Bin;
};

}  // namespace tubepick::cell

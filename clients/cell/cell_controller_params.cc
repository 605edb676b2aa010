#include "clients/cell/cell_controller_params.h"

#include <fmt/core.h>

#include <cmath>
#include <string>

#include "core/common/errors.h"

namespace tubepick::cell {
namespace {

void RequirePositiveValue(double value, const char* field) {
  if (!std::isfinite(value) || value <= 0.0)
    throw InvalidArgument(fmt::format("cell controller {}: must be a positive number, got {}", field, value));
}

void RequireNonNegativeValue(double value, const char* field) {
  if (!std::isfinite(value) || value < 0.0)
    throw InvalidArgument(
        fmt::format("cell controller {}: must be a non-negative number, got {}", field, value));
}

void RequirePositiveCount(std::uint64_t value, const char* field) {
  if (value == 0) throw InvalidArgument(fmt::format("cell controller {}: must be at least 1, got 0", field));
}

/// Durations are seconds in the YAML (cell_controller_config.h), so the message says seconds.
void RequirePositiveDuration(std::chrono::milliseconds value, const char* field) {
  if (value.count() <= 0)
    throw InvalidArgument(fmt::format("cell controller {}: must be positive (at least 0.001 s), got {} s",
                                      field, static_cast<double>(value.count()) / 1000.0));
}

void RequireVector(const Eigen::Vector3d& v, bool positive, const char* field) {
  for (int k = 0; k < 3; ++k) {
    const std::string name = fmt::format("{}[{}]", field, k);
    if (positive)
      RequirePositiveValue(v[k], name.c_str());
    else
      RequireNonNegativeValue(v[k], name.c_str());
  }
}

}  // namespace

void CellControllerParams::Validate() const {
  RequirePositiveValue(transit_speed, "transit_speed");
  RequirePositiveValue(approach_speed, "approach_speed");
  RequirePositiveValue(lift_speed, "lift_speed");
  RequirePositiveValue(resolution_speed, "resolution_speed");
  RequireNonNegativeValue(resolution_wall_margin, "resolution_wall_margin");
  RequireNonNegativeValue(resolution_dwell, "resolution_dwell");
  if (resolution_extra_motions > kMaxResolutionExtraMotions)
    throw InvalidArgument(
        fmt::format("cell controller resolution_extra_motions: {} is more than {} (each is a turn, a pause "
                    "and a reading)",
                    resolution_extra_motions, kMaxResolutionExtraMotions));
  if (resolution_rest_load != 0.0 &&
      !(resolution_rest_load > 1.0 && resolution_rest_load <= kMaxResolutionRestLoad))
    throw InvalidArgument(
        fmt::format("cell controller resolution_rest_load: {} tube weights; 0 (turn at the hold pose) or "
                    "more than 1 (the grasped tube alone weighs one) and at most {}",
                    resolution_rest_load, kMaxResolutionRestLoad));
  RequireNonNegativeValue(approach_height, "approach_height");
  RequireNonNegativeValue(transit_clearance, "transit_clearance");
  RequireNonNegativeValue(release_height, "release_height");
  RequireNonNegativeValue(put_back_margin, "put_back_margin");
  RequireNonNegativeValue(put_back_step, "put_back_step");
  RequireNonNegativeValue(place_approach_height, "place_approach_height");
  RequireNonNegativeValue(place_recheck_height, "place_recheck_height");
  RequireNonNegativeValue(place_step, "place_step");
  if (!std::isfinite(place_surface_height))
    throw InvalidArgument(
        fmt::format("cell controller place_surface_height: must be finite, got {}", place_surface_height));
  RequireNonNegativeValue(safe_release_step, "safe_release_step");
  RequirePositiveValue(safe_release_height, "safe_release_height");
  if (X_BinHome && !X_BinHome->matrix().allFinite())
    throw InvalidArgument("cell controller home_pose_in_bin (X_BinHome): not finite");
  // The same ranges as the planner's planning.tool (PlanningParams::Validate).
  RequireVector(tool.finger_size, true, "tool.finger_size");
  RequireVector(tool.housing_size, false, "tool.housing_size");
  if (!std::isfinite(tool.finger_tip_depth))
    throw InvalidArgument(
        fmt::format("cell controller tool.finger_tip_depth: must be finite, got {}", tool.finger_tip_depth));
  RequireNonNegativeValue(tool.housing_gap, "tool.housing_gap");
  RequireNonNegativeValue(tool.margin, "tool.margin");
  RequireNonNegativeValue(nudge.near_wall_distance, "nudge.near_wall_distance");
  RequireNonNegativeValue(nudge.target_wall_distance, "nudge.target_wall_distance");
  RequireNonNegativeValue(nudge.push_gain, "nudge.push_gain");
  RequireNonNegativeValue(nudge.min_push, "nudge.min_push");
  RequirePositiveValue(nudge.max_push, "nudge.max_push");
  if (nudge.min_push > nudge.max_push)
    throw InvalidArgument(fmt::format("cell controller nudge.min_push: {} exceeds nudge.max_push {}",
                                      nudge.min_push, nudge.max_push));
  RequireNonNegativeValue(nudge.press_depth, "nudge.press_depth");
  RequireNonNegativeValue(nudge.tube_clearance, "nudge.tube_clearance");
  RequireNonNegativeValue(nudge.repeat_radius, "nudge.repeat_radius");
  if (!std::isfinite(nudge.tilt) || nudge.tilt < 0.0 || nudge.tilt >= M_PI / 2)
    throw InvalidArgument(
        fmt::format("cell controller nudge.tilt: must be in [0, pi/2) rad, got {}", nudge.tilt));
  RequirePositiveValue(nudge.speed, "nudge.speed");
  RequirePositiveValue(nudge.sample_spacing, "nudge.sample_spacing");
  cell_check.Validate();
  RequirePositiveValue(gripper_speed, "gripper_speed");
  RequirePositiveValue(gripper_force, "gripper_force");
  RequirePositiveCount(ft_samples, "ft_samples");
  RequirePositiveValue(ft_spike_force, "ft_spike_force");
  RequirePositiveValue(ft_spike_torque, "ft_spike_torque");
  try {
    tube_mass_check.limits.Validate();
    wall_watch.Validate();
  } catch (const InvalidArgument& e) {
    throw InvalidArgument(fmt::format("cell controller {}", e.what()));
  }
  RequirePositiveCount(max_plans_per_scan, "max_plans_per_scan");
  if (!std::isfinite(failed_grasp_radius) || failed_grasp_radius < 0.0)
    throw InvalidArgument(
        fmt::format("cell controller failed_grasp_radius: must be a finite distance >= 0 m (0 = off), got {}",
                    failed_grasp_radius));
  RequirePositiveDuration(plan_deadline, "plan_deadline");
  RequirePositiveDuration(analyze_deadline, "analyze_deadline");
  RequirePositiveCount(max_attempts_per_tube, "max_attempts_per_tube");
  RequirePositiveCount(max_attempts_per_bin, "max_attempts_per_bin");
  RequirePositiveCount(max_consecutive_failures, "max_consecutive_failures");
  RequirePositiveDuration(scanner_timeout, "scanner_timeout");
  RequirePositiveDuration(robot_timeout, "robot_timeout");
  if (resolution_dwell >= std::chrono::duration<double>(robot_timeout).count())
    throw InvalidArgument(
        fmt::format("cell controller resolution_dwell: {} s is not below robot_timeout ({} s): the pause is "
                    "one robot call",
                    resolution_dwell, std::chrono::duration<double>(robot_timeout).count()));
  RequirePositiveDuration(gripper_timeout, "gripper_timeout");
  RequirePositiveDuration(ft_timeout, "ft_timeout");
}

ResolutionMotionSource NextResolutionMotion(const CellControllerParams& params, std::size_t m,
                                            std::size_t planned, bool reading_has_motion) {
  const std::size_t extra = params.resolution_replan && planned > 0 ? params.resolution_extra_motions : 0;
  if (m >= planned + extra) return ResolutionMotionSource::kNone;
  if (params.resolution_replan && reading_has_motion) return ResolutionMotionSource::kReading;
  return m < planned ? ResolutionMotionSource::kPlan : ResolutionMotionSource::kNone;
}

double TransitHeight(const CellControllerParams& params, const CellConfig& cell) {
  return cell.bin.inner_size.z() + params.transit_clearance;
}

std::vector<Eigen::Isometry3d> DescentSteps(double step, const Eigen::Isometry3d& X_BinTcpFrom,
                                            const Eigen::Isometry3d& X_BinTcpTo) {
  const double height = X_BinTcpFrom.translation().z() - X_BinTcpTo.translation().z();
  if (!(step > 0.0) || !(height > step)) return {};
  const int steps = static_cast<int>(std::ceil(height / step - 1e-9));
  std::vector<Eigen::Isometry3d> out;
  for (int k = 1; k < steps; ++k) {
    Eigen::Isometry3d X_BinTcpStep = X_BinTcpTo;
    X_BinTcpStep.translation().z() += height * (1.0 - static_cast<double>(k) / steps);
    out.push_back(X_BinTcpStep);
  }
  return out;
}

Eigen::Isometry3d PlacePoseClearOfTheSurface(const CellControllerParams& params, double tube_radius,
                                             const Eigen::Isometry3d& X_BinTcpPlanned) {
  const double lowest = ToolLowestZ(params.tool, 2.0 * tube_radius, X_BinTcpPlanned);
  const double clear = params.place_surface_height + params.tool.margin;
  Eigen::Isometry3d X_BinTcpPlace = X_BinTcpPlanned;
  if (lowest < clear) X_BinTcpPlace.translation().z() += clear - lowest;
  return X_BinTcpPlace;
}

std::vector<Eigen::Isometry3d> PlaceDescentSteps(const CellControllerParams& params,
                                                 const Eigen::Isometry3d& X_BinTcpFrom,
                                                 const Eigen::Isometry3d& X_BinTcpPlace) {
  return DescentSteps(params.place_step, X_BinTcpFrom, X_BinTcpPlace);
}

Eigen::Isometry3d HomePose(const CellControllerParams& params, const CellConfig& cell) {
  if (params.X_BinHome) return *params.X_BinHome;
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  // TCP z down (approach), x along the bin's x: a half turn about x_Bin.
  X.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Vector3d p_place = cell.place.X_BinPlace.translation();
  X.translation() = Eigen::Vector3d(p_place.x(), p_place.y(), TransitHeight(params, cell));
  return X;
}

}  // namespace tubepick::cell

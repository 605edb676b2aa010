// A plan's poses against the controller's own cell: the bin it grasps in and the place frame it
// places on. How the place check reads a plan: the planner computes X_BinTcpPlace = X_BinPlace ·
// X_BinTube⁻¹ · X_BinTcpGrasp (core/placement PlacementTcpPose), so the place frame a plan implies is
// X_BinTcpPlace · X_BinTcpGrasp⁻¹ · X_BinTube, with X_BinTube the tube frame the planner estimated.
// The controller estimates that frame from the tube's model in the answer.

#include "clients/cell/cell_frame_check.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "core/common/errors.h"
#include "core/placement/placement.h"
#include "wire/proto_convert.h"

namespace tubepick::cell {
namespace {

std::string Position(const Eigen::Vector3d& p) {
  return fmt::format("({:.3f}, {:.3f}, {:.3f}) m", p.x(), p.y(), p.z());
}

/// Positions this far from the bin are not a cell of another size: they are millimetres.
bool LooksLikeMillimetres(const Eigen::Vector3d& p_Bin, const CellConfig& cell) {
  return p_Bin.cwiseAbs().maxCoeff() > 20.0 * cell.bin.inner_size.maxCoeff();
}

std::string MillimetresCause() {
  return "values this large are millimetres read as metres: is the planner's cell, or the cloud's unit, "
         "in mm (sensor.unit, the request's cloud unit)?";
}

/// Why `p_Bin` (the TCP at `what`) is outside the bin, or "". With `above_walls`, it must also lie
/// at most that far above the wall top (plus the margin); without, there is no bound above.
std::string OutsideBin(const Eigen::Vector3d& p_Bin, const std::string& what, const CellConfig& cell,
                       double margin, std::optional<double> above_walls) {
  const Eigen::Vector3d& size = cell.bin.inner_size;
  const double x_max = 0.5 * size.x() + margin, y_max = 0.5 * size.y() + margin;
  const double z_min = -margin, z_max = size.z() + above_walls.value_or(0.0) + margin;
  std::string bound;
  bool too_high = false;
  if (!p_Bin.allFinite())
    bound = "not finite";
  else if (std::abs(p_Bin.x()) > x_max)
    bound = fmt::format("|x| > {:.3f} m", x_max);
  else if (std::abs(p_Bin.y()) > y_max)
    bound = fmt::format("|y| > {:.3f} m", y_max);
  else if (p_Bin.z() < z_min)
    bound = fmt::format("z < {:.3f} m (below the floor)", z_min);
  else if (above_walls && p_Bin.z() > z_max) {
    too_high = true;
    bound = fmt::format("z > {:.3f} m, {:.3f} m above the wall top (cell_check.grasp_above_walls {:.3f} m)",
                        z_max, p_Bin.z() - size.z(), *above_walls);
  }
  if (bound.empty()) return "";
  std::string cause =
      LooksLikeMillimetres(p_Bin, cell)
          ? MillimetresCause()
          : "the planner is likely configured with another bin (cell bin.inner_size) or sensor "
            "pose (sensor.pose_in_bin) than this controller";
  if (too_high && !LooksLikeMillimetres(p_Bin, cell))
    cause +=
        "; or a tube lies that high: leaning on a wall, partly outside the bin, or on a heap above the "
        "walls (clear it by hand; cell_check.grasp_above_walls allows a heap meant to rise above them)";
  return fmt::format(
      "cell check: the {} at {} lies outside this controller's bin (inner {:.3f} x {:.3f} x {:.3f} m, "
      "bin_margin {:.3f} m: {}); {}",
      what, Position(p_Bin), size.x(), size.y(), size.z(), margin, bound, cause);
}

/// The planner's model of a tube as core's Tube (cylinders with a length only).
std::optional<Tube> TubeOf(const v1::Tube& tube_proto, double radius) {
  Tube tube;
  tube.id = tube_proto.id();
  for (const v1::Cylinder& c : tube_proto.cylinders()) {
    Cylinder cylinder;
    cylinder.start = FromProto(c.start());
    cylinder.end = FromProto(c.end());
    cylinder.radius = c.radius() > 0.0 ? c.radius() : radius;
    if (!cylinder.start.allFinite() || !cylinder.end.allFinite() || cylinder.length() < 1e-6) continue;
    tube.cylinders.push_back(cylinder);
  }
  if (tube.cylinders.empty()) return std::nullopt;
  return tube;
}

/// Angle of R, radians in [0, π].
double AngleOf(const Eigen::Matrix3d& R) { return Eigen::AngleAxisd(R).angle(); }

std::string PlaceCause(const Eigen::Vector3d& p_Bin_implied, const CellConfig& cell) {
  if (LooksLikeMillimetres(p_Bin_implied, cell)) return MillimetresCause();
  return "the planner is likely configured with another place frame (cell place.pose_in_bin) than this "
         "controller";
}

std::optional<std::string> PlaceProblem(const CellConfig& cell, const CellFrameCheckParams& params,
                                        const PlanFrameInput& plan) {
  const Eigen::Isometry3d& X_BinPlace = cell.place.X_BinPlace;
  const Eigen::Isometry3d& X_BinTcpPlace = *plan.X_BinTcpPlace;
  const Eigen::Vector3d p_Bin_place = X_BinPlace.translation();
  const Eigen::Vector3d p_Bin_tcp_place = X_BinTcpPlace.translation();
  const std::string place_frame = fmt::format("this controller's place frame at {}", Position(p_Bin_place));
  std::optional<Tube> tube;
  std::optional<TubeFrame> frame;
  if (plan.tube) tube = TubeOf(*plan.tube, cell.tube.radius);
  if (tube) {
    try {
      frame = EstimateTubeFrame(*tube, PlacementParams{});
    } catch (const InvalidArgument&) {
      frame.reset();  // a degenerate model: checked as without one
    }
  }
  // The held tube moves rigidly from the grasp to the place: X_TcpGraspTcpPlace carries the tube
  // frame the planner estimated onto the planner's place frame.
  const Eigen::Isometry3d X_TcpGraspTcpPlace = X_BinTcpPlace * plan.X_BinTcpGrasp.inverse();

  // Position. The planner's tube frame origin is a point of the tube: its points' centroid (the
  // planner's placement.origin default) or the grasp point. The controller knows the tube's model
  // only: the origin lies near the model's principal line, somewhere between its ends. So the place
  // frame the plan implies lies on that stretch of line carried to the place; without a model, the
  // place TCP is at most the tube's length from it.
  if (frame) {
    const Eigen::Vector3d d_Bin = frame->principal_direction_Bin;
    double s_min = 0.0, s_max = 0.0;
    for (const Cylinder& c : tube->cylinders)
      for (const Eigen::Vector3d& p_Bin : {c.start, c.end}) {
        s_min = std::min(s_min, (p_Bin - frame->p_Bin_centroid).dot(d_Bin));
        s_max = std::max(s_max, (p_Bin - frame->p_Bin_centroid).dot(d_Bin));
      }
    const Eigen::Vector3d p_Bin_implied = X_TcpGraspTcpPlace * frame->p_Bin_centroid;
    const Eigen::Vector3d u_Bin = X_TcpGraspTcpPlace.linear() * d_Bin;
    const double s = std::clamp((p_Bin_place - p_Bin_implied).dot(u_Bin), s_min, s_max);
    const Eigen::Vector3d p_Bin_nearest = p_Bin_implied + s * u_Bin;
    const double position_error = (p_Bin_nearest - p_Bin_place).norm();
    if (position_error > params.place_position_tolerance)
      return fmt::format(
          "cell check: the place pose at {} lays the tube with its frame at {} at best, {:.3f} m from {} "
          "(place_position_tolerance {:.3f} m); {}",
          Position(p_Bin_tcp_place), Position(p_Bin_nearest), position_error, place_frame,
          params.place_position_tolerance, PlaceCause(p_Bin_nearest, cell));
  } else {
    const double reach = cell.tube.length > 0.0 ? cell.tube.length : cell.bin.inner_size.head<2>().norm();
    const double distance = (p_Bin_tcp_place - p_Bin_place).norm();
    if (distance > params.place_position_tolerance + reach)
      return fmt::format(
          "cell check: the place pose at {} is {:.3f} m from {} (at most place_position_tolerance {:.3f} m + "
          "{:.3f} m, the tube's length, for any grasp on the tube); {}",
          Position(p_Bin_tcp_place), distance, place_frame, params.place_position_tolerance, reach,
          PlaceCause(p_Bin_tcp_place, cell));
  }
  const Eigen::Isometry3d X_BinPlaceImplied = frame ? X_TcpGraspTcpPlace * frame->X_BinTube : X_BinTcpPlace;

  // Tilt: a yaw-only placement turns the held tube about the vertical only, so the place frame's z
  // seen from the TCP at the place is the bin's z seen from the TCP at the grasp (whatever the yaw).
  const Eigen::Vector3d z_Tcp_place = X_BinTcpPlace.linear().transpose() * X_BinPlace.linear().col(2);
  const Eigen::Vector3d z_Tcp_grasp = plan.X_BinTcpGrasp.linear().transpose() * Eigen::Vector3d::UnitZ();
  const double tilt_error = std::acos(std::clamp(z_Tcp_place.dot(z_Tcp_grasp), -1.0, 1.0));
  if (tilt_error > params.place_rotation_tolerance)
    return fmt::format(
        "cell check: the place pose at {} tilts the tube {:.1f} deg against the z axis of {} "
        "(place_rotation_tolerance {:.1f} deg); {}",
        Position(p_Bin_tcp_place), tilt_error * 180.0 / M_PI, place_frame,
        params.place_rotation_tolerance * 180.0 / M_PI, PlaceCause(p_Bin_place, cell));

  // Yaw, when the model gives the tube a clear direction (a bent tube's principal direction is
  // not one the planner's points would agree on).
  constexpr double kClearDirection = 0.25;  // second eigenvalue / first
  if (frame && frame->eigenvalues[1] < kClearDirection * frame->eigenvalues[0]) {
    const Eigen::Matrix3d R_PlacePlaceImplied = X_BinPlace.linear().transpose() * X_BinPlaceImplied.linear();
    const Eigen::Matrix3d half_turn = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const double rotation_error =
        std::min(AngleOf(R_PlacePlaceImplied), AngleOf(R_PlacePlaceImplied * half_turn));
    if (rotation_error > params.place_rotation_tolerance)
      return fmt::format(
          "cell check: the place pose at {} lays the tube turned {:.1f} deg from {} "
          "(place_rotation_tolerance {:.1f} deg); {}",
          Position(p_Bin_tcp_place), rotation_error * 180.0 / M_PI, place_frame,
          params.place_rotation_tolerance * 180.0 / M_PI, PlaceCause(p_Bin_place, cell));
  }
  return std::nullopt;
}

void RequireNonNegative(double value, const char* field) {
  if (!std::isfinite(value) || value < 0.0)
    throw InvalidArgument(
        fmt::format("cell controller cell_check.{}: must be a non-negative number, got {}", field, value));
}

}  // namespace

void CellFrameCheckParams::Validate() const {
  RequireNonNegative(bin_margin, "bin_margin");
  RequireNonNegative(grasp_above_walls, "grasp_above_walls");
  RequireNonNegative(place_position_tolerance, "place_position_tolerance");
  if (!std::isfinite(place_rotation_tolerance) || place_rotation_tolerance < 0.0 ||
      place_rotation_tolerance > M_PI)
    throw InvalidArgument(fmt::format(
        "cell controller cell_check.place_rotation_tolerance: must be in [0, pi] rad, got {} (degrees?)",
        place_rotation_tolerance));
}

std::optional<std::string> CellFrameProblem(const CellConfig& cell, const CellFrameCheckParams& params,
                                            const PlanFrameInput& plan) {
  if (!params.enabled) return std::nullopt;
  const Eigen::Vector3d p_Bin_grasp = plan.X_BinTcpGrasp.translation();
  std::string problem = OutsideBin(p_Bin_grasp, "grasp", cell, params.bin_margin, params.grasp_above_walls);
  if (problem.empty())
    problem =
        OutsideBin(plan.X_BinTcpPreGrasp.translation(), "pre-grasp", cell, params.bin_margin, std::nullopt);
  for (std::size_t i = 0; problem.empty() && i < plan.waypoints_Bin.size(); ++i)
    problem = OutsideBin(p_Bin_grasp + plan.waypoints_Bin[i], fmt::format("lift waypoint {}", i), cell,
                         params.bin_margin, std::nullopt);
  if (!problem.empty()) return problem;
  if (plan.X_BinTcpPlace) return PlaceProblem(cell, params, plan);
  return std::nullopt;
}

}  // namespace tubepick::cell

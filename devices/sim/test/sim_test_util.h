#pragma once

#include <chrono>
#include <cmath>
#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "core/planning/grasp_synthesis.h"
#include "devices/sim/sim_cell.h"
#include "physics/tube_geometry.h"

namespace tubepick::devices::sim::testing {

inline constexpr double kG = 9.81;
inline constexpr Timeout kLong{std::chrono::seconds(60)};

/// A tube through `points` (bin frame), one edge between consecutive points.
inline physics::TubeGeometry PolylineTube(int id, const std::vector<Eigen::Vector3d>& points, double radius) {
  physics::TubeGeometry tube;
  tube.id = id;
  for (std::size_t i = 0; i < points.size(); ++i)
    tube.nodes.push_back({static_cast<int>(i + 1), points[i], radius});
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    physics::TubeEdge e;
    e.node1 = static_cast<int>(i + 1);
    e.node2 = static_cast<int>(i + 2);
    e.order = static_cast<int>(i + 1);
    e.radius = radius;
    physics::SetEdgeFromNodes(tube, e);
    tube.edges.push_back(e);
  }
  return tube;
}

/// The grasp (core GraspFrame: z down, y across the tube) at arc length `s` along the tube's
/// centreline.
inline Eigen::Isometry3d GraspAt(const physics::TubeGeometry& tube, double s) {
  const std::vector<Eigen::Vector3d> line = tube.Centreline();
  for (std::size_t i = 0; i + 1 < line.size(); ++i) {
    const double length = (line[i + 1] - line[i]).norm();
    if (s <= length || i + 2 == line.size()) {
      const Eigen::Vector3d axis = line[i + 1] - line[i];
      return *GraspFrame(line[i] + std::min(s, length) / length * axis, axis);
    }
    s -= length;
  }
  return Eigen::Isometry3d::Identity();
}

/// The grasp at the middle of the flattest cylinder nearest the tube's middle.
inline Eigen::Isometry3d MiddleGrasp(const physics::TubeGeometry& tube) {
  const std::vector<Eigen::Vector3d> line = tube.Centreline();
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& p : line) centre += p;
  centre /= static_cast<double>(line.size());
  double best = 1e9;
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  for (std::size_t i = 0; i + 1 < line.size(); ++i) {
    const Eigen::Vector3d axis = line[i + 1] - line[i];
    const double incline = std::abs(axis.normalized().z());
    if (axis.norm() < 0.04 || incline > 0.3) continue;
    const Eigen::Vector3d mid = 0.5 * (line[i] + line[i + 1]);
    const double score = (mid - centre).head<2>().norm();
    if (score < best) {
      best = score;
      X = *GraspFrame(mid, axis);
    }
  }
  return X;
}

/// `X` raised by `dz` along the bin's z.
inline Eigen::Isometry3d Raised(Eigen::Isometry3d X, double dz) {
  X.translation().z() += dz;
  return X;
}

/// Servo on, activate, open, approach from 10 cm above and close at `X_BinTcp_grasp`.
inline GripperStatus Grasp(SimCell& cell, const Eigen::Isometry3d& X_BinTcp_grasp, double speed = 0.25) {
  cell.robot().ServoOn(kLong);
  cell.gripper().Activate(kLong);
  cell.gripper().MoveTo(0.045, 0.1, 50.0, kLong);
  cell.robot().MoveTo(Raised(X_BinTcp_grasp, 0.10), speed, kLong);
  cell.robot().MoveTo(X_BinTcp_grasp, 0.05, kLong);
  return cell.gripper().Close(0.05, 50.0, kLong);
}

/// The upward vertical in the TCP (= sensor) axes.
inline Eigen::Vector3d UpTcp(const Eigen::Isometry3d& X_BinTcp) {
  return X_BinTcp.linear().transpose() * Eigen::Vector3d::UnitZ();
}

}  // namespace tubepick::devices::sim::testing

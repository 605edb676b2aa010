#include "core/planning/grasp_synthesis.h"

#include <cmath>

#include "core/common/tube_graph.h"

namespace tubepick {

std::optional<Eigen::Isometry3d> GraspFrame(const Eigen::Vector3d& p_Bin_grasp,
                                            const Eigen::Vector3d& axis_Bin) {
  Eigen::Vector3d x(axis_Bin.x(), axis_Bin.y(), 0.0);
  const double norm = x.norm();
  if (!(norm > 1e-9 * axis_Bin.norm()) || !(norm > 0.0)) return std::nullopt;
  x /= norm;
  if (x.x() < -1e-12 || (std::abs(x.x()) <= 1e-12 && x.y() < 0.0)) x = -x;
  const Eigen::Vector3d z(0.0, 0.0, -1.0);
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d X_BinTcp = Eigen::Isometry3d::Identity();
  X_BinTcp.linear().col(0) = x;
  X_BinTcp.linear().col(1) = y;
  X_BinTcp.linear().col(2) = z;
  X_BinTcp.translation() = p_Bin_grasp;
  return X_BinTcp;
}

Grasp TiltedGrasp(const Grasp& vertical, double tilt) {
  Grasp g = vertical;
  g.X_BinTcp.linear() =
      vertical.X_BinTcp.linear() * Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()).toRotationMatrix();
  g.approach_Bin = g.X_BinTcp.linear().col(2);
  g.tilt = vertical.tilt + tilt;
  return g;
}

std::vector<double> GraspTilts(const GraspParams& params) {
  std::vector<double> tilts;
  if (!(params.max_tilt > 0.0) || !(params.tilt_step > 0.0)) return tilts;
  for (int k = 1; k * params.tilt_step <= params.max_tilt + 1e-9; ++k) {
    tilts.push_back(k * params.tilt_step);
    tilts.push_back(-k * params.tilt_step);
  }
  return tilts;
}

std::vector<double> CylinderCurveOffsets(const Tube& tube) {
  std::vector<double> offsets(tube.cylinders.size(), 0.0);
  const std::vector<TubeNode> nodes = NodesOf(tube);
  for (const TubeBranch& b : BranchesOf(tube)) {
    double s = (tube.cylinders[b.first_cylinder].start - nodes[b.from_node].p_Bin).norm();
    for (std::uint32_t i = b.first_cylinder; i < b.first_cylinder + b.cylinder_count; ++i) {
      if (i > b.first_cylinder) s += (tube.cylinders[i].start - tube.cylinders[i - 1].end).norm();
      offsets[i] = s;
      s += tube.cylinders[i].length();
    }
  }
  return offsets;
}

std::vector<Grasp> SynthesizeGrasps(const Tube& tube, const GraspParams& params) {
  std::vector<Grasp> grasps;
  const std::vector<double> offsets = CylinderCurveOffsets(tube);
  const double max_sin = std::sin(params.max_axis_inclination);
  for (std::size_t i = 0; i < tube.cylinders.size(); ++i) {
    const Cylinder& c = tube.cylinders[i];
    const double length = c.length();
    const double usable = length - 2.0 * params.min_base_distance;
    if (!(length > 0.0) || usable < 0.0) continue;
    const Eigen::Vector3d axis = c.axis();
    if (std::abs(axis.z()) > max_sin + 1e-12) continue;
    const std::optional<Eigen::Isometry3d> frame = GraspFrame(c.start, axis);
    if (!frame) continue;
    const int count = static_cast<int>(std::floor(usable / params.spacing + 1e-9)) + 1;
    const double first = params.min_base_distance + 0.5 * (usable - (count - 1) * params.spacing);
    for (int k = 0; k < count; ++k) {
      const double s = first + k * params.spacing;
      Grasp g;
      g.p_Bin_grasp = c.start + s * axis;
      g.X_BinTcp = *frame;
      g.X_BinTcp.translation() = g.p_Bin_grasp;
      g.opening_width = params.opening_width;
      g.cylinder_index = static_cast<std::uint32_t>(i);
      g.curve_position = offsets[i] + s;
      grasps.push_back(g);
    }
  }
  return grasps;
}

}  // namespace tubepick

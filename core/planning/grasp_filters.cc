#include "core/planning/grasp_filters.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace tubepick {
namespace {

constexpr double kMaxCells = 4.0e6;

}  // namespace

bool OrientedBox::Contains(const Eigen::Vector3d& p_Bin) const {
  const Eigen::Vector3d p_Box = X_BinBox.linear().transpose() * (p_Bin - X_BinBox.translation());
  return std::abs(p_Box.x()) <= half_size.x() && std::abs(p_Box.y()) <= half_size.y() &&
         std::abs(p_Box.z()) <= half_size.z();
}

RawCloudIndex::RawCloudIndex(const Points& points_Bin, double cell_size, double z_min, double z_max)
    : cell_(cell_size) {
  assert(cell_size > 0.0);
  // One pass over the full cloud: keep the band's finite points and their xy bounds; the
  // counting sort then only touches the kept points.
  Points kept;
  kept.reserve(points_Bin.size() / 4);
  float lo_x = std::numeric_limits<float>::infinity(), lo_y = lo_x;
  float hi_x = -lo_x, hi_y = -lo_x;
  for (const Eigen::Vector3f& p : points_Bin) {
    if (!(p.z() >= z_min && p.z() <= z_max) || !p.allFinite()) continue;
    kept.push_back(p);
    lo_x = std::min(lo_x, p.x());
    lo_y = std::min(lo_y, p.y());
    hi_x = std::max(hi_x, p.x());
    hi_y = std::max(hi_y, p.y());
  }
  if (kept.empty()) {
    cell_start_ = {0, 0};
    nx_ = ny_ = 1;
    return;
  }
  origin_ = Eigen::Vector2d(lo_x, lo_y);
  const Eigen::Vector2d extent(double(hi_x) - lo_x, double(hi_y) - lo_y);
  const auto cell_count = [&] {
    return (std::floor(extent.x() / cell_) + 1.0) * (std::floor(extent.y() / cell_) + 1.0);
  };
  while (cell_count() > kMaxCells) cell_ *= 2.0;
  nx_ = static_cast<int>(std::floor(extent.x() / cell_)) + 1;
  ny_ = static_cast<int>(std::floor(extent.y() / cell_)) + 1;

  const std::size_t num_cells = static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_);
  const auto cell_of = [&](const Eigen::Vector3f& p) {
    const int ix = std::min(nx_ - 1, static_cast<int>((p.x() - origin_.x()) / cell_));
    const int iy = std::min(ny_ - 1, static_cast<int>((p.y() - origin_.y()) / cell_));
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(nx_) + static_cast<std::size_t>(ix);
  };
  cell_start_.assign(num_cells + 1, 0);
  for (const Eigen::Vector3f& p : kept) ++cell_start_[cell_of(p) + 1];
  for (std::size_t c = 0; c < num_cells; ++c) cell_start_[c + 1] += cell_start_[c];
  points_.resize(kept.size());
  std::vector<std::uint32_t> cursor(cell_start_.begin(), cell_start_.end() - 1);
  for (const Eigen::Vector3f& p : kept) points_[cursor[cell_of(p)]++] = p;
}

std::size_t RawCloudIndex::CountInBox(const OrientedBox& box, std::size_t limit) const {
  if (points_.empty()) return 0;
  // xy footprint of the box: centre ± |R|·half.
  const Eigen::Vector3d reach = box.X_BinBox.linear().cwiseAbs() * box.half_size;
  const Eigen::Vector3d& c = box.X_BinBox.translation();
  const auto clamp_x = [&](double v) {
    return std::clamp(static_cast<int>(std::floor((v - origin_.x()) / cell_)), 0, nx_ - 1);
  };
  const auto clamp_y = [&](double v) {
    return std::clamp(static_cast<int>(std::floor((v - origin_.y()) / cell_)), 0, ny_ - 1);
  };
  const double x0 = c.x() - reach.x(), x1 = c.x() + reach.x();
  const double y0 = c.y() - reach.y(), y1 = c.y() + reach.y();
  if (x1 < origin_.x() || y1 < origin_.y() || x0 > origin_.x() + nx_ * cell_ ||
      y0 > origin_.y() + ny_ * cell_) {
    return 0;
  }
  const Eigen::Matrix3d R_BoxBin = box.X_BinBox.linear().transpose();
  const double z0 = c.z() - reach.z(), z1 = c.z() + reach.z();
  std::size_t count = 0;
  for (int iy = clamp_y(y0); iy <= clamp_y(y1); ++iy) {
    for (int ix = clamp_x(x0); ix <= clamp_x(x1); ++ix) {
      const std::size_t cell = static_cast<std::size_t>(iy) * nx_ + ix;
      for (std::uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
        const Eigen::Vector3d p = points_[k].cast<double>();
        if (p.z() < z0 || p.z() > z1) continue;
        const Eigen::Vector3d p_Box = R_BoxBin * (p - c);
        if (std::abs(p_Box.x()) <= box.half_size.x() && std::abs(p_Box.y()) <= box.half_size.y() &&
            std::abs(p_Box.z()) <= box.half_size.z()) {
          if (++count > limit) return count;
        }
      }
    }
  }
  return count;
}

std::array<OrientedBox, 2> FingerBoxes(const Grasp& grasp, const GraspFilterParams& params) {
  std::array<OrientedBox, 2> boxes;
  const double offset = 0.5 * (grasp.opening_width + params.finger_thickness);
  const double z = params.finger_tip_depth - 0.5 * params.finger_length;
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector3d p_Tcp_box(0.0, i == 0 ? offset : -offset, z);
    boxes[i].X_BinBox.linear() = grasp.X_BinTcp.linear();
    boxes[i].X_BinBox.translation() = grasp.X_BinTcp * p_Tcp_box;
    boxes[i].half_size =
        0.5 * Eigen::Vector3d(params.finger_width, params.finger_thickness, params.finger_length);
  }
  return boxes;
}

std::pair<double, double> FingerBandZ(const std::vector<Tube>& tubes, const GraspFilterParams& params,
                                      const GraspParams& grasps) {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (const Tube& tube : tubes) {
    for (const Cylinder& c : tube.cylinders) {
      lo = std::min({lo, c.start.z(), c.end.z()});
      hi = std::max({hi, c.start.z(), c.end.z()});
    }
  }
  if (lo > hi) return {0.0, 0.0};
  const double tilt_reach =
      std::sin(std::max(0.0, grasps.max_tilt)) * (0.5 * grasps.opening_width + params.finger_thickness);
  const double bottom = -params.finger_tip_depth - tilt_reach;
  double top = params.finger_length - params.finger_tip_depth;
  if (params.approach_check) top = std::max(top, params.approach_column_height);
  top += tilt_reach;
  // 1 mm slack against rounding at the band's edges.
  return {lo + bottom - 1e-3, hi + top + 1e-3};
}

std::array<OrientedBox, 3> ApproachColumns(const Grasp& grasp, const GraspFilterParams& params,
                                           const ToolParams& tool) {
  // z_Tcp points down: heights above the grasp point are negative z_Tcp.
  auto column = [&](double x, double y, double bottom_height, const Eigen::Vector2d& size_xy) {
    const double height = std::max(0.0, params.approach_column_height - bottom_height);
    OrientedBox box;
    box.X_BinBox.linear() = grasp.X_BinTcp.linear();
    box.X_BinBox.translation() = grasp.X_BinTcp * Eigen::Vector3d(x, y, -(bottom_height + 0.5 * height));
    box.half_size = 0.5 * Eigen::Vector3d(size_xy.x(), size_xy.y(), height);
    return box;
  };
  const double pad_top = params.finger_length - params.finger_tip_depth;
  const double offset = 0.5 * (grasp.opening_width + params.finger_thickness);
  const Eigen::Vector2d pad(params.finger_width, params.finger_thickness);
  const double housing_bottom = tool.finger_size.z() - tool.finger_tip_depth + tool.housing_gap;
  return {column(0.0, offset, pad_top, pad), column(0.0, -offset, pad_top, pad),
          column(0.0, 0.0, housing_bottom, tool.housing_size.head<2>())};
}

bool ApproachBlocked(const Grasp& grasp, const RawCloudIndex& raw, const GraspFilterParams& params,
                     const ToolParams& tool) {
  const std::size_t limit = params.max_points_in_approach;
  std::size_t count = 0;
  for (const OrientedBox& box : ApproachColumns(grasp, params, tool)) {
    count += raw.CountInBox(box, limit - count);
    if (count > limit) return true;
  }
  return false;
}

bool FingersCollide(const Grasp& grasp, const RawCloudIndex& raw, const GraspFilterParams& params) {
  const std::size_t limit = params.max_points_in_fingers;
  const std::array<OrientedBox, 2> boxes = FingerBoxes(grasp, params);
  const std::size_t first = raw.CountInBox(boxes[0], limit);
  if (first > limit) return true;
  return first + raw.CountInBox(boxes[1], limit - first) > limit;
}

bool InsideWorkspace(const Grasp& grasp, const Trajectory& trajectory, const GraspFilterParams& params) {
  const auto inside = [&](const Eigen::Vector3d& p) {
    return (p.array() >= params.workspace_min.array()).all() &&
           (p.array() <= params.workspace_max.array()).all();
  };
  if (!inside(grasp.p_Bin_grasp)) return false;
  for (const Eigen::Vector3d& w : trajectory.waypoints) {
    if (!inside(grasp.p_Bin_grasp + w)) return false;
  }
  return true;
}

bool InAllowedSection(const Grasp& grasp, const Trajectory& trajectory) {
  if (!trajectory.section_mask.empty()) {
    return grasp.cylinder_index < trajectory.section_mask.size() &&
           trajectory.section_mask[grasp.cylinder_index];
  }
  return grasp.cylinder_index >= trajectory.section_begin && grasp.cylinder_index < trajectory.section_end;
}

}  // namespace tubepick

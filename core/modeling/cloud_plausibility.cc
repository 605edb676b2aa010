#include "core/modeling/cloud_plausibility.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "core/common/errors.h"
#include "core/common/require.h"

namespace tubepick {
namespace {

// Points used for the robust extent: every k-th point, at most about this many.
constexpr std::size_t kExtentSample = 100000;

// "2,302,818".
std::string Grouped(std::uint64_t n) {
  std::string digits = std::to_string(n), out;
  for (std::size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

// Value at quantile q of `values` (reorders it).
double Quantile(std::vector<float>& values, double q) {
  const std::size_t k = std::min(values.size() - 1, static_cast<std::size_t>(q * (values.size() - 1) + 0.5));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

// "(0.000, 0.000, 1.100)": millimetre resolution, no "-0.000".
std::string Position(const Eigen::Vector3d& v) {
  auto c = [](double x) { return std::round(x * 1000.0) / 1000.0 + 0.0; };
  return fmt::format("({:.3f}, {:.3f}, {:.3f})", c(v.x()), c(v.y()), c(v.z()));
}

// "(0.00, 0.00, -1.00)".
std::string Direction(const Eigen::Vector3d& v) {
  auto c = [](double x) { return std::round(x * 100.0) / 100.0 + 0.0; };
  return fmt::format("({:.2f}, {:.2f}, {:.2f})", c(v.x()), c(v.y()), c(v.z()));
}

// The scan's walls are not where the cell's bin puts them: both walls of an axis off the same way
// is a shifted sensor pose; off in opposite ways, the bin's size.
std::string DescribeMisfitWalls(const BinWalls& walls, const BinConfig& bin,
                                const PlausibilityParams& params) {
  bool shifted = false;
  int inside = 0, outside = 0;  // walls seen off nearer the centre than the cell's, and farther
  for (int w = 0; w < 4; ++w) {
    if (walls.off[w]) (std::abs(*walls.seen[w]) < std::abs(walls.expected[w]) ? inside : outside) += 1;
  }
  for (int axis = 0; axis < 2; ++axis) {
    const auto& lo = walls.seen[2 * axis];
    const auto& hi = walls.seen[2 * axis + 1];
    if (!lo || !hi) continue;
    const double d_lo = *lo - walls.expected[2 * axis], d_hi = *hi - walls.expected[2 * axis + 1];
    if (std::abs(d_lo - d_hi) <= params.wall_tolerance && std::abs(d_lo + d_hi) > 2.0 * params.wall_tolerance)
      shifted = true;
  }
  const Eigen::Vector3d& s = bin.inner_size;
  return fmt::format(
      "cloud does not fit the cell's bin: {} (more than {:g} m off). {} "
      "(modeling.plausibility.wall_tolerance; "
      "0 turns this check off)",
      DescribeBinWalls(walls), params.wall_tolerance,
      shifted
          ? "The walls are shifted, not resized: is the sensor pose right (sensor.pose_in_bin, X_BinSensor)?"
          : fmt::format("Is bin.inner_size [{:g}, {:g}, {:g}] m the bin's inner size, in metres? {}", s.x(),
                        s.y(), s.z(),
                        inside >= outside
                            ? "Set larger than the bin, the walls would be modeled as tubes"
                            : "Set smaller than the bin, tubes near the walls would be cropped away"));
}

}  // namespace

void PlausibilityParams::Validate() const {
  RequireNonNegative(margin_xy, "modeling.plausibility.margin_xy");
  RequireNonNegative(below_floor, "modeling.plausibility.below_floor");
  RequireNonNegative(above_walls, "modeling.plausibility.above_walls");
  RequireInRange(min_inside_share, 0.0, 1.0, "modeling.plausibility.min_inside_share");
  RequirePositive(floor_tolerance, "modeling.plausibility.floor_tolerance");
  RequireInRange(min_floor_share, 0.0, 1.0, "modeling.plausibility.min_floor_share");
  RequireNonNegative(wall_tolerance, "modeling.plausibility.wall_tolerance");
}

PlausibilityTally::PlausibilityTally(const BinConfig& bin, const PlausibilityParams& params,
                                     std::size_t expected_points)
    : bin_(bin), params_(params) {
  // Bounds in float, the points' precision.
  const double hx = 0.5 * bin.inner_size.x(), hy = 0.5 * bin.inner_size.y();
  volume_x_ = static_cast<float>(hx + params.margin_xy);
  volume_y_ = static_cast<float>(hy + params.margin_xy);
  volume_z_lo_ = static_cast<float>(-params.below_floor);
  volume_z_hi_ = static_cast<float>(bin.inner_size.z() + params.above_walls);
  floor_x_ = static_cast<float>(hx);
  floor_y_ = static_cast<float>(hy);
  floor_tolerance_ = static_cast<float>(params.floor_tolerance);
  stride_ = std::max<std::size_t>(1, expected_points / kExtentSample);
  sample_.reserve(expected_points / stride_ + 1);
}

void PlausibilityTally::Add(const float* x_Bin, const float* y_Bin, const float* z_Bin, std::size_t n) {
  // Branch-free counts in 32 bits over the arrays (vectorised), then the sampled points.
  const float vx = volume_x_, vy = volume_y_, vz_lo = volume_z_lo_, vz_hi = volume_z_hi_;
  const float fx = floor_x_, fy = floor_y_, ft = floor_tolerance_;
  std::uint32_t inside = 0, on_floor = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const float x = std::abs(x_Bin[i]), y = std::abs(y_Bin[i]), z = z_Bin[i];
    inside += static_cast<std::uint32_t>((x <= vx) & (y <= vy) & (z >= vz_lo) & (z <= vz_hi));
    on_floor += static_cast<std::uint32_t>((x <= fx) & (y <= fy) & (std::abs(z) <= ft));
  }
  inside_ += inside;
  on_floor_ += on_floor;
  // Add() samples a point when until_sample_ is 0, then waits stride_ − 1 points.
  std::size_t next = until_sample_;
  for (; next < n; next += stride_) sample_.emplace_back(x_Bin[next], y_Bin[next], z_Bin[next]);
  until_sample_ = next - n;
  points_ += n;
}

CloudPlausibility PlausibilityTally::Finish() const {
  CloudPlausibility e;
  e.points = points_;
  e.inside = inside_;
  e.on_floor = on_floor_;
  if (e.points > 0) e.inside_share = static_cast<double>(e.inside) / static_cast<double>(e.points);
  if (e.inside > 0) e.floor_share = static_cast<double>(e.on_floor) / static_cast<double>(e.inside);
  e.enough_inside = e.points > 0 && e.inside_share >= params_.min_inside_share;
  e.floor_seen =
      e.on_floor > 0 && e.on_floor >= params_.min_floor_points && e.floor_share >= params_.min_floor_share;
  if (!sample_.empty()) {
    std::vector<float> axis(sample_.size());
    for (int d = 0; d < 3; ++d) {
      for (std::size_t i = 0; i < sample_.size(); ++i) axis[i] = sample_[i][d];
      const double lo = Quantile(axis, 0.01), hi = Quantile(axis, 0.99);
      e.extent[d] = hi - lo;
      e.median[d] = Quantile(axis, 0.5);
    }
    const Eigen::Vector3d& s = bin_.inner_size;
    e.extent_ratio = e.extent.maxCoeff() / std::max({s.x(), s.y(), s.z()});
    BinWallParams wall_params;
    wall_params.tolerance = params_.wall_tolerance;
    wall_params.min_points = params_.wall_min_points;
    e.walls = FindBinWalls(sample_, bin_, wall_params);
  }
  return e;
}

CloudPlausibility CheckCloudAgainstCell(const Points& points_Bin, const BinConfig& bin,
                                        const PlausibilityParams& params) {
  PlausibilityTally tally(bin, params, points_Bin.size());
  for (const Eigen::Vector3f& p : points_Bin) tally.Add(p);
  return tally.Finish();
}

std::string DescribeImplausibleCloud(const CloudPlausibility& e, const BinConfig& bin, LengthUnit unit,
                                     const Eigen::Isometry3d& X_BinSensor, const PlausibilityParams& params) {
  const Eigen::Vector3d& s = bin.inner_size;
  if (e.enough_inside && e.floor_seen && !e.walls.fit()) return DescribeMisfitWalls(e.walls, bin, params);
  std::string text = fmt::format(
      "cloud does not fit the cell: {} of {} points ({:.1f} %) fall inside the bin volume "
      "(bin inner size {:g} × {:g} × {:g} m, {:g} m margin; at least {:.0f} % needed) and {} lie on "
      "its floor (|z| <= {:g} m; the floor is {}); in the bin frame the cloud spans "
      "{:.3g} × {:.3g} × {:.3g} m around {} m",
      Grouped(e.inside), Grouped(e.points), 100.0 * e.inside_share, s.x(), s.y(), s.z(), params.margin_xy,
      100.0 * params.min_inside_share, Grouped(e.on_floor), params.floor_tolerance,
      e.floor_seen ? "seen" : "not seen", e.extent.x(), e.extent.y(), e.extent.z(), Position(e.median));
  const std::string declared = ToString(unit);
  if (e.extent_ratio > 100.0 && unit == LengthUnit::kMetre) {
    text += fmt::format(", about {:.0f}× the bin: is the unit mm rather than m (cloud.unit / --unit)?",
                        e.extent_ratio);
  } else if (e.extent_ratio > 0.0 && e.extent_ratio < 0.01 && unit == LengthUnit::kMillimetre) {
    text += fmt::format(", about 1/{:.0f} of the bin: is the unit m rather than mm (cloud.unit / --unit)?",
                        1.0 / e.extent_ratio);
  } else {
    text += fmt::format(
        ": is the sensor pose right (sensor.pose_in_bin, X_BinSensor)? It puts the sensor at {} m looking "
        "along {} in the bin frame (cloud unit {})",
        Position(X_BinSensor.translation()), Direction(X_BinSensor.linear().col(2)), declared);
  }
  return text;
}

void RequirePlausible(const CloudPlausibility& evidence, const BinConfig& bin, LengthUnit unit,
                      const Eigen::Isometry3d& X_BinSensor, const PlausibilityParams& params) {
  if (params.check && !evidence.plausible()) {
    throw FailedPrecondition(DescribeImplausibleCloud(evidence, bin, unit, X_BinSensor, params));
  }
}

}  // namespace tubepick

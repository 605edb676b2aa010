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

}  // namespace

void PlausibilityParams::Validate() const {
  RequireNonNegative(margin_xy, "modeling.plausibility.margin_xy");
  RequireNonNegative(below_floor, "modeling.plausibility.below_floor");
  RequireNonNegative(above_walls, "modeling.plausibility.above_walls");
  RequireInRange(min_inside_share, 0.0, 1.0, "modeling.plausibility.min_inside_share");
  RequirePositive(floor_tolerance, "modeling.plausibility.floor_tolerance");
  RequireInRange(min_floor_share, 0.0, 1.0, "modeling.plausibility.min_floor_share");
}

CloudPlausibility CheckCloudAgainstCell(const Points& points_Bin, const BinConfig& bin,
                                        const PlausibilityParams& params) {
  CloudPlausibility e;
  e.points = points_Bin.size();
  const double hx = 0.5 * bin.inner_size.x(), hy = 0.5 * bin.inner_size.y();
  const double ax = hx + params.margin_xy, ay = hy + params.margin_xy;
  const double z_lo = -params.below_floor, z_hi = bin.inner_size.z() + params.above_walls;
  for (const Eigen::Vector3f& p : points_Bin) {
    const double x = std::abs(p.x()), y = std::abs(p.y()), z = p.z();
    if (x <= ax && y <= ay && z >= z_lo && z <= z_hi) ++e.inside;
    if (x <= hx && y <= hy && std::abs(z) <= params.floor_tolerance) ++e.on_floor;
  }
  if (e.points > 0) e.inside_share = static_cast<double>(e.inside) / static_cast<double>(e.points);
  if (e.inside > 0) e.floor_share = static_cast<double>(e.on_floor) / static_cast<double>(e.inside);
  e.enough_inside = e.points > 0 && e.inside_share >= params.min_inside_share;
  e.floor_seen =
      e.on_floor > 0 && e.on_floor >= params.min_floor_points && e.floor_share >= params.min_floor_share;

  if (e.points > 0) {
    const std::size_t stride = std::max<std::size_t>(1, points_Bin.size() / kExtentSample);
    std::vector<float> axis;
    axis.reserve(points_Bin.size() / stride + 1);
    for (int d = 0; d < 3; ++d) {
      axis.clear();
      for (std::size_t i = 0; i < points_Bin.size(); i += stride) axis.push_back(points_Bin[i][d]);
      const double lo = Quantile(axis, 0.01), hi = Quantile(axis, 0.99);
      e.extent[d] = hi - lo;
      e.median[d] = Quantile(axis, 0.5);
    }
    const double bin_size = std::max({bin.inner_size.x(), bin.inner_size.y(), bin.inner_size.z()});
    e.extent_ratio = e.extent.maxCoeff() / bin_size;
  }
  return e;
}

std::string DescribeImplausibleCloud(const CloudPlausibility& e, const BinConfig& bin, LengthUnit unit,
                                     const Eigen::Isometry3d& X_BinSensor, const PlausibilityParams& params) {
  const Eigen::Vector3d& s = bin.inner_size;
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

CloudPlausibility RequirePlausibleCloud(const Points& points_Bin, const BinConfig& bin, LengthUnit unit,
                                        const Eigen::Isometry3d& X_BinSensor,
                                        const PlausibilityParams& params) {
  CloudPlausibility evidence = CheckCloudAgainstCell(points_Bin, bin, params);
  if (params.check && !evidence.plausible()) {
    throw FailedPrecondition(DescribeImplausibleCloud(evidence, bin, unit, X_BinSensor, params));
  }
  return evidence;
}

}  // namespace tubepick

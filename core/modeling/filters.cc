#include "core/modeling/filters.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>

#include "core/common/errors.h"
#include "core/modeling/filters_internal.h"

namespace tubepick {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
// Deduction guide: clang before 17 does not deduce aggregate template arguments (P1816).
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

std::string Text(double value) {
  std::ostringstream os;
  os << value;
  return os.str();
}

std::string Text(const Eigen::Vector3d& v) {
  std::ostringstream os;
  os << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return os.str();
}

/// Throws "<key>.<field>: <reason>, got <value>".
[[noreturn]] void Reject(const std::string& key, const char* field, const std::string& reason,
                         const std::string& value) {
  throw InvalidArgument(key + "." + field + ": " + reason + ", got " + value);
}

void RequireFinite(const std::string& key, const char* field, double value) {
  if (!std::isfinite(value)) Reject(key, field, "must be finite", Text(value));
}

void RequirePositive(const std::string& key, const char* field, double value) {
  if (!(value > 0.0) || !std::isfinite(value)) Reject(key, field, "must be finite and > 0", Text(value));
}

void Validate(const CropBoxParams& p, const std::string& key) {
  if (p.from_bin) {
    if (!(p.inset_xy >= 0.0) || !std::isfinite(p.inset_xy)) {
      Reject(key, "inset_xy", "must be finite and >= 0", Text(p.inset_xy));
    }
    RequireFinite(key, "min_z", p.min_z);
    RequireFinite(key, "above_walls", p.above_walls);
    return;
  }
  if (!p.min.allFinite()) Reject(key, "min", "must be finite", Text(p.min));
  if (!p.max.allFinite()) Reject(key, "max", "must be finite", Text(p.max));
  if ((p.min.array() > p.max.array()).any()) {
    Reject(key, "min", "must be <= max " + Text(p.max) + " in every axis", Text(p.min));
  }
}

void Validate(const PassThroughParams& p, const std::string& key) {
  if (std::isnan(p.min)) Reject(key, "min", "must be a number", Text(p.min));
  if (std::isnan(p.max)) Reject(key, "max", "must be a number", Text(p.max));
  if (p.min > p.max) Reject(key, "min", "must be <= max (" + Text(p.max) + ")", Text(p.min));
  const int axis = static_cast<int>(p.axis);
  if (axis < 0 || axis > 2) Reject(key, "axis", "must be x, y or z", std::to_string(axis));
}

void Validate(const VoxelGridParams& p, const std::string& key) {
  RequirePositive(key, "leaf_size", p.leaf_size);
}

void Validate(const RandomSampleParams& p, const std::string& key) {
  if (p.count == 0) Reject(key, "count", "must be > 0", "0");
}

void Validate(const RadiusOutlierParams& p, const std::string& key) {
  RequirePositive(key, "radius", p.radius);
}

void Validate(const StatisticalOutlierParams& p, const std::string& key) {
  if (p.neighbours == 0) Reject(key, "neighbours", "must be > 0", "0");
  if (!(p.stddev_mult >= 0.0) || !std::isfinite(p.stddev_mult)) {
    Reject(key, "stddev_mult", "must be finite and >= 0", Text(p.stddev_mult));
  }
}

void Validate(const PlaneRemovalParams& p, const std::string& key) {
  RequirePositive(key, "distance_threshold", p.distance_threshold);
  if (!(p.normal_distance_weight >= 0.0 && p.normal_distance_weight <= 1.0)) {
    Reject(key, "normal_distance_weight", "must be in [0, 1]", Text(p.normal_distance_weight));
  }
  if (!p.axis.allFinite() || p.axis.norm() < 1e-9) {
    Reject(key, "axis", "must be a finite non-zero vector", Text(p.axis));
  }
  if (!(p.eps_angle >= 0.0 && p.eps_angle <= std::numbers::pi / 2)) {
    Reject(key, "eps_angle", "must be in [0, pi/2] radians", Text(p.eps_angle));
  }
  if (p.max_iterations == 0) Reject(key, "max_iterations", "must be > 0", "0");
  if (!(p.probability > 0.0 && p.probability < 1.0)) {
    Reject(key, "probability", "must be in (0, 1)", Text(p.probability));
  }
}

}  // namespace

std::string FilterName(const FilterStep& step) {
  return std::visit(Overloaded{
                        [](const CropBoxParams&) { return "crop_box"; },
                        [](const PassThroughParams&) { return "pass_through"; },
                        [](const VoxelGridParams&) { return "voxel_grid"; },
                        [](const RandomSampleParams&) { return "random_sample"; },
                        [](const RadiusOutlierParams&) { return "radius_outlier"; },
                        [](const StatisticalOutlierParams&) { return "statistical_outlier"; },
                        [](const PlaneRemovalParams&) { return "plane_removal"; },
                    },
                    step);
}

bool FilterNeedsNormals(const FilterStep& step) { return std::holds_alternative<PlaneRemovalParams>(step); }

void ValidateFilter(const FilterStep& step, const std::string& key) {
  std::visit([&](const auto& params) { Validate(params, key); }, step);
}

std::vector<std::uint32_t> ApplyFilter(const FilterStep& step, const Points& points_Bin,
                                       const Points* normals, const FilterContext& context,
                                       std::uint64_t seed, const StopToken* stop) {
  const std::string name = FilterName(step);
  ValidateFilter(step, name);
  if (points_Bin.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw InvalidArgument(name + ": too many points (" + std::to_string(points_Bin.size()) +
                          "), at most 2^32 - 1");
  }
  if (FilterNeedsNormals(step)) {
    if (normals == nullptr) throw InvalidArgument(name + ": needs normals but none were given");
    if (normals->size() != points_Bin.size()) {
      throw InvalidArgument(name + ": " + std::to_string(normals->size()) + " normals for " +
                            std::to_string(points_Bin.size()) + " points");
    }
  }
  return std::visit(
      Overloaded{
          [&](const CropBoxParams& p) { return internal::CropBoxFilter(p, points_Bin, context, stop); },
          [&](const PassThroughParams& p) {
            return internal::PassThroughFilter(p, points_Bin, context, stop);
          },
          [&](const VoxelGridParams& p) { return internal::VoxelGridFilter(p, points_Bin, stop); },
          [&](const RandomSampleParams& p) {
            return internal::RandomSampleFilter(p, points_Bin.size(), seed, stop);
          },
          [&](const RadiusOutlierParams& p) { return internal::RadiusOutlierFilter(p, points_Bin, stop); },
          [&](const StatisticalOutlierParams& p) {
            return internal::StatisticalOutlierFilter(p, points_Bin, stop);
          },
          [&](const PlaneRemovalParams& p) {
            return internal::PlaneRemovalFilter(p, points_Bin, *normals, seed, stop);
          },
      },
      step);
}

}  // namespace tubepick

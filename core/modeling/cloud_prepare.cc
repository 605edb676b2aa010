#include "core/modeling/cloud_prepare.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "core/common/errors.h"
#include "core/modeling/filters.h"

namespace tubepick {
namespace {

// Points between two polls of the stop token.
constexpr std::size_t kStopPollInterval = 1 << 16;

// The pass itself; `point(i)` reads input point i in the sensor frame and unit.
template <typename ReadPoint>
PreparedCloud Prepare(std::size_t count, ReadPoint point, LengthUnit unit,
                      const Eigen::Isometry3d& X_BinSensor, const PrepareSpec& spec, const StopToken* stop) {
  if (count == 0) {
    throw InvalidArgument(
        "cloud: no points arrived (0 points); a scan must contain at least one finite point");
  }
  // One affine map from the file's unit in the sensor frame to metres in the bin frame, in float
  // (the points' precision; about 0.1 µm at 1 m).
  const Eigen::Matrix3f R_scaled = (X_BinSensor.linear() * MetresPer(unit)).cast<float>();
  const Eigen::Vector3f p_BinSo = X_BinSensor.translation().cast<float>();
  const bool crop = spec.crop_Bin.has_value();
  const Eigen::Vector3f lo = crop ? spec.crop_Bin->first : Eigen::Vector3f::Zero();
  const Eigen::Vector3f hi = crop ? spec.crop_Bin->second : Eigen::Vector3f::Zero();
  // In float like the points (±∞ stay infinite).
  const RawRegion& raw = spec.raw_region_Bin;
  const bool keep_all_raw = raw.KeepsAll();
  const float raw_min_z = static_cast<float>(raw.min_z),
              raw_any_xy_z = static_cast<float>(raw.any_xy_above_z);
  const float raw_hx = static_cast<float>(raw.half_xy.x()), raw_hy = static_cast<float>(raw.half_xy.y());

  PreparedCloud out;
  out.input_points = count;
  // Reserved, not touched: only the pages actually written are faulted in.
  out.working_Bin.reserve(count);
  out.working_source_index.reserve(count);
  if (!raw.KeepsNone()) out.raw_Bin.reserve(count);
  PlausibilityTally tally(spec.bin, spec.plausibility, count);
  for (std::size_t i = 0; i < count; ++i) {
    if (i % kStopPollInterval == 0) ThrowIfStopped(stop, "prepare");
    // NaN/Inf propagate through the map; checking the result also catches float overflow.
    const Eigen::Vector3f p_Bin = R_scaled * point(i) + p_BinSo;
    if (!p_Bin.allFinite()) continue;
    tally.Add(p_Bin);
    if (!crop || InCropBox(p_Bin, lo, hi)) {
      out.working_Bin.push_back(p_Bin);
      out.working_source_index.push_back(static_cast<std::uint32_t>(i));
    }
    if (keep_all_raw || p_Bin.z() >= raw_any_xy_z ||
        (p_Bin.z() >= raw_min_z && std::abs(p_Bin.x()) <= raw_hx && std::abs(p_Bin.y()) <= raw_hy)) {
      out.raw_Bin.push_back(p_Bin);
    }
  }
  out.plausibility = tally.Finish();
  out.dropped_non_finite = count - out.plausibility.points;
  if (out.plausibility.points == 0) {
    throw InvalidArgument("cloud: no finite point: " + std::to_string(count) + " points arrived and " +
                          std::to_string(out.dropped_non_finite) + " of them were non-finite (NaN or Inf)");
  }
  return out;
}

}  // namespace

Eigen::Vector3f PackedXyz::Point(std::size_t i) const {
  const char* p = bytes.data() + 12 * i;
  Eigen::Vector3f point;
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(point.data(), p, 12);
  } else {
    for (int k = 0; k < 3; ++k) {
      std::uint32_t bits = 0;
      for (int b = 0; b < 4; ++b)
        bits |= static_cast<std::uint32_t>(static_cast<unsigned char>(p[4 * k + b])) << (8 * b);
      point[k] = std::bit_cast<float>(bits);
    }
  }
  return point;
}

PreparedCloud PrepareCloud(const Points& points_Sensor, LengthUnit unit, const Eigen::Isometry3d& X_BinSensor,
                           const PrepareSpec& spec, const StopToken* stop) {
  return Prepare(
      points_Sensor.size(), [&](std::size_t i) -> const Eigen::Vector3f& { return points_Sensor[i]; }, unit,
      X_BinSensor, spec, stop);
}

PreparedCloud PrepareCloud(PackedXyz xyz_Sensor, LengthUnit unit, const Eigen::Isometry3d& X_BinSensor,
                           const PrepareSpec& spec, const StopToken* stop) {
  return Prepare(
      xyz_Sensor.size(), [&](std::size_t i) { return xyz_Sensor.Point(i); }, unit, X_BinSensor, spec, stop);
}

}  // namespace tubepick

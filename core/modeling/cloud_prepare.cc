#include "core/modeling/cloud_prepare.h"

#include <string>

#include "core/common/errors.h"

namespace tubepick {

PreparedCloud PrepareCloud(const Points& points_Sensor, LengthUnit unit,
                           const Eigen::Isometry3d& X_BinSensor) {
  if (points_Sensor.empty()) {
    throw InvalidArgument(
        "cloud: no points arrived (0 points); a scan must contain at least one finite point");
  }
  // One affine map from the file's unit in the sensor frame to metres in the bin frame, in float
  // (the points' precision; about 0.1 µm at 1 m).
  const Eigen::Matrix3f R_scaled = (X_BinSensor.linear() * MetresPer(unit)).cast<float>();
  const Eigen::Vector3f p_BinSo = X_BinSensor.translation().cast<float>();

  PreparedCloud prepared;
  prepared.points_Bin.resize(points_Sensor.size());
  std::size_t kept = 0;
  for (const Eigen::Vector3f& p_Sensor : points_Sensor) {
    // NaN/Inf propagate through the map; checking the result also catches float overflow.
    const Eigen::Vector3f p_Bin = R_scaled * p_Sensor + p_BinSo;
    if (p_Bin.allFinite()) prepared.points_Bin[kept++] = p_Bin;
  }
  prepared.points_Bin.resize(kept);
  prepared.dropped_non_finite = points_Sensor.size() - kept;
  if (prepared.dropped_non_finite > 0) {
    // Rare path: remember where each kept point came from.
    prepared.source_index.reserve(kept);
    for (std::uint32_t i = 0; i < points_Sensor.size(); ++i) {
      if ((R_scaled * points_Sensor[i] + p_BinSo).allFinite()) prepared.source_index.push_back(i);
    }
  }
  if (kept == 0) {
    throw InvalidArgument("cloud: no finite point: " + std::to_string(points_Sensor.size()) +
                          " points arrived and " + std::to_string(prepared.dropped_non_finite) +
                          " of them were non-finite (NaN or Inf)");
  }
  return prepared;
}

}  // namespace tubepick

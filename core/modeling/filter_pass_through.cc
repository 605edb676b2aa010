// pass_through: keeps the points whose coordinate along one axis (bin or sensor frame) is in range.

#include "core/modeling/filters_internal.h"

namespace tubepick::internal {

std::vector<std::uint32_t> PassThroughFilter(const PassThroughParams& params, const Points& points_Bin,
                                             const FilterContext& context, const StopToken* stop) {
  const int axis = static_cast<int>(params.axis);
  // The coordinate is one row of the affine map into the filter frame.
  Eigen::Vector3d row = Eigen::Vector3d::Unit(axis);
  double offset = 0.0;
  if (params.frame == FilterFrame::kSensor) {
    const Eigen::Isometry3d X_SensorBin = context.X_BinSensor.inverse();
    row = X_SensorBin.linear().row(axis).transpose();
    offset = X_SensorBin.translation()[axis];
  }
  std::vector<std::uint32_t> kept;
  kept.reserve(points_Bin.size());
  for (std::size_t i = 0; i < points_Bin.size(); ++i) {
    if (i % kStopPollInterval == 0) ThrowIfStopped(stop, "filter pass_through");
    const double value = row.dot(points_Bin[i].cast<double>()) + offset;
    if (value >= params.min && value <= params.max) kept.push_back(static_cast<std::uint32_t>(i));
  }
  return kept;
}

}  // namespace tubepick::internal

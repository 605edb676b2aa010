// crop_box: keeps the points inside an axis-aligned box of the bin frame.

#include <sstream>

#include "core/common/errors.h"
#include "core/modeling/filters_internal.h"

namespace tubepick {
namespace {

std::string Text(const Eigen::Vector3d& v) {
  std::ostringstream os;
  os << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return os.str();
}

}  // namespace

std::pair<Eigen::Vector3f, Eigen::Vector3f> CropBoxBounds(const CropBoxParams& params, const BinConfig& bin) {
  Eigen::Vector3d lo = params.min;
  Eigen::Vector3d hi = params.max;
  if (params.from_bin) {
    const Eigen::Vector3d& size = bin.inner_size;
    lo = Eigen::Vector3d(-0.5 * size.x() + params.inset_xy, -0.5 * size.y() + params.inset_xy, params.min_z);
    hi = Eigen::Vector3d(0.5 * size.x() - params.inset_xy, 0.5 * size.y() - params.inset_xy,
                         size.z() + params.above_walls);
    if ((lo.array() > hi.array()).any()) {
      std::ostringstream os;
      os << "crop_box: the box from the bin is empty (min " << Text(lo) << ", max " << Text(hi)
         << ") for bin inner_size " << Text(size) << " with inset_xy " << params.inset_xy << ", min_z "
         << params.min_z << ", above_walls " << params.above_walls;
      throw InvalidArgument(os.str());
    }
  }
  // Rounded to the nearest float: points are compared in their own precision.
  return {lo.cast<float>(), hi.cast<float>()};
}

}  // namespace tubepick

namespace tubepick::internal {

std::vector<std::uint32_t> CropBoxFilter(const CropBoxParams& params, const Points& points_Bin,
                                         const FilterContext& context, const StopToken* stop) {
  const auto [lo_f, hi_f] = CropBoxBounds(params, context.bin);
  std::vector<std::uint32_t> kept;
  kept.reserve(points_Bin.size());
  for (std::size_t i = 0; i < points_Bin.size(); ++i) {
    if (i % kStopPollInterval == 0) ThrowIfStopped(stop, "filter crop_box");
    const Eigen::Vector3f& p = points_Bin[i];
    if (InCropBox(p, lo_f, hi_f)) kept.push_back(static_cast<std::uint32_t>(i));
  }
  return kept;
}

}  // namespace tubepick::internal

// crop_box: keeps the points inside an axis-aligned box of the bin frame.

#include <sstream>

#include "core/common/errors.h"
#include "core/modeling/filters_internal.h"

namespace tubepick::internal {
namespace {

std::string Text(const Eigen::Vector3d& v) {
  std::ostringstream os;
  os << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return os.str();
}

}  // namespace

std::vector<std::uint32_t> CropBoxFilter(const CropBoxParams& params, const Points& points_Bin,
                                         const FilterContext& context, const StopToken* stop) {
  Eigen::Vector3d lo = params.min;
  Eigen::Vector3d hi = params.max;
  if (params.from_bin) {
    const Eigen::Vector3d& size = context.bin.inner_size;
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
  // Compared in float, the points' own precision (bounds rounded to the nearest float).
  const Eigen::Array3f lo_f = lo.cast<float>().array();
  const Eigen::Array3f hi_f = hi.cast<float>().array();
  std::vector<std::uint32_t> kept;
  kept.reserve(points_Bin.size());
  for (std::size_t i = 0; i < points_Bin.size(); ++i) {
    if (i % kStopPollInterval == 0) ThrowIfStopped(stop, "filter crop_box");
    const Eigen::Vector3f& p = points_Bin[i];
    // NaN fails every comparison, so non-finite points are dropped too.
    if (p.x() >= lo_f.x() && p.x() <= hi_f.x() && p.y() >= lo_f.y() && p.y() <= hi_f.y() &&
        p.z() >= lo_f.z() && p.z() <= hi_f.z()) {
      kept.push_back(static_cast<std::uint32_t>(i));
    }
  }
  return kept;
}

}  // namespace tubepick::internal

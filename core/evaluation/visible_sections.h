#pragma once

#include <cstdint>
#include <vector>

#include "core/common/types.h"

namespace tubepick {

/// What counts as one visible continuous section of a real tube (the thesis' annotators counted
/// them by eye, §4.4.4).
struct VisibleSectionParams {
  /// Two points of the same tube closer than this are in the same section, metres. Larger than
  /// the point spacing of the filtered cloud, smaller than the gap an occluding tube leaves
  /// (about its diameter).
  double link_radius = 0.010;
  /// Components with fewer points are not counted (specks the segmentation cannot see either).
  std::uint32_t min_points = 30;
};

/// Per real tube: the number of visible sections, i.e. connected components (points linked when
/// within link_radius) of the points labelled with that tube that have at least min_points
/// points. `truth` holds one label per point (tube index ≥ 0, anything negative is ignored);
/// labels ≥ tube_count are ignored too.
/// @throws InvalidArgument when the sizes differ or link_radius is not positive.
std::vector<std::uint32_t> CountVisibleSections(const Points& points, const std::vector<std::int32_t>& truth,
                                                std::uint32_t tube_count, const VisibleSectionParams& params);

}  // namespace tubepick

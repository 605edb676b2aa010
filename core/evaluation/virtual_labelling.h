#pragma once

#include <cstdint>
#include <vector>

#include "core/common/types.h"

namespace tubepick {

/// How points that no cylinder took as an inlier are given a virtual tube (thesis §4.5.2).
struct VirtualLabellingParams {
  /// A point belongs to a cylinder or joint when its distance to the primitive's axis segment
  /// (a capsule: the segment between the two endpoints) is at most its radius plus this, metres.
  /// Covers range noise and the fitting error of the radius.
  double tolerance = 0.005;
  /// Also label unlabelled points inside a tube's cylinders (not only inside its joints).
  bool label_inside_cylinders = true;
};

/// Per-point virtual tube of the filtered cloud.
struct VirtualLabels {
  /// Index into the modeled tubes (not the tube id), or −1 for the null label c∅.
  std::vector<std::int32_t> tube;
  /// Index into that tube's cylinders of the cylinder nearest the point (its axis segment), or −1.
  std::vector<std::int32_t> cylinder;
  /// How the label was given: 0 cylinder inlier, 1 inside a joint, 2 inside a cylinder, −1 none.
  std::vector<std::int8_t> source;
};

/// Labels every filtered point with a virtual tube: cylinder inliers (`tube_of_point`, holding
/// tube ids) keep their tube; every other point inside a joint (from cylinders[i].end to
/// cylinders[i+1].start, radius = the mean of the two cylinders' radii) or, with
/// label_inside_cylinders, inside a cylinder of some tube gets that tube — the one whose surface
/// (|distance to axis − radius|) is nearest when several contain it; the rest get −1 (c∅).
/// @throws InvalidArgument when tube_of_point's size differs from the points', or it names a
///         tube id that is not in `tubes`.
VirtualLabels LabelVirtualTubes(const Points& points_Bin, const std::vector<std::int32_t>& tube_of_point,
                                const std::vector<Tube>& tubes, const VirtualLabellingParams& params);

/// Distance from `p` to the segment [a, b] (to `a` when the segment is degenerate).
double DistanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b);

}  // namespace tubepick

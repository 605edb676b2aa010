#pragma once

#include <vector>

#include <Eigen/Core>

#include "core/common/cell_config.h"

namespace tubepick::physics {

/// An axis-aligned box of the Bin frame.
struct AlignedBox {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  Eigen::Vector3d half_size = Eigen::Vector3d::Zero();
};

/// The bin as solids, shared by the drop (collision) and the scanner (rendering) so both see the
/// same cell. The inner faces match BinConfig: floor top at z = 0, inner walls at x = ±length/2
/// and y = ±width/2, wall tops at z = height. The floor slab (thickness t) spans the outer
/// footprint and sits on the ground, so the ground plane is z = −t.
struct BinSolids {
  /// Floor slab, then the walls at +x, −x, +y, −y.
  std::vector<AlignedBox> boxes;
  /// Height of the ground plane (infinite, z up) around and under the bin, metres.
  double ground_z = 0.0;
};

/// @throws InvalidArgument when wall_thickness is not in (0, 1] m.
BinSolids MakeBinSolids(const BinConfig& bin, double wall_thickness);

}  // namespace tubepick::physics
